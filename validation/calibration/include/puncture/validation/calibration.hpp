// calibration.hpp: tunes the per-layer force-mesh parameters of a scene so
// that the real-time model's insertion curve matches reference curves.
//
// In:  a Scene (SI units; its geometry, insertion and settings are kept), one
//      or more reference InsertionCurves (FEM, measured, or synthetic) and
//      CalibrationOptions.
// Out: CalibrationResult: the tuned Scene, parameters and metrics before and
//      after, the optimiser's record and the identifiability report;
//      write_tuned_preset() writes it as a scene file, a provenance file and
//      an identifiability page.
//
// What is tuned (per layer, switchable in CalibrationOptions::parameters):
//   K (virtual stiffness) and the layer's breakthrough parameter (the ring
//   deformation threshold, the critical force or the critical energy, by the
//   layer's criterion) always; the cutting force, the dynamic shaft friction
//   (the static level keeps its ratio to it) and the tip stiffening
//   coefficients (a2 and a3 of the polynomial law, k_e of the exponential one) when
//   their effects are on in the scene; the friction's presliding travel when
//   the scene's start value is > 0; k_s, L and w on request; d with rate
//   information (DampingPolicy).
// Bounds with physical meaning (parameter_bounds): every parameter stays
//   inside an absolute physical range (e.g. a ring threshold between 1 um,
//   below which a ring counts as deformed by numerical noise, and the layer
//   thickness; a critical force between 0.1 mN and 50 N, the span of
//   measured puncture forces; a cutting force between 0 and 20 N; a rupture
//   release length of at least five haptic ticks' travel and 0.1 mm, so that
//   its decay is resolved by the ticks it is applied on), and the
//   scale parameters (K, k_s, L, d, threshold, critical force and energy)
//   also within [p0 / bound_factor, p0 x bound_factor] of their start. A
//   start outside the physical range is moved inside it (and reported).
//   Scale parameters are optimised in log space, the ones that may be 0
//   (cutting, friction, stiffening) in linear space scaled to a typical
//   value. The result lists every tuned parameter with its bounds and
//   whether it ended at one.
// Identifiability: before breakthrough the force is S(K, k_s, w) z0 (+ the
//   stiffening), and the breakthrough parameter sets where it breaks; after
//   it, the cutting force sets the level and the friction the slope with
//   the shaft length; on withdrawal only friction (and d h v) remain, with
//   reversed sign, which separates friction from cutting. k_s and L change
//   the ring deflection profile and are only identifiable with a
//   deflection-profile reference (L does not enter the quasi-static force
//   at all). d and the friction both grow with the shaft length: d is tuned
//   only when a reference carries rate information.
// Reference punctures: from given depths, the <layer>_state columns, or the
//   force drops of a curve with depth and force only (puncture_events.hpp).
// Sequential stages (what we do): layers are calibrated top to bottom. The
//   stage of layer k minimises the layer's terms of the trajectory objective
//   (trajectory_objective.hpp: its pressing, its puncture force and depth,
//   its cut (cutting and friction) and the overall and part terms) over the
//   reference insertion down to the end of the cut through layer k, plus the
//   withdrawal above that depth. The model runs down to that end plus
//   stage_turn_margin_m (2 mm) and turns there (the skin's stage runs a
//   third of the insertion); a run that has not broken through a layer the
//   reference breaks within the compared depths is repeated over the whole
//   trajectory, so a breakthrough far beyond the reference's still gives a
//   depth error, not a missing puncture.
//   When d is tuned, a stage tunes the
//   d of all calibrated layers together; a final joint stage (joint_polish)
//   refines every tuned parameter of every calibrated layer on the whole
//   objective (every term, dwell included).
// Objective of a stage, summed over the references: sum of weight x value^2
//   of the selected terms (the header of trajectory_objective.hpp), which is
//   the sum of squares of their residuals (one per compared reference sample
//   and per puncture term): Levenberg-Marquardt (the default) minimises it
//   as least squares (levenberg_marquardt.hpp), the NLopt and GSL methods as
//   a scalar.
// Identifiability report: at the tuned values, the forward-difference
//   Jacobian of the whole objective's residuals over every tuned parameter
//   gives sensitivities, standard errors and correlations
//   (identifiability.hpp); each parameter is identified, at a bound or not
//   identifiable (with the reason), and the parameters withheld before the
//   fit are listed with theirs. A tuned parameter the objective does not
//   change with goes back to its start value (keep_unidentifiable_at_start).
// Model runs: a copy of the scene with realtime.integrator =
//   options.integrator, no frames, the reference's trajectory (its insertion
//   speed: metadata "speed_mm_per_s", else the scene's; its deepest depth;
//   its dwell in the joint stage and the report; its withdrawal speed, or a
//   fast withdrawal when it has none), every effect of the scene (the
//   damping force d h v included: the model is compared as it renders), and a
//   haptic rate raised so that one tick moves the needle at most
//   objective_depth_step_m (sharper breakthrough depths). The SH layer
//   surfaces depend only on geometry and degree: they are fitted once per
//   calibrate() call (SurfaceCache). Runs are independent: the Jacobian's
//   columns and the trial points go to `threads` threads at once.
// A candidate whose run throws (e.g. a non-finite force) gets the objective
//   kFailedObjective; it is counted, never returned as a result.
#pragma once

#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "puncture/model/realtime_model.hpp"
#include "puncture/scene.hpp"
#include "puncture/sh/layer_surface.hpp"
#include "puncture/validation/identifiability.hpp"
#include "puncture/validation/metrics.hpp"
#include "puncture/validation/puncture_events.hpp"
#include "puncture/validation/trajectory_objective.hpp"

namespace puncture::io {
class OutputSession;
}

namespace puncture::validation {

constexpr double kFailedObjective = 1e6;

enum class CalibrationMethod { LevenbergMarquardt, Bobyqa, NelderMead, SimulatedAnnealing };
/// "levenberg_marquardt", "bobyqa", "nelder_mead", "simulated_annealing" (std::invalid_argument otherwise).
CalibrationMethod parse_calibration_method(const std::string& name);
const char* to_string(CalibrationMethod method);

/// When the damping d is tuned. Auto: only if references with the metadata
/// line "# rate_dependent: true" (measured curves, or the FEM reference of a
/// viscoelastic scene, fem_reference_curve.hpp) span two or more insertion
/// speeds (metadata "speed_mm_per_s", else the scene's): at one speed d h v
/// grows with the shaft length exactly as the friction does, so only the
/// change with speed tells d apart. An elastic scene's FEM reference is quasi-
/// static, so d is kept fixed against it.
enum class DampingPolicy { Auto, Fixed, Tune };

struct TunedParameterSet {
  bool virtual_stiffness = true;   ///< K
  bool deformed_threshold = true;  ///< the breakthrough parameter: ring threshold, critical force or energy (by criterion)
  bool cutting = true;             ///< cutting force (if the cutting effect is on)
  bool friction = true;            ///< dynamic shaft friction (if the friction effect is on)
  bool stiffening = true;          ///< tip stiffening coefficient (if the stiffening effect is on)
  bool surface_stiffness = false;  ///< k_s (needs a deflection profile to be identifiable)
  bool spacing = false;            ///< L (needs a deflection profile)
  bool rings = false;              ///< w (integer, enumerated)
  DampingPolicy damping = DampingPolicy::Auto;
  /// Layers (by name) whose force mesh was identified before the stages (the
  /// surface fit, `puncture calibrate --surface-fit`): their K and stiffening
  /// stay, whatever virtual_stiffness and stiffening say; the other layers'
  /// follow those flags.
  std::vector<std::string> mesh_identified_layers;
};

/// Weights of the objective terms (trajectory_objective.hpp).
using CalibrationWeights = ObjectiveWeights;

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

/// Default of CalibrationOptions::bound_factor and of `puncture calibrate --bound-factor`: against the
/// FEM the Table 2 values can be two orders of magnitude off, so the box is wide.
inline constexpr double kDefaultCalibrationBoundFactor = 1000.0;

struct CalibrationOptions {
  /// Levenberg-Marquardt by default: least squares on the objective's
  /// residual vector (one residual per compared reference sample and per
  /// puncture term), finite-difference Jacobians on `threads` threads; the
  /// derivative-free methods evaluate the scalar objective one run at a time
  /// (Nelder-Mead needed about 7,000 runs on the default slab where
  /// Levenberg-Marquardt needs a few hundred: results/calibration_speed).
  CalibrationMethod method = CalibrationMethod::LevenbergMarquardt;
  int threads = 0;                  ///< model runs at once (Jacobian columns, trial points); 0: all cores
  int lm_max_iterations = 100;      ///< Levenberg-Marquardt iterations per stage
  /// Finite-difference step in x (5 % of a scale parameter): wide enough to
  /// step over the objective's small steps where a breakthrough moves by one
  /// tick or a reference sample changes sides of it (1 % stalled the default
  /// slab's skin stage at 0.0017 against 0.0014).
  double lm_difference_step = 5e-2;
  double lm_difference_step_min = 1e-4;  ///< refined down to this on a stall (levenberg_marquardt.hpp)
  /// Parameters the references cannot identify keep their start values:
  /// those withheld before the fit (reference_checks.hpp: no puncture of the
  /// layer, too few samples) and a tuned one the whole objective does not
  /// change with at the optimum. false (`puncture calibrate
  /// --tune-unidentifiable`): they are tuned and left where the optimiser
  /// left them, with a warning each.
  bool keep_unidentifiable_at_start = true;
  /// A layer whose next layer is met at the tip (the crack stays open while
  /// that layer is pressed) gets its cutting force tuned in the next layer's
  /// stage, identified by that layer's puncture force and depth, however
  /// short its own cut (`puncture calibrate --cutting-from-next-puncture`).
  /// Off by default: on the default slab it fits the calibration trajectory's
  /// punctures closer but holds out worse (results/experiments/cutting_from_next_puncture).
  bool cutting_from_next_puncture = false;
  /// Per-layer stages run the model down to the end of their compared depth
  /// range plus this margin and turn there (not to the reference's deepest
  /// sample); the joint stage runs the whole trajectory. <= 0: always whole.
  double stage_turn_margin_m = 2e-3;
  std::vector<std::string> layers;  ///< layers to calibrate; empty = all (always processed top to bottom)
  TunedParameterSet parameters;
  CalibrationWeights weights;
  double bound_factor = kDefaultCalibrationBoundFactor;  ///< each continuous parameter stays in [p0 / f, p0 f]
  int rings_search_radius = 1;
  int max_evaluations_per_stage = 300;  ///< NLopt evaluation budget per stage and w (shared by restarts) ...
  int evaluations_per_parameter = 250;  ///< ... raised to this many per tuned parameter of the stage
  double log_x_tolerance = 1e-4;    ///< NLopt xtol_abs in log space (1e-4 = 0.01 %)
  std::string integrator = "quasi_static";
  double objective_depth_step_m = 2e-6;  ///< breakthrough depth resolution of the objective's model runs
  double depth_margin_m = 1e-3;     ///< stage range beyond the layer's reference puncture depth when the reference ends there
  /// Puncture depths of the (first) reference, one per layer from the top;
  /// empty: from its state columns, else from its force drops.
  std::vector<double> puncture_depths_m;
  PunctureDetectionOptions detection;
  /// Final stage over every tuned parameter of every calibrated layer on the
  /// whole objective (when more than one layer or parameter kind is tuned).
  bool joint_polish = true;
  /// Sweeps of the per-layer stages; 0: two for layers in series
  /// (Effects::layer_interaction: a layer's stiffness changes the pressing of
  /// the layers above it, so the second sweep revisits them), else one.
  int passes = 0;
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
/// Called after every model run (from the optimiser's threads, one call at a
/// time). It may throw to stop the calibration (a user's Ctrl-C, a script's
/// abort): the exception is kept, every later model run of the calibration is
/// skipped (counted as failed, no model run), and calibrate() rethrows it
/// after the current stage instead of returning.
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
  std::string breakthrough;        ///< "rings", "critical_force" or "critical_energy"
  double critical_force_N = 0.0;
  double critical_energy_J = 0.0;
  double cutting_force_N = 0.0;
  double friction_dynamic_N_per_m = 0.0;
  double friction_static_N_per_m = 0.0;
  double stiffening_quadratic_N_per_m2 = 0.0;
  double stiffening_cubic_N_per_m3 = 0.0;
  double stiffening_exponential_N_per_m = 0.0;
};

/// One tuned parameter in the result: start, tuned value and physical
/// bounds in the units named by `unit`, and whether it ended at a bound.
struct TunedParameterRecord {
  std::string layer;
  std::string name;       ///< e.g. "K", "critical_force", "cutting_force"
  std::string unit;       ///< e.g. "N/mm"
  double start = 0.0;     ///< the scene's value
  double tuned = 0.0;
  double lower = 0.0, upper = 0.0;
  std::string at_bound;   ///< "", "lower" or "upper"
  bool start_moved_inside = false;  ///< the scene's value lay outside the bounds
};
std::vector<LayerParameters> layer_parameters(const Scene& scene);

/// A reference curve and what it is ("fem", "measured", "synthetic", ...).
struct ReferenceCurve {
  InsertionCurve curve;
  std::string kind = "fem";
};
/// True for the FEM reference (kind "fem") or a curve whose metadata says
/// "quasi_static: true" (or yes / 1): no rate dependence, so d cannot be
/// identified from it (the model runs still include d h v).
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
  /// The whole-trajectory objective, term by term, per reference.
  std::vector<TrajectoryComparison> trajectory_before, trajectory_after;
  std::vector<ReferenceEvents> reference_events;  ///< per reference
  std::vector<TunedParameterRecord> parameters;   ///< every tuned parameter
  std::vector<std::string> warnings;              ///< puncture depths more than L apart, bounds, detection
  std::vector<InsertionCurve> model_before;  ///< the model curves those comparisons were made with
  std::vector<InsertionCurve> model_after;
  double objective_before = 0.0;        ///< sum of the stage objectives at the start values
  double objective_after = 0.0;
  int evaluations = 0;
  bool damping_tuned = false;
  std::string damping_note;
  /// Where each tuned critical force started: G_c x 2a from the layer's
  /// fracture toughness (a scene with the fracture_energy puncture criterion),
  /// else the reference's puncture force (scaled start).
  std::string critical_force_note;
  std::vector<CalibrationStageRecord> stages;
  std::vector<std::string> calibrated_layers;
  /// At the tuned values, on the whole objective (every term, every
  /// reference): each tuned parameter's sensitivity, standard error,
  /// correlations and status, and the parameters withheld with the reason.
  IdentifiabilityReport identifiability;
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

/// What a calibration step determined of one value of the preset: the
/// layer, the value's JSON pointer relative to the layer (e.g.
/// "/force_mesh/K_N_per_mm"), its status ("identified", "at a bound" or "not
/// identifiable"), why, the step ("surface fit" or "stages") and its
/// relative standard error (standard error / |value|; NaN where not
/// determined, e.g. a value of 0 or a parameter withheld from the fit).
struct CalibratedValue {
  std::string layer, pointer, status, reason, step;
  double relative_standard_error = std::numeric_limits<double>::quiet_NaN();
};

/// Every value the calibration set, with its status: the force meshes'
/// values from `surface_fit` (when --surface-fit ran before the stages),
/// then every parameter of the identifiability report (a value set by both
/// takes the stages' status: they set it last). Values the calibration did
/// not set are not listed. This is what tells a user of the preset (e.g.
/// the slab rule) which of its values the reference determined.
std::vector<CalibratedValue> calibrated_values(const CalibrationResult& result,
                                               const std::vector<CalibratedValue>& surface_fit = {});

/// Writes <name>.json (a scene file `puncture run` accepts: the tuned scene,
/// renamed to `name`), <name>.provenance.json (references with kind,
/// source and FNV-1a 64 content hash, trajectory, metrics before and after,
/// optimiser and settings, parameters before and after, identifiability,
/// "calibrated_values" (calibrated_values() above), UTC date, project version
/// and git revision) and <name>.identifiability.md into the session; the
/// caller commits.
void write_tuned_preset(io::OutputSession& session, const std::string& name, const CalibrationResult& result,
                        const std::vector<ReferenceCurve>& references, const CalibrationOptions& options,
                        const std::vector<CalibratedValue>& surface_fit = {});
/// Provenance JSON text as written by write_tuned_preset.
std::string tuned_preset_provenance_json(const std::string& name, const CalibrationResult& result,
                                         const std::vector<ReferenceCurve>& references,
                                         const CalibrationOptions& options,
                                         const std::vector<CalibratedValue>& surface_fit = {});

}  // namespace puncture::validation
