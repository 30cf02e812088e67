// `puncture sweep`: what accuracy costs in time.
//
// The real-time force compared is the total minus the damping force d h v
// (the FEM is quasi-static and frictionless; as in validate and calibrate).
//
// Algorithm (top-down):
//   1. load the scene;
//   2. FEM knobs (include_fem_knobs): the reference at refinement 0 Q1,
//      refinement 0 Q2 and refinement 1 Q1 (each cached by obtain_fem_reference;
//      kFemKnobs). Without FEM knobs only the scene's own FEM setting runs.
//      The finest FEM (most DoFs) is the reference for every error below;
//      each FEM setting's own error is against it too (0 for itself);
//   3. real-time knobs, one at a time around the scene's values: SH degree l,
//      rings w (added to every layer's w), spacing L (factor on every layer's
//      L), integrator, haptic step (rate). Each variant runs the whole
//      scripted insertion without output;
//   4. per variant: force RMSE over the insertion phase (N, and relative to the
//      reference peak) and the puncture-depth error (RMS over the layers both
//      models puncture; layers punctured by one model only are counted in
//      missed_punctures), cost = mean and 99th percentile of the tick wall
//      time over the ticks with contact (real-time; tick_cost in
//      realtime_model.hpp: where the work is, not the median over all ticks,
//      which is a tick without contact) or FEM wall time per load step;
//   5. accuracy_cost.csv, accuracy_cost.md (table + provenance), accuracy_cost.json,
//      pareto.png (scripts/plot_sweep.py: error against time, log axes).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "command_errors.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/apps/fem_reference.hpp"
#include "puncture/apps/provenance.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/metrics.hpp"
#include "validation_support.hpp"

namespace puncture::apps {

namespace {

constexpr double kMm = 1e-3;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct FemKnob {
  int refinement;
  int degree;
};
/// The default FEM part: what finishes in about a quarter of an hour on 2 cores.
const std::vector<FemKnob> kFemKnobs{{0, 1}, {0, 2}, {1, 1}};

struct SweepRow {
  std::string model;    ///< "realtime" or "fem"
  std::string knob;     ///< e.g. "sh_degree"
  std::string value;    ///< the knob's value as text
  bool baseline = false;
  std::string status = "ok";
  double force_rmse_N = kNaN;
  double force_rmse_relative = kNaN;
  double puncture_depth_error_mm = kNaN;
  int punctures_compared = 0;
  int missed_punctures = 0;
  double time_per_step_s = kNaN;   ///< real-time: mean tick over the ticks with contact
  double time_p99_s = kNaN;        ///< real-time: 99th percentile over the ticks with contact
  std::string time_kind;
  double n_dofs = kNaN;
};

std::string fmt(double x, int precision = 8) {
  if (!std::isfinite(x)) return "nan";
  std::ostringstream s;
  s << std::setprecision(precision) << x;
  return s.str();
}

void fill_errors(SweepRow& row, const validation::InsertionCurve& model, const validation::InsertionCurve& reference) {
  const validation::CurveComparison cmp = validation::compare_curves(model, reference);
  row.force_rmse_N = cmp.force_rmse_N;
  row.force_rmse_relative = cmp.force_rmse_relative;
  double sum_sq = 0.0;
  for (const validation::LayerMetrics& m : cmp.layers) {
    if (m.reference_puncture.found && m.model_puncture.found) {
      sum_sq += m.puncture_depth_error_m * m.puncture_depth_error_m;
      ++row.punctures_compared;
    } else if (m.reference_puncture.found != m.model_puncture.found) {
      ++row.missed_punctures;
    }
  }
  row.puncture_depth_error_mm = row.punctures_compared > 0 ? std::sqrt(sum_sq / row.punctures_compared) / kMm : kNaN;
}


SweepRow realtime_variant(const Scene& scene, const std::string& knob, const std::string& value, bool baseline,
                          const validation::InsertionCurve& reference) {
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
    fill_errors(row, validation::curve_from_run(scene, run, "realtime", /*include_damping=*/false), reference);
  } catch (const std::exception& e) {
    row.status = std::string("failed: ") + e.what();
  }
  return row;
}

std::string table_csv(const std::vector<SweepRow>& rows) {
  std::ostringstream csv;
  csv << "model,knob,value,baseline,status,force_rmse_N,force_rmse_relative,puncture_depth_error_mm,"
         "punctures_compared,missed_punctures,time_per_step_s,time_p99_s,n_dofs\n";
  for (const SweepRow& r : rows) {
    std::string status = r.status;
    std::replace(status.begin(), status.end(), ',', ';');
    std::replace(status.begin(), status.end(), '\n', ' ');
    csv << r.model << ',' << r.knob << ',' << r.value << ',' << (r.baseline ? 1 : 0) << ',' << status << ','
        << fmt(r.force_rmse_N) << ',' << fmt(r.force_rmse_relative) << ',' << fmt(r.puncture_depth_error_mm) << ','
        << r.punctures_compared << ',' << r.missed_punctures << ',' << fmt(r.time_per_step_s) << ','
        << fmt(r.time_p99_s) << ',' << fmt(r.n_dofs) << '\n';
  }
  return csv.str();
}

std::string table_markdown(const Scene& scene, const std::vector<SweepRow>& rows, const std::string& finest,
                           const nlohmann::json& provenance, const std::vector<std::string>& plots) {
  std::ostringstream md;
  md << "# Accuracy against cost: " << scene.name << "\n\n";
  md << "Every fidelity knob varied one at a time around the scene's values (baseline rows marked). Error "
        "against the finest FEM reference (" << finest << "): force RMSE over the insertion phase and the RMS "
        "puncture-depth error over the layers both models puncture (missed = punctured by one model only). "
        "Cost: real-time = wall time of one haptic tick over the ticks with contact (the tip below the skin "
        "surface or a layer pressed: where the work is), mean and 99th percentile; FEM = wall time per "
        "quasi-static load step.\n\n";
  md << "- command: `" << provenance.value("command", "") << "`\n";
  md << "- program " << provenance.value("program_version", "") << ", git revision "
     << provenance.value("git_revision", "") << "; machine: " << provenance.value("machine", "")
     << "; date (UTC): " << provenance.value("date_utc", "") << "\n\n";
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

}  // namespace

int sweep_command(const SweepOptions& options, std::ostream& out, std::ostream& err) {
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  return report_errors(err, scene_path.string(), [&]() -> int {
    const Scene scene = load_scene(scene_path);
    const std::filesystem::path dir =
        options.output_dir.empty() ? std::filesystem::path("out") / (scene.name + "_accuracy_cost") : options.output_dir;
    auto progress = [&](const std::string& line) {
      if (!options.quiet) out << "[sweep] " << line << '\n' << std::flush;
    };
    std::vector<SweepRow> rows;

    // 2. FEM settings; the finest (most DoFs) is the reference.
    std::vector<FemKnob> fem_knobs = options.include_fem_knobs ? kFemKnobs
                                                               : std::vector<FemKnob>{{scene.fem.refinement,
                                                                                       scene.fem.element_degree}};
    struct FemResult {
      FemKnob knob;
      FemReference ref;
      validation::InsertionCurve curve;
      nlohmann::json summary;
    };
    std::vector<FemResult> fem_results;
    for (const FemKnob& k : fem_knobs) {
      progress("FEM refinement " + std::to_string(k.refinement) + " Q" + std::to_string(k.degree));
      FemReferenceOptions fo;
      if (!options.cache_dir.empty()) fo.cache_dir = options.cache_dir;
      fo.refinement = k.refinement;
      fo.degree = k.degree;
      fo.write_vtu = false;
      fo.verbose = !options.quiet;
      FemResult r{k, obtain_fem_reference(scene, fo, out), {}, {}};
      r.curve = validation::read_insertion_curve(r.ref.dir / "fem_force_depth.csv");
      r.summary = nlohmann::json::parse(read_text(r.ref.dir / "fem_summary.json"));
      fem_results.push_back(std::move(r));
    }
    if (!is_mpi_root()) return 0;  // the other ranks only help with the FEM
    const auto finest_it = std::max_element(fem_results.begin(), fem_results.end(), [](const auto& a, const auto& b) {
      return a.summary.value("n_dofs", 0.0) < b.summary.value("n_dofs", 0.0);
    });
    const FemResult& finest = *finest_it;
    const std::string finest_name = "FEM refinement " + std::to_string(finest.knob.refinement) + " Q" +
                                    std::to_string(finest.knob.degree) + ", " +
                                    fmt(finest.summary.value("n_dofs", 0.0), 10) + " DoFs";
    progress("reference: finest " + finest_name);
    for (const FemResult& r : fem_results) {
      SweepRow row;
      row.model = "fem";
      row.knob = "refinement_degree";
      row.value = "r" + std::to_string(r.knob.refinement) + "_Q" + std::to_string(r.knob.degree);
      row.baseline = r.knob.refinement == scene.fem.refinement && r.knob.degree == scene.fem.element_degree;
      row.time_kind = "FEM wall time per load step";
      row.n_dofs = r.summary.value("n_dofs", 0.0);
      const double steps = r.summary.value("load_steps", 0.0);
      row.time_per_step_s = steps > 0 ? r.summary.value("wall_time_s", 0.0) / steps : kNaN;
      fill_errors(row, r.curve, finest.curve);
      rows.push_back(row);
    }

    // 3. Real-time knobs, one at a time.
    const validation::InsertionCurve& reference = finest.curve;
    auto run_variant = [&](const Scene& variant, const std::string& knob, const std::string& value, bool baseline) {
      progress("real-time " + knob + " = " + value);
      rows.push_back(realtime_variant(variant, knob, value, baseline, reference));
      if (!options.quiet && rows.back().status != "ok") out << "[sweep]   " << rows.back().status << '\n';
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

    // 5. Outputs.
    std::string command_line = "puncture sweep " + scene_path.string() + " -o " + dir.string();
    if (!options.include_fem_knobs) command_line += " --no-fem-knobs";
    const nlohmann::json provenance = provenance_json(command_line);
    io::OutputSession session(dir);
    session.write_text("accuracy_cost.csv", table_csv(rows));
    nlohmann::json j;
    j["provenance"] = provenance;
    j["scene"] = {{"name", scene.name}, {"file", scene_path.string()}};
    j["reference"] = {{"description", finest_name}, {"hash", finest.ref.hash}};
    j["cost"] = "real-time: time_per_step_s = mean and time_p99_s = 99th percentile of the tick wall time over the "
                "ticks with contact (tip below the skin surface or a layer pressed); FEM: wall time per load step";
    nlohmann::json fem_json = nlohmann::json::array();
    for (const FemResult& r : fem_results) fem_json.push_back({{"hash", r.ref.hash}, {"summary", r.summary}});
    j["fem_runs"] = fem_json;
    session.write_text("accuracy_cost.json", j.dump(2) + "\n");
    session.commit();
    const std::vector<std::string> plots = run_plot_script("plot_sweep.py", dir, out, err);
    io::OutputSession md_session(dir);
    md_session.write_text("accuracy_cost.md", table_markdown(scene, rows, finest_name, provenance, plots));
    md_session.commit();

    out << "\nAccuracy against cost (" << rows.size() << " variants; reference " << finest_name << ")\n";
    for (const SweepRow& r : rows)
      out << "  " << std::left << std::setw(9) << r.model << std::setw(18) << r.knob << std::setw(14) << r.value
          << std::right << " force RMSE " << std::setw(10) << fmt(r.force_rmse_N, 4) << " N   depth error "
          << std::setw(9) << fmt(r.puncture_depth_error_mm, 4) << " mm   step " << fmt(r.time_per_step_s, 4) << " s"
          << (r.status == "ok" ? "" : "   " + r.status) << '\n';
    out << "Table: " << (dir / "accuracy_cost.md").string() << '\n';
    return 0;
  });
}

}  // namespace puncture::apps
