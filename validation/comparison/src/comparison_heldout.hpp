// comparison_heldout.hpp (internal to the comparison report): every model,
// identified once on the scene's trajectory, judged without retuning on the
// held-out cases of a cases file (validation_cases.hpp: other speeds, depths,
// slabs), each against the FEM reference of that case.
//
// run_heldout_cases(scene, model_scenes, options, out, err):
//   In:  the scene, each compared model's own scene (its identified critical
//        forces; the scene itself for the real-time model), the report
//        options (options.cases: the cases with their FEM directories).
//   Per held-out case (a case that is not held out is the calibration
//   trajectory, the main table): the case's overrides applied to each model's scene
//   (case_scene), a tetrahedral mesh of the case's slab when a volumetric
//   model is compared, every model run along the case's trajectory and
//   measured against the case's FEM (metrics_against_reference). The
//   (case, model) runs are independent and run two at a time, one per core
//   (their step times are those of a run beside one other).
//   Out: one row per case and model (ModelMetrics, the case's name and
//   whether it is held out).
// heldout_csv: those rows (heldout.csv).
// aggregate_heldout: one ModelMetrics per model over the held-out cases
//   (every case's layer punctures, for the ranking's puncture metric; means
//   of the force RMSE, |peak force error|, puncture depth error and
//   deflection RMSE; the largest step p99 and memory; the smallest completed
//   fraction), in the order of `models`: what the Sec. 3.3 ranking reads.
#pragma once

#include <functional>
#include <map>
#include <ostream>
#include <string>
#include <vector>

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

/// first_jobs: other independent runs (the volumetric models' runs on the
/// calibration trajectory) that the same two workers take first, before the
/// held-out runs; an exception of one is rethrown after every worker stopped.
std::vector<HeldOutRow> run_heldout_cases(const Scene& scene, const std::map<std::string, Scene>& model_scenes,
                                          const ComparisonReportOptions& options, std::ostream& out,
                                          std::ostream& err,
                                          const std::vector<std::function<void()>>& first_jobs = {});

std::string heldout_csv(const Scene& scene, const std::vector<HeldOutRow>& rows);

std::vector<ModelMetrics> aggregate_heldout(const std::vector<HeldOutRow>& rows, const std::vector<std::string>& models);

}  // namespace puncture::validation::comparison_report_detail
