// model_comparison.hpp: every comparison model on the identical insertion,
// measured against the FEM reference (issue: same slab, same needle, same
// insertion; accuracy against the reference, cost per step, memory).
//
// run_comparison_model(model, scene, options):
//   drives a ComparisonModel (core/models) one haptic step at a time
//   (dt = 1 / realtime.haptic_rate_Hz) along the scene's scripted trajectory
//   (approach, insertion, dwell, withdrawal), timing every step, and records
//   per step: time, depth, velocity, the contact force, the post-puncture
//   (shaft) force of the scene's force law and the layer states. The shaft
//   force is computed from the model's layer states with the same formulas
//   for every model: Table 1 d h v of every punctured layer (effect
//   `damping`, puncture_force.hpp), Karnopp shaft friction (effect
//   `friction`, shaft_friction.hpp) and the cutting force of the last
//   punctured layer while the next is untouched (effect `cutting`,
//   cutting.hpp); the real-time model's contact force is its tip force;
//   the skin's surface deflection at the requested depths and radii; frames
//   for ParaView through a callback. A model that throws is recorded as
//   failed (its message kept) from that step on.
// metrics_against_reference(run, reference, ...): accuracy and cost of a run
//   (ModelMetrics, see the fields).
#pragma once

#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "puncture/comparison/comparison_model.hpp"
#include "puncture/scene.hpp"
#include "puncture/validation/metrics.hpp"

namespace puncture::validation {

/// The skin surface deflection (m, > 0 into the tissue) at one needle depth.
struct SurfaceSnapshot {
  double depth_m = 0.0;  ///< the requested depth (taken at the first step at or past it)
  std::vector<double> r_m;
  std::vector<double> deflection_m;
};

struct ModelRun {
  std::string model;
  std::string description;
  std::vector<double> time_s, depth_m, velocity_m_per_s;
  std::vector<double> contact_force_N;       ///< the model's own contact force
  std::vector<double> post_puncture_force_N; ///< shaft forces: cutting, friction, d h v (0 with those effects off)
  std::vector<std::vector<LayerState>> states;  ///< [step][layer]
  std::vector<double> step_wall_time_s;
  std::vector<SurfaceSnapshot> skin_profiles;
  comparison::ModelSize size;
  long recovered_steps = 0;
  std::string integrator_report;
  double build_wall_time_s = 0.0;
  double run_wall_time_s = 0.0;
  /// Volumetric models with ModelRunOptions::measure_inversion: the deformed
  /// mesh's worst moment (element_inversion.hpp), sampled every
  /// kInversionSampleSteps haptic steps and at the last one.
  long inverted_elements_max = -1;  ///< -1: not measured (no tetrahedral mesh, or not asked)
  double inverted_share_max = std::numeric_limits<double>::quiet_NaN();  ///< of the remaining tetrahedra, at that sample
  double first_inversion_depth_m = std::numeric_limits<double>::quiet_NaN();  ///< needle depth of the first inverted sample (NaN: none)
  double min_volume_ratio = std::numeric_limits<double>::quiet_NaN();       ///< smallest J = V / V0 sampled
  std::string failure;  ///< empty when the run completed

  bool failed() const { return !failure.empty(); }
  std::size_t steps() const { return time_s.size(); }
};

using ModelFrameCallback = std::function<void(const comparison::ComparisonModel&, double time_s, int frame)>;
using RunProgress = std::function<void(double fraction_done)>;

struct ModelRunOptions {
  /// Record the skin surface deflection when the needle first reaches each of
  /// these depths during the insertion (m), at these radii (m).
  std::vector<double> profile_depths_m;
  std::vector<double> profile_radii_m;
  /// Frames for ParaView: the callback is called at t = 0 and then every
  /// frame_interval_s (0: never).
  double frame_interval_s = 0.0;
  ModelFrameCallback on_frame;
  RunProgress on_progress;
  /// Stop after this time (s; <= 0: the whole trajectory).
  double end_time_s = -1.0;
  /// Sample the volumetric models' inverted tetrahedra (ModelRun; one sweep
  /// over the mesh per sample; the identification's partial runs skip it).
  bool measure_inversion = false;
};

/// Haptic steps between two samples of a run's inverted tetrahedra (10 ms at 1 kHz).
inline constexpr long kInversionSampleSteps = 10;

ModelRun run_comparison_model(comparison::ComparisonModel& model, const Scene& scene,
                              const ModelRunOptions& options = {});

/// The run as an insertion curve (force = contact force, plus the
/// post-puncture force when include_post_puncture) in the shared reader's
/// schema.
InsertionCurve curve_from_model_run(const Scene& scene, const ModelRun& run, bool include_post_puncture);

struct LayerPunctureComparison {
  std::string layer;
  bool reference_punctured = false, model_punctured = false;
  double reference_depth_m = std::numeric_limits<double>::quiet_NaN();
  double model_depth_m = std::numeric_limits<double>::quiet_NaN();
};

/// Accuracy and cost of one model against the reference. NaN marks a metric
/// that cannot be computed (no common sample, no puncture in both, no
/// withdrawal in the reference); tables print it as "n/a".
struct ModelMetrics {
  std::string model;
  std::size_t compared_samples = 0;
  double force_rmse_N = std::numeric_limits<double>::quiet_NaN();
  double force_rmse_relative = std::numeric_limits<double>::quiet_NaN();  ///< / reference peak
  double reference_peak_force_N = std::numeric_limits<double>::quiet_NaN();
  double model_peak_force_N = std::numeric_limits<double>::quiet_NaN();
  double peak_force_error_relative = std::numeric_limits<double>::quiet_NaN();  ///< (model - reference) / reference peak
  double withdrawal_force_rmse_N = std::numeric_limits<double>::quiet_NaN();
  std::vector<LayerPunctureComparison> punctures;
  double puncture_depth_error_m = std::numeric_limits<double>::quiet_NaN();  ///< mean |model - reference| over layers both puncture
  int puncture_layers_disagreeing = 0;  ///< layers punctured by one of the two only
  double deflection_rmse_m = std::numeric_limits<double>::quiet_NaN();       ///< skin u_z(r) before the skin breaks
  double deflection_rmse_relative = std::numeric_limits<double>::quiet_NaN();///< / max reference deflection
  std::size_t deflection_depths = 0;
  double step_time_mean_s = std::numeric_limits<double>::quiet_NaN();  ///< over steps with the tip in the tissue
  double step_time_p99_s = std::numeric_limits<double>::quiet_NaN();
  double step_time_max_s = std::numeric_limits<double>::quiet_NaN();
  double completed_fraction = 0.0;  ///< steps completed / trajectory steps (1 unless the model failed)
  double memory_bytes = std::numeric_limits<double>::quiet_NaN();  ///< the model's own data (ModelSize)
  long dofs = 0;
  /// Deformed-mesh validity (ModelRun; NaN: no tetrahedral mesh or not measured).
  double inverted_share_max = std::numeric_limits<double>::quiet_NaN();
  double first_inversion_depth_m = std::numeric_limits<double>::quiet_NaN();
  double min_volume_ratio = std::numeric_limits<double>::quiet_NaN();
};

/// Reference side of the comparison: the FEM curve and its surface profiles
/// of the skin (u_z(r), z up), one per recorded depth.
struct ReferenceData {
  InsertionCurve curve;
  std::vector<RadialProfile> skin_profiles;
  bool has_shaft_forces = false;  ///< the curve includes cutting/friction: compare totals
};

ModelMetrics metrics_against_reference(const Scene& scene, const ModelRun& run, const ReferenceData& reference,
                                       std::size_t total_steps);

/// p-quantile (0..1) of the values (linear between order statistics).
double quantile(std::vector<double> values, double p);

}  // namespace puncture::validation
