// commands.hpp: the subcommands of the `puncture` program as functions.
// Each returns the process exit code (0 success, 1 the run failed, 2 bad
// input: scene, CSV or option, 3 the output cannot be written) and prints
// progress and a short report to `out` (nothing with quiet), warnings and
// errors to `err`. Outputs are written through an io::OutputSession: on any
// error nothing half-written is left behind.
#pragma once

#include <filesystem>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "puncture/validation/calibration.hpp"
#include "puncture/validation/recording.hpp"

namespace puncture::apps {

/// Exit codes of the `puncture` program (apps/README.md); 128 + n when ended by signal n.
enum ExitCode : int { kExitOk = 0, kExitFailure = 1, kExitBadInput = 2, kExitOutput = 3 };

/// Called after every load step of an FEM reference a command computes on the
/// way (not when it comes from the cache) with the tip depth (m) and the share
/// of its trajectory done; may throw to stop the command (the Python module's
/// Ctrl-C). Empty: nothing is called.
using FemStepCallback = std::function<void(double depth_m, double fraction_done)>;

/// The scene `puncture run` uses without arguments: scenes/default.json in the
/// working directory if present, else the one in the source tree.
std::filesystem::path default_scene_path();

struct RunOptions {
  std::filesystem::path scene;        ///< empty: default_scene_path()
  std::filesystem::path output_dir;   ///< empty: out/<scene name>
  bool write_frames = true;           ///< VTK surface frames (also needs Effects::surface_output)
  bool quiet = false;                 ///< nothing on `out` (warnings and errors still go to `err`)
};

/// `puncture run`: real-time model along the scene's scripted insertion.
/// Writes realtime_curve.csv, summary.json, sh_fit_error.csv and, with the
/// surface_output effect, frames/*.vtp + realtime.pvd.
int run_command(const RunOptions& options, std::ostream& out, std::ostream& err);

struct FemOptions {
  std::filesystem::path scene;
  std::filesystem::path output_dir;   ///< empty: out/<scene name>_fem
  int refinement = -1;                ///< -1: from the scene
  int degree = -1;                    ///< -1: from the scene
  bool write_vtu = true;
  double stop_depth_mm = -1.0;  ///< > 0: stop the insertion at this tip depth (no dwell, no withdrawal)
  bool quiet = false;                 ///< nothing on `out`
};

/// `puncture fem`: the deal.II reference along the same insertion (MPI-aware).
int fem_command(const FemOptions& options, std::ostream& out, std::ostream& err);

struct ValidateOptions {
  std::filesystem::path scene;
  std::filesystem::path output_dir;   ///< empty: out/<scene name>_validation
  std::filesystem::path cache_dir;    ///< empty: out/.fem_cache
  int refinement = -1;                ///< FEM refinement, -1: from the scene
  int degree = -1;                    ///< FEM degree, -1: from the scene
  bool write_vtk = true;              ///< VTK report (.vtp, .vtu, validation.pvd); false: CSV, PNG, md only
  bool quiet = false;
  /// Cases file (validation_cases.hpp); empty: the scene alone. With cases,
  /// output_dir holds one report per case and the held-out summary.
  std::filesystem::path cases;
  std::string model_note;             ///< with cases: how the model was calibrated, for the summary
  /// With cases: the model's slab rule (slab_rule.json of `puncture slab-rule`);
  /// cases that change the layer thicknesses take the ruled parameters from it.
  std::filesystem::path slab_rule;
  /// With cases: why the model misses where it does (validation_cases.hpp
  /// read_miss_reasons), for the summary's "Why each miss".
  std::filesystem::path why_misses;
  /// Measured curves or raw rig recordings (read as calibrate's --reference,
  /// with `recording`): the scene's model judged against each on its own
  /// trajectory instead of against the FEM (apps/src/validate_recordings.hpp).
  std::vector<std::filesystem::path> references;
  validation::ReferenceRecordingOptions recording;
  FemStepCallback fem_step;  ///< see FemStepCallback
};

/// `puncture validate`: real-time model and FEM reference (cached) on the
/// identical insertion; metrics per layer; report folder (CSV, PNG, VTK, md).
int validate_command(const ValidateOptions& options, std::ostream& out, std::ostream& err);

struct CalibrateOptions {
  std::filesystem::path scene;
  /// Measured curves or raw recordings calibrated against together (repeats
  /// and other speeds of one tissue, each at its own speed); empty: the FEM
  /// reference of the scene (cached).
  std::vector<std::filesystem::path> references;
  /// Recordings of the same tissue left out of the fit: judged with the tuned
  /// model in the same report (and counted in the scatter of repeats).
  std::vector<std::filesystem::path> held_out;
  /// How to read a raw rig recording (recording.hpp): a format file
  /// (--recording-format; empty: the sidecar <reference stem>.json if present)
  /// and the command line's fields over it (--time-column, ...).
  validation::ReferenceRecordingOptions recording;
  std::filesystem::path output_dir;   ///< empty: out/<scene name>_calibration
  std::filesystem::path cache_dir;    ///< empty: out/.fem_cache
  std::string method = "levenberg_marquardt"; ///< levenberg_marquardt, nelder_mead, bobyqa, simulated_annealing
  std::string preset_name;            ///< empty: <scene name>_tuned
  std::vector<std::string> layers;    ///< empty: all
  int threads = 0;                    ///< model runs at once; 0: every core
  bool tune_unidentifiable = false;   ///< also tune what the reference cannot identify
  /// Subtracted from the measured curve's depths (mm), for a trace that starts above the surface.
  double reference_depth_offset_mm = 0.0;
  /// Per-layer stages turn this far past their compared depth range (mm); 0: whole runs.
  double stage_turn_margin_mm = validation::CalibrationOptions{}.stage_turn_margin_m * 1e3;
  /// Each tuned parameter stays within [start / f, start x f]; the library's default (1000).
  double bound_factor = validation::kDefaultCalibrationBoundFactor;
  /// Parameters tuned besides K and the deformation threshold:
  /// "surface_stiffness" (k_s), "rings" (w), "spacing" (L).
  std::vector<std::string> also_tune;
  /// Force-mesh integrator of the model runs; empty: the scene's own (what the
  /// tuned preset will run with).
  std::string integrator;
  /// Weight of the puncture-depth term of the objective (error in units of
  /// min(L, thickness)); the force terms have weight 1. 0.1: a depth error of
  /// one L weighs like a force RMSE of 32 % of the peak. The committed tuned
  /// preset (scripts/results_validation.sh) uses 1, with --force-weight 4:
  /// with 0.1 its muscle broke 4.8 mm early.
  double depth_weight = 0.1;
  /// Weight of each layer's puncture-force term (relative error); 1 weighs a
  /// 10 % force error like a 10 % RMSE. Raise it when the puncture forces
  /// matter more than the fit after them (the acceptance of validate asks
  /// for them within 10 %).
  double force_weight = 1.0;
  /// Puncture depths of the reference (mm), one per layer from the top; empty:
  /// from its state columns, else from its force drops.
  std::vector<double> puncture_depths_mm;
  /// Insertion speeds (mm/s) of further FEM references of the scene (not with
  /// --reference): each is the scene inserted and withdrawn at that speed.
  std::vector<double> fem_speeds_mm_per_s;
  /// Identify each layer's force mesh (K, k_s, k_a, z_v) from the FEM's force
  /// and surface deflection profiles first (surface_identification.hpp); the
  /// tip stiffening of those layers goes to 0 and K and the stiffening are
  /// then kept by the later stages.
  bool surface_fit = false;
  /// CalibrationOptions::cutting_from_next_puncture.
  bool cutting_from_next_puncture = false;
  /// Parameters kept at the scene's values: "K", "breakthrough", "cutting",
  /// "friction", "stiffening" (by default each is tuned where its effect is on).
  std::vector<std::string> keep;
  /// Calibrate on another slab: the scene with these layer thicknesses (mm,
  /// one per layer from the top; its FEM reference is that slab's). Empty:
  /// the scene's own. For the family of a slab rule (slab-rule below).
  std::vector<double> layer_thickness_mm;
  bool quiet = false;
  /// Called after every model run besides the printed progress (the Python
  /// module's progress callback); may throw to stop the calibration
  /// (calibration.hpp), which then writes nothing and fails with the message.
  validation::CalibrationProgressCallback progress;
  FemStepCallback fem_step;  ///< see FemStepCallback
};

/// `puncture calibrate`: tunes the force-law parameters against a reference
/// and writes a tuned preset (a scene `puncture run` accepts) + provenance;
/// the summary shows every term of the objective before and after ("n/a"
/// where it cannot be computed), the reference's punctures and how they were
/// found, the tuned parameters with their bounds, and warnings.
int calibrate_command(const CalibrateOptions& options, std::ostream& out, std::ostream& err);

struct GradeOptions {
  std::filesystem::path scores;       ///< CSV: model,resident,<one column per indicator>
  std::filesystem::path output_dir;   ///< empty: out/grading
  double mu = 0.4;                    ///< preference coefficient (subjective share)
  bool quiet = false;                 ///< nothing on `out`
};

/// `puncture grade`: comprehensive weighted grading (seed paper Sec. 3.3).
int grade_command(const GradeOptions& options, std::ostream& out, std::ostream& err);

struct SlabRuleOptions {
  std::vector<std::filesystem::path> presets;  ///< calibrated on a family of slabs; the first is the reference
  std::filesystem::path output_dir;            ///< empty: out/slab_rule
  bool quiet = false;
};

/// `puncture slab-rule`: fits each layer's parameters as a power law in its
/// thickness on presets calibrated on a family of slabs
/// (validation/slab_rule.hpp); writes slab_rule.json and slab_rule.md.
int slab_rule_command(const SlabRuleOptions& options, std::ostream& out, std::ostream& err);

struct SweepOptions {
  std::filesystem::path scene;
  std::filesystem::path output_dir;   ///< empty: out/<scene name>_accuracy_cost
  std::filesystem::path cache_dir;    ///< empty: out/.fem_cache
  bool include_fem_knobs = true;      ///< also sweep FEM refinement and degree (slow)
  bool quiet = false;
};

/// `puncture sweep`: what accuracy costs in time: error against the finest FEM
/// and time per step for each fidelity knob; table + Pareto plot.
int sweep_command(const SweepOptions& options, std::ostream& out, std::ostream& err);

struct CompareOptions {
  std::filesystem::path scene;
  std::filesystem::path output_dir;   ///< empty: out/<scene name>_comparison
  std::filesystem::path cache_dir;    ///< empty: out/.fem_cache
  std::filesystem::path weights;      ///< Delphi weights file; empty: scenes/delphi_weights.json
  std::vector<std::string> models;    ///< empty: all (realtime, shf, msm, mass_tensor, nonlinear_mass_tensor, viscoelastic_mass_tensor, bem, fem)
  std::vector<std::string> identify;  ///< mass-spring identification methods: simulated_annealing, isres
  int identify_evaluations = 40;      ///< model runs per identification
  bool scene_parameters = false;      ///< true: no identification (the scene's moduli and breakthrough rules)
  bool critical_forces_only = false;  ///< identify the critical forces only (no stiffness factors)
  std::filesystem::path cases;        ///< held-out cases file (validation_cases.hpp); empty: none
  int frames = 20;                    ///< ParaView frames per model over the trajectory (0: none)
  bool write_vtk = true;
  bool quiet = false;
  FemStepCallback fem_step;  ///< see FemStepCallback
  /// Called every 5 % of each model run and after every identification run;
  /// may throw to stop (nothing is written): the Python module's Ctrl-C.
  std::function<void()> model_step;
};

/// `puncture compare`: every comparison model and the real-time model on the
/// identical insertion against the FEM reference: comparison.csv, ranking
/// (Sec. 3.3 grading), plots, ParaView series, comparison.md.
int compare_command(const CompareOptions& options, std::ostream& out, std::ostream& err);
/// scenes/delphi_weights.json next to the default scene.
std::filesystem::path default_delphi_weights_path();

}  // namespace puncture::apps
