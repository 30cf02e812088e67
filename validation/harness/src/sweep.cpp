// sweep.cpp: see sweep.hpp.
#include "puncture/validation/sweep.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "puncture/io/csv_writer.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/number_format.hpp"

namespace puncture::validation {

namespace {
constexpr double kMm = 1e-3;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

std::string fmt(double x, int precision = 8) {
  if (!std::isfinite(x)) return "nan";
  return significant_digits(x, precision);
}

void fill_sweep_errors(SweepRow& row, const InsertionCurve& model, const InsertionCurve& reference) {
  const CurveComparison cmp = compare_curves(model, reference);
  row.force_rmse_N = cmp.force_rmse_N;
  row.force_rmse_relative = cmp.force_rmse_relative;
  double sum_sq = 0.0;
  for (const LayerMetrics& m : cmp.layers) {
    if (m.reference_puncture.found && m.model_puncture.found) {
      sum_sq += m.puncture_depth_error_m * m.puncture_depth_error_m;
      ++row.punctures_compared;
    } else if (m.reference_puncture.found != m.model_puncture.found) {
      ++row.missed_punctures;
    }
  }
  row.puncture_depth_error_mm = row.punctures_compared > 0 ? std::sqrt(sum_sq / row.punctures_compared) / kMm : kNaN;
}

SweepRow sweep_realtime_variant(const Scene& scene, const std::string& knob, const std::string& value, bool baseline,
                          const InsertionCurve& reference) {
  SweepRow row;
  row.model = "realtime";
  row.knob = knob;
  row.value = value;
  row.baseline = baseline;
  row.time_kind = "haptic tick wall time over the ticks with contact (mean, p99)";
  try {
    validate_scene(scene, "sweep variant " + knob + " = " + value);
  } catch (const SceneError& e) {
    // E.g. a spacing L that puts the force mesh outside the sample.
    row.status = std::string("invalid: ") + e.what();
    return row;
  }
  try {
    RealtimeModel model = build_realtime_model(scene);
    const ScriptedRunResult run = run_scripted_insertion(model, scene);
    const TickCost cost = tick_cost(run);
    row.time_per_step_s = cost.contact_mean_s;
    row.time_p99_s = cost.contact_p99_s;
    // Against the quasi-static, frictionless FEM: without the damping force.
    fill_sweep_errors(row, curve_from_run(scene, run, "realtime", /*include_damping=*/true), reference);
  } catch (const std::exception& e) {
    row.status = std::string("failed: ") + e.what();
  }
  return row;
}

std::string sweep_table_csv(const std::vector<SweepRow>& rows, const io::Provenance& provenance) {
  io::CsvWriter csv({"model", "knob", "value", "baseline", "status", "force_rmse_N", "force_rmse_relative",
                     "puncture_depth_error_mm", "punctures_compared", "missed_punctures", "time_per_step_s", "time_p99_s",
                     "n_dofs"});
  csv.add_provenance(provenance);
  for (const SweepRow& r : rows) {
    std::string status = r.status;
    std::replace(status.begin(), status.end(), ',', ';');
    std::replace(status.begin(), status.end(), '\n', ' ');
    csv.text(r.model).text(r.knob).text(r.value).integer(r.baseline ? 1 : 0).text(status);
    csv.number(r.force_rmse_N, 8).number(r.force_rmse_relative, 8).number(r.puncture_depth_error_mm, 8);
    csv.integer(r.punctures_compared).integer(r.missed_punctures).number(r.time_per_step_s, 8);
    csv.number(r.time_p99_s, 8).number(r.n_dofs, 8);
    csv.end_row();
  }
  return csv.str();
}

std::string sweep_table_markdown(const Scene& scene, const std::vector<SweepRow>& rows, const std::string& finest,
                                 const io::Provenance& provenance, const std::vector<std::string>& plots) {
  std::ostringstream md;
  md << "# Accuracy against cost: " << scene.name << "\n\n";
  md << "Every fidelity knob varied one at a time around the scene's values (baseline rows marked). Error "
        "against the finest FEM reference (" << finest << "): force RMSE over the insertion phase and the RMS "
        "puncture-depth error over the layers both models puncture (missed = punctured by one model only). "
        "Cost: real-time = wall time of one haptic tick over the ticks with contact (the tip below the skin "
        "surface or a layer pressed: where the work is), mean and 99th percentile; FEM = wall time per "
        "quasi-static load step.\n\n";
  md << "- command: `" << provenance.command << "`\n";
  md << "- program " << provenance.program_version << ", git revision " << provenance.git_revision
     << "; machine: " << provenance.machine << "; date (UTC): " << provenance.date_utc << "\n\n";
  for (const std::string& p : plots) md << "![" << p << "](" << p << ")\n\n";
  md << "| model | knob | value | force RMSE (N) | RMSE / peak | puncture depth error (mm) | missed punctures | "
        "time per step (mean) | p99 | DoFs | status |\n";
  md << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const SweepRow& r : rows) {
    std::string time = "–";
    if (std::isfinite(r.time_per_step_s)) {
      std::ostringstream t;
      if (r.model == "fem")
        t << std::setprecision(3) << r.time_per_step_s << " s";
      else
        t << std::setprecision(3) << r.time_per_step_s * 1e6 << " µs";
      time = t.str();
    }
    std::string p99 = "–";
    if (std::isfinite(r.time_p99_s)) {
      std::ostringstream t;
      t << std::setprecision(3) << r.time_p99_s * 1e6 << " µs";
      p99 = t.str();
    }
    md << "| " << r.model << " | " << r.knob << " | " << r.value << (r.baseline ? " (baseline)" : "") << " | "
       << fmt(r.force_rmse_N, 4) << " | " << fmt(r.force_rmse_relative, 3) << " | "
       << fmt(r.puncture_depth_error_mm, 4) << " | " << r.missed_punctures << " | " << time << " | " << p99 << " | "
       << (std::isfinite(r.n_dofs) ? fmt(r.n_dofs, 10) : "–") << " | " << r.status << " |\n";
  }
  md << "\nFiles: [accuracy_cost.csv](accuracy_cost.csv), [accuracy_cost.json](accuracy_cost.json).\n";
  return md.str();
}


std::vector<SweepRow> sweep_realtime_knobs(const Scene& scene, const InsertionCurve& reference,
                                           const std::function<void(const std::string&, const std::string&)>& on_variant) {
  std::vector<SweepRow> rows;
  auto run_variant = [&](const Scene& variant, const std::string& knob, const std::string& value, bool baseline) {
    if (on_variant) on_variant(knob, value);
    rows.push_back(sweep_realtime_variant(variant, knob, value, baseline, reference));
  };
  std::vector<int> degrees{4, 8, 12, 16, 24, 32};
  if (std::find(degrees.begin(), degrees.end(), scene.realtime.sh_degree) == degrees.end())
    degrees.push_back(scene.realtime.sh_degree), std::sort(degrees.begin(), degrees.end());
  for (int l : degrees) {
    Scene v = scene;
    v.realtime.sh_degree = l;
    run_variant(v, "sh_degree", std::to_string(l), l == scene.realtime.sh_degree);
  }
  for (int delta : {-2, -1, 0, 1, 2, 4}) {
    Scene v = scene;
    bool valid = true;
    for (Layer& layer : v.layers) {
      layer.force_mesh.rings_w += delta;
      valid = valid && layer.force_mesh.rings_w >= 2;
    }
    if (!valid) continue;
    run_variant(v, "rings_w_delta", (delta > 0 ? "+" : "") + std::to_string(delta), delta == 0);
  }
  for (double factor : {0.5, 0.75, 1.0, 1.5, 2.0}) {
    Scene v = scene;
    for (Layer& layer : v.layers) layer.force_mesh.spacing_L_m *= factor;
    run_variant(v, "spacing_L_factor", fmt(factor, 3), factor == 1.0);
  }
  for (const char* integrator : {"explicit", "implicit", "quasi_static"}) {
    Scene v = scene;
    v.realtime.integrator = integrator;
    run_variant(v, "integrator", integrator, v.realtime.integrator == scene.realtime.integrator);
  }
  for (double rate : {250.0, 500.0, 1000.0, 2000.0, 4000.0}) {
    Scene v = scene;
    v.realtime.haptic_rate_Hz = rate;
    run_variant(v, "haptic_rate_Hz", fmt(rate, 6), rate == scene.realtime.haptic_rate_Hz);
  }

  return rows;
}

}  // namespace puncture::validation
