// comparison_heldout.hpp (internal to the comparison report): every model,
// identified once on the scene's trajectory, judged without retuning on the
// held-out cases of a cases file (validation_cases.hpp: other speeds, depths,
// slabs), each against the FEM reference of that case.
//
// HeldOutRuns(scene, model_scenes, options, out, err):
//   In:  the scene, each compared model's own scene (its identified critical
//        forces; the scene itself for the real-time model), the report
//        options (options.cases: the cases with their FEM directories).
//   Per held-out case (a case that is not held out is the calibration
//   trajectory, the main table): the case's overrides applied to each model's scene
//   (case_scene), a tetrahedral mesh of the case's slab when a volumetric
//   model is compared (made in the constructor), every model run along the
//   case's trajectory and measured against the case's FEM
//   (metrics_against_reference). The (case, model) runs are independent jobs
//   of one queue, worked off two at a time, one per core (their step times
//   are those of a run beside one other): start_background() lets one thread
//   begin while the caller does other one-core work (the calibration
//   trajectory's runs); finish() makes the caller the second worker until the
//   queue is empty, joins, and returns one row per case and model
//   (ModelMetrics, the case's name and whether it is held out), in the
//   order of the cases and models.
// heldout_csv: those rows (heldout.csv).
// aggregate_heldout: one ModelMetrics per model over the held-out cases
//   (every case's layer punctures, for the ranking's puncture metric; means
//   of the force RMSE, |peak force error|, puncture depth error and
//   deflection RMSE; the largest step p99 and memory; the smallest completed
//   fraction), in the order of `models`: what the Sec. 3.3 ranking reads.
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

#include "comparison_runs.hpp"

#include "puncture/scene.hpp"
#include "puncture/validation/comparison_report.hpp"
#include "puncture/validation/model_comparison.hpp"

namespace puncture::validation::comparison_report_detail {

struct HeldOutRow {
  std::string case_name;
  bool held_out = true;
  ModelMetrics metrics;
  std::string failure;  ///< the model's run failure (empty when it completed)
  double wall_time_s = 0.0;  ///< the model's build and run on the case, s
};

/// One case as the models see it: its base scene, its FEM reference and, if
/// a volumetric model is compared, its own tetrahedral mesh (slab and depth).
struct CaseSetup {
  Scene base;
  ComparisonReference reference;
  std::shared_ptr<const comparison::TetMesh> mesh;
};

class HeldOutRuns {
 public:
  HeldOutRuns(const Scene& scene, const std::map<std::string, Scene>& model_scenes,
              const ComparisonReportOptions& options, std::ostream& out, std::ostream& err);
  ~HeldOutRuns();  ///< joins the background worker
  HeldOutRuns(const HeldOutRuns&) = delete;
  HeldOutRuns& operator=(const HeldOutRuns&) = delete;
  void start_background();
  std::vector<HeldOutRow> finish();

 private:
  void work();  ///< takes jobs off the queue until it is empty

  const ComparisonReportOptions& options_;
  const std::map<std::string, Scene> model_scenes_;  ///< a copy: the caller's map grows while the jobs run
  std::ostream& out_;
  std::ostream& err_;
  std::vector<CaseSetup> setups_;
  std::vector<std::pair<std::size_t, std::string>> jobs_;  ///< (case index, model key)
  std::vector<HeldOutRow> rows_;
  std::atomic<std::size_t> next_{0};
  std::mutex report_mutex_;
  std::thread background_;
};

std::string heldout_csv(const Scene& scene, const std::vector<HeldOutRow>& rows);

std::vector<ModelMetrics> aggregate_heldout(const std::vector<HeldOutRow>& rows, const std::vector<std::string>& models);

}  // namespace puncture::validation::comparison_report_detail
