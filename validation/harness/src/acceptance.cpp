#include "puncture/validation/acceptance.hpp"

#include <cmath>
#include <stdexcept>
#include <sstream>

#include "puncture/validation/number_format.hpp"

namespace puncture::validation {
namespace {

std::string fmt(double v, int digits = 3) { return significant_digits(v, digits); }

/// |value| <= limit for one objective term: its relative value or its raw error.
AcceptanceCheck term_check(const ObjectiveTerm* t, bool relative, double limit) {
  AcceptanceCheck c;
  c.limit = limit;
  if (!t || !t->available) {
    c.note = "n/a: " + (t ? t->note : std::string("no term"));
    return c;
  }
  c.available = true;
  c.value = relative ? t->value : t->raw;
  c.met = std::abs(c.value) <= limit;
  c.note = t->note;
  return c;
}

}  // namespace

std::vector<LayerAcceptance> layer_acceptance(const std::vector<LayerGeometry>& layers,
                                              const TrajectoryComparison& comparison,
                                              const AcceptanceCriteria& criteria) {
  std::vector<LayerAcceptance> out;
  for (const LayerGeometry& g : layers) {
    LayerAcceptance a;
    a.layer = g.name;
    // Force RMSE over the layer's pressing and cut.
    double sum = 0.0;
    std::string missing;
    for (const char* name : {"pressing", "after_puncture"}) {
      const ObjectiveTerm* t = comparison.term(name, g.name);
      if (t && t->available && t->samples > 0) {
        sum += static_cast<double>(t->samples) * t->value * t->value;
        a.rmse_samples += t->samples;
      } else {
        missing += std::string(missing.empty() ? "" : ", ") + name + (t ? ": " + t->note : ": no term");
      }
    }
    a.force_rmse.limit = criteria.max_rmse_relative;
    if (a.rmse_samples > 0) {
      a.force_rmse.available = true;
      a.force_rmse.value = std::sqrt(sum / static_cast<double>(a.rmse_samples));
      a.force_rmse.met = a.force_rmse.value <= criteria.max_rmse_relative;
      a.force_rmse.note = std::to_string(a.rmse_samples) + " samples" + (missing.empty() ? "" : " (n/a: " + missing + ")");
    } else {
      a.force_rmse.note = "n/a: " + missing;
    }
    // Puncture depth within L (the term's error in m), force within 10 % (its relative error).
    a.puncture_depth = term_check(comparison.term("puncture_depth", g.name), false, g.spacing_L_m);
    a.puncture_force = term_check(comparison.term("puncture_force", g.name), true, criteria.max_force_error_relative);
    out.push_back(a);
  }
  return out;
}

void add_deflection_acceptance(std::vector<LayerAcceptance>& acceptance, const std::vector<LayerDeflectionErrors>& errors,
                               const AcceptanceCriteria& criteria) {
  if (acceptance.size() != errors.size())
    throw std::invalid_argument("add_deflection_acceptance: one deflection comparison per layer");
  auto check = [](bool available, double value, double limit, const std::string& note) {
    AcceptanceCheck c;
    c.available = available && std::isfinite(value);
    c.limit = limit;
    if (c.available) {
      c.value = value;
      c.met = value <= limit;
      c.note = "relative RMSE of the ring deflections";
    } else {
      c.note = "n/a: " + (note.empty() ? std::string("surfaces not compared") : note);
    }
    return c;
  };
  for (std::size_t k = 0; k < acceptance.size(); ++k) {
    acceptance[k].deflection_judged = true;
    acceptance[k].deflection = check(errors[k].before_available, errors[k].before_relative,
                                     criteria.max_deflection_relative, errors[k].note);
    acceptance[k].recovery = check(errors[k].after_available, errors[k].after_relative, criteria.max_recovery_relative,
                                   errors[k].note);
  }
}

std::string acceptance_markdown(const std::vector<LayerAcceptance>& acceptance, const TrajectoryComparison& comparison,
                                const AcceptanceCriteria& criteria) {
  std::ostringstream md;
  const bool judged = !acceptance.empty() && acceptance.front().deflection_judged;
  md << "| layer | force RMSE over pressing and cut / peak (limit " << fmt(100 * criteria.max_rmse_relative) << " %) | puncture depth error "
     << "(limit L) | puncture force error (limit " << fmt(100 * criteria.max_force_error_relative) << " %) | ";
  if (judged)
    md << "deflection RMSE before the break / FEM's largest (limit " << fmt(100 * criteria.max_deflection_relative)
       << " %) | after the break (limit " << fmt(100 * criteria.max_recovery_relative) << " %) | ";
  md << "accepted |\n|---|---|---|---|" << (judged ? "---|---|" : "") << "---|\n";
  auto cell = [](const AcceptanceCheck& c, const std::string& value) {
    if (!c.available) return c.note;
    return value + (c.met ? " (met)" : " (**not met**)");
  };
  for (const LayerAcceptance& a : acceptance) {
    md << "| " << a.layer << " | "
       << cell(a.force_rmse, fmt(100 * a.force_rmse.value) + " % over " + std::to_string(a.rmse_samples) + " samples")
       << " | "
       << cell(a.puncture_depth, fmt(a.puncture_depth.value * 1e3) + " mm (L = " + fmt(a.puncture_depth.limit * 1e3) + " mm)")
       << " | " << cell(a.puncture_force, fmt(100 * a.puncture_force.value) + " %") << " | ";
    if (judged)
      md << cell(a.deflection, fmt(100 * a.deflection.value) + " %") << " | "
         << cell(a.recovery, fmt(100 * a.recovery.value) + " %") << " | ";
    md << (a.accepted() ? "yes" : "**no**") << " |\n";
  }
  md << "\nWhole trajectory (RMSE over the reference's samples, relative to its insertion peak "
     << fmt(comparison.reference_peak_force_N) << " N):\n\n| term | value | error | samples | note |\n|---|---|---|---|---|\n";
  for (const ObjectiveTerm& t : comparison.terms) {
    if (!t.layer.empty()) continue;
    md << "| " << t.label() << " | " << (t.available ? fmt(100 * t.value) + " %" : "n/a") << " | "
       << (t.available ? fmt(t.raw) + " N" : "n/a") << " | " << t.samples << " | " << t.note << " |\n";
  }
  return md.str();
}

}  // namespace puncture::validation
