// calibration.hpp: tunes the per-layer force-mesh parameters of a scene so
// that the real-time model's insertion curve matches reference curves.
//
// In:  a Scene (SI units; its geometry, insertion and settings are kept), one
//      or more reference InsertionCurves (FEM, measured, or synthetic) and
//      CalibrationOptions.
// Out: CalibrationResult: the tuned Scene, parameters and metrics before and
//      after, the optimiser's record; write_tuned_preset() writes it as a
//      scene file plus a provenance file.
//
// What is tuned (per layer, switchable in CalibrationOptions::parameters):
//   K (virtual_stiffness), deformed_threshold, surface_stiffness, L (spacing)
//   and d (damping) are continuous; they are optimised in log space,
//   x = log(p), inside [p0 / bound_factor, p0 * bound_factor]; w (rings) is an
//   integer, enumerated over w0 - r .. w0 + r (r = rings_search_radius, w >= 2,
//   force mesh inside the sample) with a full continuous optimisation for
//   each w; the best w wins.
// Identifiability (quasi-static force mesh on a flat layer top): the force
//   before breakthrough is S(K, k_s, w) * z0 and the layer breaks at
//   z0 = threshold / u_w(K / k_s, w). A force-depth curve fixes two numbers
//   per layer (slope and breakthrough point), so by default only K and the
//   threshold are tuned; k_s and L change the ring deflection profile and
//   are only identifiable with a deflection-profile reference (L does not
//   enter the quasi-static force at all). d is tuned only when a reference
//   carries rate information (see DampingPolicy).
// Sequential stages (what we do): layers are calibrated top to bottom. The
//   stage of layer k tunes layer k's parameters on the reference samples down
//   to the reference puncture depth of layer k plus depth_margin_m (the
//   layers below are not reached before layer k breaks, and the layers above
//   are already tuned). The model itself runs the whole insertion, so that
//   its breakthrough of layer k is found even when a start value moves it
//   far beyond the reference's (the puncture-depth term then stays a smooth
//   guide instead of a flat "missing" penalty). When d is tuned, a final
//   stage tunes the d of all calibrated layers together on the whole
//   insertion phase.
// Objective of a stage, summed over the references (dimensionless):
//   w_rmse (RMSE / peak)^2 over the compared samples
//   + sum over the stage's layers: w_layer (layer RMSE / peak)^2
//     + w_depth (puncture depth error / min(ring spacing L, layer thickness))^2
//     + w_force (puncture force error / reference puncture force)^2
//     + w_missing if exactly one of model and reference punctures the layer.
// Model runs: a copy of the scene with realtime.integrator =
//   options.integrator (default "quasi_static"), no frames, dwell 0, a fast
//   withdrawal (not compared), the damping effect off when the reference is
//   quasi-static (reference_is_quasi_static: the FEM), the insertion speed of the reference (its
//   metadata "speed_mm_per_s" if present, else the scene's), and a haptic rate
//   raised so that one tick moves the needle at most objective_depth_step_m
//   (sharper breakthrough depths; for the quasi-static mesh the tick rate does
//   not change the force). The SH layer surfaces depend only on geometry and
//   degree: they are fitted once per calibrate() call (SurfaceCache).
// A candidate whose run throws (e.g. a non-finite force) gets the objective
//   kFailedObjective; it is counted, never returned as a result.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "puncture/model/realtime_model.hpp"
#include "puncture/scene.hpp"
#include "puncture/sh/layer_surface.hpp"
#include "puncture/validation/metrics.hpp"

namespace puncture::io {
class OutputSession;
}

namespace puncture::validation {

constexpr double kFailedObjective = 1e6;

enum class CalibrationMethod { Bobyqa, NelderMead, SimulatedAnnealing };
/// "bobyqa", "nelder_mead", "simulated_annealing" (std::invalid_argument otherwise).
CalibrationMethod parse_calibration_method(const std::string& name);
const char* to_string(CalibrationMethod method);

/// When the damping d is tuned. Auto: only if a reference has the metadata
/// line "# rate_dependent: true" (a measured curve, ideally at two or more
/// speeds); the quasi-static FEM reference has no rate dependence, so d is
/// kept fixed against it.
enum class DampingPolicy { Auto, Fixed, Tune };

struct TunedParameterSet {
  bool virtual_stiffness = true;   ///< K
  bool deformed_threshold = true;  ///< ring deformation threshold
  bool surface_stiffness = false;  ///< k_s (needs a deflection profile to be identifiable)
  bool spacing = false;            ///< L (needs a deflection profile)
  bool rings = false;              ///< w (integer, enumerated)
  DampingPolicy damping = DampingPolicy::Auto;
};

/// Weights of the objective terms (see the header comment).
struct CalibrationWeights {
  double overall_rmse = 1.0;
  double layer_rmse = 1.0;
  double puncture_depth = 1.0;
  double puncture_force = 1.0;
  double missing_puncture = 1.0;
};

/// GSL gsl_siman schedule (temperatures in units of the starting objective,
/// the energy is objective / objective at the start point).
struct AnnealingSettings {
  int iters_fixed_T = 20;        ///< evaluations per temperature
  double step_size = 0.15;       ///< max move per log-parameter per step
  double t_initial = 0.05;
  double mu_t = 1.3;             ///< cooling factor
  double t_min = 1e-4;
  unsigned long seed = 12345;
  bool polish_locally = true;      ///< local Nelder-Mead (with restarts) from the annealing's best point
};

struct CalibrationOptions {
  /// Nelder-Mead by default: the objective is piecewise smooth with small
  /// steps where a breakthrough moves by one tick, and in our identifiability
  /// tests BOBYQA's quadratic models stalled in the K-threshold valley (a few
  /// % off) where Nelder-Mead reached the known values.
  CalibrationMethod method = CalibrationMethod::NelderMead;
  std::vector<std::string> layers;  ///< layers to calibrate; empty = all (always processed top to bottom)
  TunedParameterSet parameters;
  CalibrationWeights weights;
  double bound_factor = 3.0;        ///< each continuous parameter stays in [p0 / f, p0 f]
  int rings_search_radius = 1;
  int max_evaluations_per_stage = 300;  ///< NLopt evaluation budget per stage and w (shared by restarts)
  double log_x_tolerance = 1e-4;    ///< NLopt xtol_abs in log space (1e-4 = 0.01 %)
  std::string integrator = "quasi_static";
  double objective_depth_step_m = 2e-6;  ///< breakthrough depth resolution of the objective's model runs
  double depth_margin_m = 1e-3;     ///< stage range beyond the layer's reference puncture depth
  /// Start each layer's stage from the scene's values scaled to the first
  /// reference's pressing slope and breakthrough deflection (see calibration.cpp,
  /// scaled_start); the local optimiser then refines.
  bool scaled_start = true;
  AnnealingSettings annealing;
};

struct CalibrationProgress {
  int evaluations = 0;              ///< model runs so far (all stages)
  double best_objective = 0.0;      ///< best objective of the current stage
  double last_objective = 0.0;
  std::string stage;                ///< e.g. "skin (w = 8)" or "damping"
};
using CalibrationProgressCallback = std::function<void(const CalibrationProgress&)>;

/// The tunable parameters of one layer, SI.
struct LayerParameters {
  std::string layer;
  double virtual_stiffness_N_per_m = 0.0;
  double damping_N_s_per_m2 = 0.0;
  int rings_w = 0;
  double spacing_L_m = 0.0;
  double surface_stiffness_N_per_m = 0.0;
  double deformed_threshold_m = 0.0;
};
std::vector<LayerParameters> layer_parameters(const Scene& scene);

/// A reference curve and what it is ("fem", "measured", "synthetic", ...).
struct ReferenceCurve {
  InsertionCurve curve;
  std::string kind = "fem";
};
/// True for the FEM reference (kind "fem") or a curve whose metadata says
/// "quasi_static: true" (or yes / 1): no rate dependence and no friction, so
/// the model runs compared with it leave the damping force d h v out.
bool reference_is_quasi_static(const ReferenceCurve& reference);
/// True if the curve's metadata says "rate_dependent: true" (or yes / 1).
bool reference_is_rate_dependent(const InsertionCurve& curve);

struct CalibrationStageRecord {
  std::string stage;
  int evaluations = 0;
  double objective_start = 0.0;
  double objective_best = 0.0;
  std::string nlopt_result;         ///< NLopt return code name, or "annealing"
};

struct CalibrationResult {
  Scene tuned_scene;
  std::vector<LayerParameters> initial;
  std::vector<LayerParameters> tuned;
  std::vector<CurveComparison> before;  ///< one per reference, full insertion phase
  std::vector<CurveComparison> after;
  std::vector<InsertionCurve> model_before;  ///< the model curves those comparisons were made with
  std::vector<InsertionCurve> model_after;
  double objective_before = 0.0;        ///< sum of the stage objectives at the start values
  double objective_after = 0.0;
  int evaluations = 0;
  bool damping_tuned = false;
  std::string damping_note;
  std::vector<CalibrationStageRecord> stages;
  std::vector<std::string> calibrated_layers;
};

/// SH layer surfaces of a scene, fitted once; build() assembles a real-time
/// model for any scene with the same geometry and SH degree (what
/// build_realtime_model does, without refitting).
class SurfaceCache {
 public:
  explicit SurfaceCache(const Scene& scene);
  bool matches(const Scene& scene) const;
  /// Throws std::invalid_argument if !matches(scene).
  RealtimeModel build(const Scene& scene) const;

 private:
  std::vector<double> thickness_m_;
  double diameter_m_ = 0.0;
  int degree_ = 0;
  std::vector<LayerSurface> surfaces_;
  std::vector<LayerSurfaceFitInfo> fits_;
};

/// Runs the scene's scripted insertion (build_realtime_model or the cache,
/// then run_scripted_insertion) and returns its curve.
InsertionCurve simulate_insertion_curve(const Scene& scene, const SurfaceCache* cache = nullptr);

/// The scene of the model runs the objective compares with `reference`
/// (integrator, speed, dwell, tick rate as described in the header comment;
/// whole insertion): what a report should plot before and after.
Scene calibration_run_scene(const Scene& scene, const ReferenceCurve& reference, const CalibrationOptions& options);

CalibrationResult calibrate(const Scene& scene, const std::vector<ReferenceCurve>& references,
                            const CalibrationOptions& options = {}, const CalibrationProgressCallback& progress = {});
/// One reference curve; its kind is its "kind" metadata, else "curve" (not
/// quasi-static unless its metadata says "quasi_static: true").
CalibrationResult calibrate(const Scene& scene, const InsertionCurve& reference, const CalibrationOptions& options = {},
                            const CalibrationProgressCallback& progress = {});

/// Writes <name>.json (a scene file `puncture run` accepts: the tuned scene,
/// renamed to `name`) and <name>.provenance.json (references with kind,
/// source and FNV-1a 64 content hash, trajectory, metrics before and after,
/// optimiser and settings, parameters before and after, UTC date, project
/// version and git revision) into the session; the caller commits.
void write_tuned_preset(io::OutputSession& session, const std::string& name, const CalibrationResult& result,
                        const std::vector<ReferenceCurve>& references, const CalibrationOptions& options);
/// Provenance JSON text as written by write_tuned_preset.
std::string tuned_preset_provenance_json(const std::string& name, const CalibrationResult& result,
                                         const std::vector<ReferenceCurve>& references,
                                         const CalibrationOptions& options);

}  // namespace puncture::validation
