// The identifiability report of a calibration (identifiability_report.hpp).
#include "identifiability_report.hpp"

#include <cmath>
#include <sstream>

#include "puncture/validation/levenberg_marquardt.hpp"
#include "puncture/validation/number_format.hpp"

namespace puncture::validation::calibration_detail {

namespace {

ParameterIdentifiability named(const Scene& s, std::size_t layer, ParamKind kind) {
  const ParamInfo in = info(kind);
  ParameterIdentifiability p;
  p.layer = s.layers[layer].name;
  p.name = in.name;
  p.unit = in.unit;
  p.preset_pointers = preset_pointers(kind);
  return p;
}

std::string label(const Scene& s, const Parameter& p) { return s.layers[p.layer].name + " " + info(p.kind).name; }

/// Status and reason of tuned parameter j from the Jacobian's statistics.
void classify(const JacobianStatistics& st, std::size_t j, const Parameter& p, double x, double max_sensitivity,
              ParameterIdentifiability& out) {
  const Eigen::Index i = static_cast<Eigen::Index>(j);
  const std::string bound = bound_name(p, x);
  if (!(st.sensitivity(i) > 1e-6 * max_sensitivity)) {
    out.status = "not identifiable";
    out.insensitive = true;
    out.reason = "the objective does not change with it at the optimum";
  } else if (!bound.empty()) {
    out.status = "at a bound";
    out.reason = "ended at its " + bound + " bound";
  } else if (!std::isfinite(st.standard_error(i))) {
    out.status = "not identifiable";
    out.reason = "the Jacobian is singular in its direction (another parameter compensates it)";
  } else if (st.standard_error(i) > 1.0) {
    out.status = "not identifiable";
    out.reason = std::string("standard error above ") + (p.log_space ? "its value" : "its scale");
  } else {
    out.status = "identified";
  }
}

}  // namespace

IdentifiabilityReport identifiability_report(StageObjective& whole, const std::vector<WithheldParameter>& withheld,
                                             const CalibrationOptions& o) {
  IdentifiabilityReport rep;
  const Scene& s = whole.scene;
  const std::vector<Parameter>& ps = whole.parameters;
  if (!ps.empty()) {
    const std::vector<double> x = x_values(s, ps);
    std::vector<double> lo, hi, r0;
    for (const Parameter& p : ps) lo.push_back(p.lower), hi.push_back(p.upper);
    if (whole.set_layout(x) && whole.residuals_at(x, r0)) {
      const ResidualFunction r = [&whole](const std::vector<double>& xi, std::vector<double>& out) {
        return whole.residuals_at(xi, out);
      };
      const Eigen::MatrixXd J = finite_difference_jacobian(r, x, r0, lo, hi, o.lm_difference_step, o.threads);
      const JacobianStatistics st =
          jacobian_statistics(J, Eigen::Map<const Eigen::VectorXd>(r0.data(), static_cast<Eigen::Index>(r0.size())));
      const double smax = st.sensitivity.size() ? st.sensitivity.maxCoeff() : 0.0;
      for (std::size_t j = 0; j < ps.size(); ++j) {
        const ParamInfo in = info(ps[j].kind);
        ParameterIdentifiability pi = named(s, ps[j].layer, ps[j].kind);
        const double value = param_value(s, ps[j].layer, ps[j].kind);
        pi.value = value * in.to_unit;
        pi.sensitivity = st.sensitivity(static_cast<Eigen::Index>(j));
        const double se_x = st.standard_error(static_cast<Eigen::Index>(j));
        pi.standard_error = (ps[j].log_space ? std::abs(value) : ps[j].scale) * se_x * in.to_unit;
        classify(st, j, ps[j], x[j], smax, pi);
        rep.parameters.push_back(pi);
      }
      rep.correlation = st.correlation;
      for (const CorrelatedPair& c : st.correlated) {
        rep.correlated_names.emplace_back(label(s, ps[static_cast<std::size_t>(c.first)]),
                                          label(s, ps[static_cast<std::size_t>(c.second)]));
        rep.correlated_values.push_back(c.correlation);
      }
      rep.residual_variance = st.residual_variance;
      rep.residuals = st.residuals;
      rep.note = "forward-difference Jacobian (step " + significant_digits(o.lm_difference_step, 3) +
                 " in x = ln p, or p / scale) of the whole objective's " + std::to_string(st.residuals) +
                 " residuals at the tuned values";
    } else {
      rep.note = "the model cannot be run at the tuned values: no Jacobian";
    }
  }
  for (const WithheldParameter& w : withheld) {
    const ParamInfo in = info(w.kind);
    ParameterIdentifiability pi = named(s, w.layer, w.kind);
    pi.value = param_value(s, w.layer, w.kind) * in.to_unit;
    pi.standard_error = std::numeric_limits<double>::infinity();
    pi.status = "not identifiable";
    pi.reason = w.reason + "; kept at its start value";
    rep.parameters.push_back(pi);
  }
  return rep;
}

}  // namespace puncture::validation::calibration_detail
