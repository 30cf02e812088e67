// `puncture sweep`: what accuracy costs in time.
//
// The real-time force compared is the whole force, the damping force d h v
// included (as in validate and calibrate).
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
#include <functional>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "command_errors.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/validation/fem_reference.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/io/provenance_json.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/metrics.hpp"
#include "puncture/validation/recording.hpp"
#include "puncture/io/atomic_file.hpp"
#include "puncture/validation/fem_comparison.hpp"
#include "puncture/validation/sweep.hpp"

namespace puncture::apps {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
using validation::SweepRow;

std::string fmt(double x, int precision) {
  if (!std::isfinite(x)) return "nan";
  std::ostringstream s;
  s << std::setprecision(precision) << x;
  return s.str();
}

struct FemKnob {
  int refinement;
  int degree;
};
/// The default FEM part: what finishes in about a quarter of an hour on 2 cores.
const std::vector<FemKnob> kFemKnobs{{0, 1}, {0, 2}, {1, 1}};

/// One FEM setting's reference: the cached run, its curve and summary.
struct FemResult {
  FemKnob knob;
  validation::FemReference ref;
  validation::InsertionCurve curve;
  nlohmann::json summary;
};

/// The FEM references at every FEM setting of the sweep (cached).
std::vector<FemResult> fem_references(const Scene& scene, const SweepOptions& options, std::ostream& out,
                                      const std::function<void(const std::string&)>& progress) {
  const std::vector<FemKnob> knobs =
      options.include_fem_knobs ? kFemKnobs : std::vector<FemKnob>{{scene.fem.refinement, scene.fem.element_degree}};
  std::vector<FemResult> results;
  for (const FemKnob& k : knobs) {
    progress("FEM refinement " + std::to_string(k.refinement) + " Q" + std::to_string(k.degree));
    validation::FemReferenceOptions fo;
    if (!options.cache_dir.empty()) fo.cache_dir = options.cache_dir;
    fo.refinement = k.refinement;
    fo.degree = k.degree;
    fo.write_vtu = false;
    fo.verbose = !options.quiet;
    FemResult r{k, validation::obtain_fem_reference(scene, fo, out), {}, {}};
    r.curve = validation::read_insertion_curve(r.ref.dir / "fem_force_depth.csv");
    r.summary = nlohmann::json::parse(io::read_text_file(r.ref.dir / "fem_summary.json"));
    results.push_back(std::move(r));
  }
  return results;
}

std::string fem_name(const FemResult& r) {
  return "FEM refinement " + std::to_string(r.knob.refinement) + " Q" + std::to_string(r.knob.degree) + ", " +
         fmt(r.summary.value("n_dofs", 0.0), 10) + " DoFs";
}

/// One row per FEM setting against the finest.
void add_fem_rows(const Scene& scene, const std::vector<FemResult>& fem, const FemResult& finest,
                  std::vector<SweepRow>& rows) {
  for (const FemResult& r : fem) {
    SweepRow row;
    row.model = "fem";
    row.knob = "refinement_degree";
    row.value = "r" + std::to_string(r.knob.refinement) + "_Q" + std::to_string(r.knob.degree);
    row.baseline = r.knob.refinement == scene.fem.refinement && r.knob.degree == scene.fem.element_degree;
    row.time_kind = "FEM wall time per load step";
    row.n_dofs = r.summary.value("n_dofs", 0.0);
    const double steps = r.summary.value("load_steps", 0.0);
    row.time_per_step_s = steps > 0 ? r.summary.value("wall_time_s", 0.0) / steps : kNaN;
    validation::fill_sweep_errors(row, r.curve, finest.curve);
    rows.push_back(row);
  }
}

/// accuracy_cost.csv, .json, the plots and accuracy_cost.md in dir.
void write_sweep_outputs(const Scene& scene, const std::filesystem::path& scene_path, const std::filesystem::path& dir,
                         const SweepOptions& options, const std::vector<SweepRow>& rows,
                         const std::vector<FemResult>& fem, const FemResult& finest, std::ostream& out,
                         std::ostream& err) {
  std::string command_line = "puncture sweep " + scene_path.string() + " -o " + dir.string();
  if (!options.include_fem_knobs) command_line += " --no-fem-knobs";
  const io::Provenance provenance = io::make_provenance(command_line);
  io::OutputSession session(dir);
  session.write_text("accuracy_cost.csv", validation::sweep_table_csv(rows, provenance));
  nlohmann::json j;
  j["provenance"] = io::provenance_json(provenance);
  j["scene"] = {{"name", scene.name}, {"file", scene_path.string()}};
  j["reference"] = {{"description", fem_name(finest)}, {"hash", finest.ref.hash}};
  j["cost"] = "real-time: time_per_step_s = mean and time_p99_s = 99th percentile of the tick wall time over the "
              "ticks with contact (tip below the skin surface or a layer pressed); FEM: wall time per load step";
  nlohmann::json fem_json = nlohmann::json::array();
  for (const FemResult& r : fem) fem_json.push_back({{"hash", r.ref.hash}, {"summary", r.summary}});
  j["fem_runs"] = fem_json;
  session.write_text("accuracy_cost.json", j.dump(2) + "\n");
  session.commit();
  const std::vector<std::string> plots = validation::run_plot_script("plot_sweep.py", dir, out, err);
  io::OutputSession md_session(dir);
  md_session.write_text("accuracy_cost.md",
                        validation::sweep_table_markdown(scene, rows, fem_name(finest), provenance, plots));
  md_session.commit();
}

void print_sweep_table(const std::vector<SweepRow>& rows, const std::string& reference,
                       const std::filesystem::path& dir, std::ostream& out) {
  out << "\nAccuracy against cost (" << rows.size() << " variants; reference " << reference << ")\n";
  for (const SweepRow& r : rows)
    out << "  " << std::left << std::setw(9) << r.model << std::setw(18) << r.knob << std::setw(14) << r.value
        << std::right << " force RMSE " << std::setw(10) << fmt(r.force_rmse_N, 4) << " N   depth error "
        << std::setw(9) << fmt(r.puncture_depth_error_mm, 4) << " mm   step " << fmt(r.time_per_step_s, 4) << " s"
        << (r.status == "ok" ? "" : "   " + r.status) << '\n';
  out << "Table: " << (dir / "accuracy_cost.md").string() << '\n';
}

}  // namespace

int sweep_command(const SweepOptions& options, std::ostream& stdout_stream, std::ostream& err) {
  NullStream quiet;
  std::ostream& out = options.quiet ? quiet : stdout_stream;
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  return report_errors(err, scene_path.string(), [&]() -> int {
    const Scene scene = load_scene(scene_path);
    const std::filesystem::path dir =
        options.output_dir.empty() ? std::filesystem::path("out") / (scene.name + "_accuracy_cost") : options.output_dir;
    auto progress = [&](const std::string& line) { out << "[sweep] " << line << '\n' << std::flush; };
    // 1. FEM settings; the finest (most DoFs) is the reference.
    const std::vector<FemResult> fem = fem_references(scene, options, out, progress);
    if (!validation::is_mpi_root()) return 0;  // the other ranks only help with the FEM
    const FemResult& finest = *std::max_element(fem.begin(), fem.end(), [](const auto& a, const auto& b) {
      return a.summary.value("n_dofs", 0.0) < b.summary.value("n_dofs", 0.0);
    });
    progress("reference: finest " + fem_name(finest));
    std::vector<SweepRow> rows;
    add_fem_rows(scene, fem, finest, rows);
    // 2. Real-time knobs, one at a time, against the finest FEM.
    for (SweepRow& row : validation::sweep_realtime_knobs(scene, finest.curve, [&](const std::string& knob,
                                                                                   const std::string& value) {
           progress("real-time " + knob + " = " + value);
         })) {
      if (row.status != "ok") out << "[sweep]   " << row.status << '\n';
      rows.push_back(std::move(row));
    }
    // 3. Outputs.
    write_sweep_outputs(scene, scene_path, dir, options, rows, fem, finest, out, err);
    print_sweep_table(rows, fem_name(finest), dir, out);
    return 0;
  });
}

}  // namespace puncture::apps
