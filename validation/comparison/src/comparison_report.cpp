// write_model_comparison: the report of `puncture compare` (see
// comparison_report.hpp), top-down: the FEM reference's files, the mesh,
// every model, the identifications, the metrics and grading, the files.
#include "puncture/validation/comparison_report.hpp"

#include <algorithm>
#include <chrono>
#include <functional>

#include "comparison_heldout.hpp"
#include "comparison_runs.hpp"
#include "comparison_tables.hpp"
#include "puncture/comparison/model_factory.hpp"
#include "puncture/comparison/sparse_spd_factor.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/io/provenance_json.hpp"
#include "puncture/io/pvd.hpp"

namespace puncture::validation {

using namespace comparison_report_detail;

ComparisonOutcome write_model_comparison(const Scene& scene, const DelphiWeights& weights,
                                         const ComparisonFemReference& fem, const ComparisonReportOptions& options,
                                         std::ostream& out, std::ostream& err) {
  const ComparisonReference reference = read_comparison_reference(scene, fem.dir);
  io::OutputSession session(options.output_dir);
  const nlohmann::json provenance = io::provenance_json(io::make_provenance(options.command_line));
  const ComparisonMesh mesh = build_comparison_mesh(scene, options, session, out);

  if (const std::string limit = comparison::concurrent_solver_limit(); !limit.empty()) err << "warning: " << limit << "\n";
  ComparisonRunner runner(scene, options, reference, mesh.mesh, session, out, err);
  // The real-time model is the scene's (`puncture calibrate` tunes it);
  // every other model is identified against the FEM first, two at a time.
  std::vector<std::string> to_identify;
  for (const std::string& key : options.models)
    if (options.identify_models && key != "realtime" && key != "fem") to_identify.push_back(key);
  double identification_wall_time_s = 0.0;
  const std::map<std::string, Scene> identified = runner.identify_models(to_identify, identification_wall_time_s);
  // Then each model's run on the calibration trajectory: the light ones now,
  // one at a time; the volumetric ones (minutes each) side by side with each
  // other and with the held-out runs, two at a time (one per core; their
  // time per step, a column of the tables, is that of a run beside one other,
  // as the held-out runs' always was).
  std::vector<std::function<void()>> volumetric_runs;
  std::vector<std::string> run_beside_others;
  for (const std::string& key : options.models) {
    if (key == "fem") continue;
    const auto it = identified.find(key);
    const Scene& model_scene = it != identified.end() ? it->second : scene;
    const std::size_t slot = runner.add_slot(key, model_scene, key);
    if (comparison::is_volumetric_model(key)) {
      volumetric_runs.push_back([&runner, slot, key, &model_scene]() { runner.run_in_slot(slot, key, model_scene, key); });
      run_beside_others.push_back(key);
    } else {
      runner.run_in_slot(slot, key, model_scene, key);
    }
  }
  // Held out: every model as identified above, on the cases' trajectories and slabs.
  const auto pool_start = std::chrono::steady_clock::now();
  const std::vector<HeldOutRow> heldout =
      run_heldout_cases(scene, runner.model_scenes(), options, out, err, volumetric_runs);
  const double pool_wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - pool_start).count();
  nlohmann::json identification = nlohmann::json::array();
  for (const std::string& method : options.identify) identification.push_back(runner.identify(method));

  const std::vector<std::unique_ptr<ModelRun>>& runs = runner.runs();
  const bool with_fem_row = std::find(options.models.begin(), options.models.end(), "fem") != options.models.end();
  const ComparisonRows rows = comparison_rows(scene, runs, reference, with_fem_row);
  session.write_text("comparison.csv", comparison_csv(scene, rows));
  session.write_text("fem_curve.csv", insertion_curve_csv(reference.fem.curve));
  session.write_text("deflection_profiles.csv", deflection_profiles_csv(reference.data, runs));
  ComparisonOutcome outcome;
  outcome.metrics = rows.metrics;
  outcome.grade = grade_models(rows.metrics, weights);
  outcome.has_shaft_forces = reference.data.has_shaft_forces;
  session.write_text("ranking.csv", ranking_csv(outcome.grade));
  if (!heldout.empty()) {
    session.write_text("heldout.csv", heldout_csv(scene, heldout));
    outcome.heldout_metrics = aggregate_heldout(heldout, options.models);
    if (with_fem_row) outcome.heldout_metrics.push_back(rows.metrics.back());  // the reference: no error by definition
    outcome.heldout_grade = grade_models(outcome.heldout_metrics, weights);
    session.write_text("ranking_heldout.csv", ranking_csv(outcome.heldout_grade));
  }
  const double wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - options.wall_start).count();
  const ComparisonContent content{scene,         options, fem,     reference,      mesh,
                                  provenance,    runs,    identification, runner.identification_records(),
                                  rows,          outcome.grade, heldout, outcome,  weights,
                                  wall_time_s,   identification_wall_time_s, pool_wall_time_s,
                                  run_beside_others};
  session.write_text("comparison_summary.json", summary_json(content).dump(2) + "\n");
  if (!runner.pvd().empty()) {
    std::vector<io::PvdEntry> pvd = runner.pvd();  // in the order the frames were written: sorted by part and time
    std::stable_sort(pvd.begin(), pvd.end(), [](const io::PvdEntry& a, const io::PvdEntry& b) {
      return a.part != b.part ? a.part < b.part : a.time_s < b.time_s;
    });
    io::write_pvd(session, "comparison.pvd", pvd);
  }
  session.commit();

  const std::vector<std::string> plots = run_plot_script("plot_comparison.py", options.output_dir, out, err);
  io::OutputSession md_session(options.output_dir);
  md_session.write_text("comparison.md", comparison_markdown(content, plots));
  md_session.commit();
  return outcome;
}

}  // namespace puncture::validation
