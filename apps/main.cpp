// puncture: command-line front end of the needle-puncture framework.
//   puncture run       [SCENE] [-o DIR]   real-time SHF + MSM model
//   puncture fem       [SCENE] [-o DIR]   deal.II FEM reference (mpirun-able)
//   puncture validate  [SCENE] [-o DIR]   both models on the same insertion, metrics, report
//   puncture calibrate [SCENE] [--reference CSV ...] [--held-out CSV ...] [-o DIR]   tuned preset
//   puncture sweep     [SCENE] [-o DIR]   accuracy versus time of every fidelity knob
//   puncture grade SCORES.csv [-o DIR]    comprehensive weighted grading (paper Sec. 3.3)
//   puncture slab-rule PRESET... [-o DIR] each layer's parameters from its thickness or depth, fitted on a family of slabs
//   puncture compare   [SCENE] [-o DIR]   comparison models of both papers against the FEM
//   puncture --version
// Exit codes: 0 success, 1 the run failed, 2 bad input (scene, CSV, command
// line), 3 output not writable, 128 + n ended by signal n (apps/README.md).
#include <CLI/CLI.hpp>
#include <iostream>
#include <sstream>

#include "puncture/apps/commands.hpp"
#include "puncture/validation/fem_reference.hpp"
#include "puncture/io/interrupt_cleanup.hpp"
#include "puncture/io/provenance.hpp"

namespace {

using namespace puncture::apps;

/// A default value as the help text shows it (e.g. 1000).
std::string default_text(double value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

/// What the command line sets: the options of every subcommand and the
/// values they share (scene, output, FEM cache).
struct CommandLine {
  std::string scene, output, cache, scores;
  RunOptions run;
  FemOptions fem;
  ValidateOptions validate;
  CalibrateOptions calibrate;
  SweepOptions sweep;
  GradeOptions grade;
  SlabRuleOptions slab_rule;
#ifdef PUNCTURE_HAVE_COMPARE
  CompareOptions compare;
#endif
};

/// The options of a command on a scene: the scene file, the output
/// directory (help text `output_help`) and, with_cache, the FEM cache.
void add_scene_options(CLI::App* cmd, CommandLine& c, const std::string& output_help, bool with_cache) {
  cmd->add_option("scene", c.scene, "Scene file (JSON); default: scenes/default.json");
  cmd->add_option("-o,--output", c.output, output_help);
  if (with_cache) cmd->add_option("--cache", c.cache, "FEM cache directory; default: out/.fem_cache");
}

CLI::App* add_run(CLI::App& app, CommandLine& c) {
  CLI::App* run_cmd = app.add_subcommand("run", "Run the real-time model along the scene's scripted insertion");
  add_scene_options(run_cmd, c, "Output directory; default: out/<scene name>", false);
  run_cmd->add_flag("--no-frames", [&c](std::int64_t) { c.run.write_frames = false; }, "Do not write VTK frames");
  run_cmd->add_flag("-q,--quiet", c.run.quiet, "Nothing on stdout (warnings and errors still on stderr)");
  return run_cmd;
}

CLI::App* add_fem(CLI::App& app, CommandLine& c) {
  CLI::App* fem_cmd = app.add_subcommand("fem", "Run the deal.II FEM reference along the same insertion (MPI-aware)");
  add_scene_options(fem_cmd, c, "Output directory; default: out/<scene name>_fem", false);
  fem_cmd->add_option("--refinement", c.fem.refinement, "Global refinements (overrides the scene)")->check(CLI::Range(0, 4));
  fem_cmd->add_option("--degree", c.fem.degree, "Element degree 1 (Q1) or 2 (Q2) (overrides the scene)")->check(CLI::Range(1, 2));
  fem_cmd->add_flag("--no-vtu", [&c](std::int64_t) { c.fem.write_vtu = false; }, "Do not write .vtu field output");
  fem_cmd->add_option("--stop-depth", c.fem.stop_depth_mm,
                      "Stop the insertion at this tip depth (mm; no dwell, no withdrawal): for studies")
      ->check(CLI::PositiveNumber);
  fem_cmd->add_flag("-q,--quiet", c.fem.quiet, "Nothing on stdout");
  return fem_cmd;
}

void add_recording_options(CLI::App* cmd, puncture::validation::ReferenceRecordingOptions& r);

CLI::App* add_validate(CLI::App& app, CommandLine& c) {
  CLI::App* validate_cmd = app.add_subcommand("validate", "Real-time model against the FEM reference on the same insertion");
  add_scene_options(validate_cmd, c, "Report directory; default: out/<scene name>_validation", true);
  validate_cmd->add_option("--refinement", c.validate.refinement, "FEM refinement (overrides the scene)")->check(CLI::Range(0, 4));
  validate_cmd->add_option("--degree", c.validate.degree, "FEM element degree (overrides the scene)")->check(CLI::Range(1, 2));
  validate_cmd->add_option("--cases", c.validate.cases,
                           "Cases file (JSON; validation/cases/default_heldout.json): validate the scene, without "
                           "retuning, on each case (other speeds, depths, slabs); one report per case and "
                           "heldout_summary.json / .md");
  validate_cmd->add_option("--slab-rule", c.validate.slab_rule,
                           "With --cases: the model's slab rule (slab_rule.json of puncture slab-rule); cases that "
                           "change the layer thicknesses take each layer's ruled parameters from it");
  validate_cmd->add_option("--why-misses", c.validate.why_misses,
                           "With --cases: the model's reasons for its misses (JSON: reasons by case and layer; "
                           "validation/cases/default_tuned_why_misses.json), shown under \"Why each miss\"");
  validate_cmd->add_option("--model-note", c.validate.model_note,
                           "With --cases: how the model was calibrated (which references), for the summary page");
  validate_cmd->add_option("--reference", c.validate.references,
                           "Measured curve or raw rig recording (repeatable; read as calibrate --reference reads it): "
                           "judge the scene's model on each recording's own trajectory instead of the FEM "
                           "(recordings_validation.md: force RMSE, punctures found on the recording beside the "
                           "model's, the scatter of repeats)");
  add_recording_options(validate_cmd, c.validate.recording);
  validate_cmd->add_flag("--no-vtk", [&c](std::int64_t) { c.validate.write_vtk = false; },
                         "CSV, PNG and markdown only (no .vtp, .vtu, validation.pvd)");
  validate_cmd->add_flag("-q,--quiet", c.validate.quiet, "Nothing on stdout (warnings and errors still on stderr)");
  return validate_cmd;
}

/// How a raw rig recording is read (validation/harness recording.hpp): its
/// format file and the fields that override it.
void add_recording_options(CLI::App* cmd, puncture::validation::ReferenceRecordingOptions& r) {
  namespace pv = puncture::validation;
  const auto field = [&r](std::string& into) {
    return [&r, &into](const std::string& v) {
      into = v;
      r.overrides.source = "the command line";
    };
  };
  cmd->add_option("--recording-format", r.format_file,
                  "Raw rig recording: its format (JSON: time, position, force columns, units, into_tissue, sign; "
                  "validation/README.md); default: <reference stem>.json beside it, if present")
      ->check(CLI::ExistingFile);
  cmd->add_option_function<std::string>("--time-column", field(r.overrides.time.name), "Raw recording: the time column");
  cmd->add_option_function<std::string>("--time-unit", field(r.overrides.time.unit), "Raw recording: s, ms or us "
                                        "(default: the column name's _<unit> suffix)");
  cmd->add_option_function<std::string>("--position-column", field(r.overrides.position.name),
                                        "Raw recording: the stage position column");
  cmd->add_option_function<std::string>("--position-unit", field(r.overrides.position.unit), "Raw recording: m, mm or um");
  cmd->add_option_function<std::string>("--force-column", field(r.overrides.force.name), "Raw recording: the force column");
  cmd->add_option_function<std::string>("--force-unit", field(r.overrides.force.unit), "Raw recording: N or mN");
  cmd->add_option_function<std::string>(
         "--stage-direction",
         [&r](const std::string& d) {
           r.overrides.into_tissue = d == "increasing" ? pv::StageDirection::Increasing : pv::StageDirection::Decreasing;
           r.overrides.source = "the command line";
         },
         "Raw recording: increasing or decreasing (the stage position as the needle goes into the tissue)")
      ->check(CLI::IsMember({"increasing", "decreasing"}));
  cmd->add_option_function<int>(
         "--force-sign",
         [&r](int sign) {
           r.overrides.force_sign = sign;
           r.overrides.source = "the command line";
         },
         "Raw recording: 1 or -1 (the sign of the file's force while the tissue resists the insertion)")
      ->check(CLI::IsMember({1, -1}));
}

CLI::App* add_calibrate(CLI::App& app, CommandLine& c) {
  CLI::App* calibrate_cmd = app.add_subcommand("calibrate", "Tune the force law per layer (K, breakthrough, cutting, friction, stiffening; optionally w, L, k_s, d); write a preset");
  add_scene_options(calibrate_cmd, c, "Output directory; default: out/<scene name>_calibration", true);
  calibrate_cmd->add_option("--reference", c.calibrate.references,
                            "Measured insertion curve (CSV with depth_mm and force_N at least, or a raw rig "
                            "recording with its format: --recording-format or its sidecar; see validation/README.md); "
                            "repeat it for repeats and other speeds of the same tissue, calibrated together, each at "
                            "its own speed (two or more speeds identify d and the rate laws); default: the scene's FEM "
                            "reference (cached)")
      ->expected(1)
      ->take_all();
  calibrate_cmd->add_option("--held-out", c.calibrate.held_out,
                            "Recording of the same tissue left out of the fit (repeatable): judged with the tuned "
                            "model in the same report and counted in the scatter of repeats")
      ->expected(1)
      ->take_all();
  add_recording_options(calibrate_cmd, c.calibrate.recording);
  calibrate_cmd->add_option("--method", c.calibrate.method,
                            "levenberg_marquardt (default), nelder_mead, bobyqa or simulated_annealing")
      ->check(CLI::IsMember({"levenberg_marquardt", "nelder_mead", "bobyqa", "simulated_annealing"}));
  calibrate_cmd->add_option("--threads", c.calibrate.threads, "Model runs at once; default 0: every core")
      ->check(CLI::Range(0, 256));
  calibrate_cmd->add_option("--stage-turn-margin", c.calibrate.stage_turn_margin_mm,
                            "Per-layer stages run the model this far (mm) past their compared depth range and "
                            "turn; 0: every run the whole trajectory; default " +
                                default_text(puncture::validation::CalibrationOptions{}.stage_turn_margin_m * 1e3))
      ->check(CLI::Range(0.0, 1e3));
  calibrate_cmd->add_option("--name", c.calibrate.preset_name, "Preset name; default: <scene name>_tuned");
  calibrate_cmd->add_option("--layers", c.calibrate.layers, "Layers to calibrate; default: all");
  calibrate_cmd->add_option("--also-tune", c.calibrate.also_tune,
                            "Also tune: surface_stiffness, rings, spacing (comma separated)")
      ->delimiter(',');
  calibrate_cmd->add_option("--integrator", c.calibrate.integrator,
                            "Integrator of the model runs: quasi_static, explicit or implicit; default: the scene's");
  calibrate_cmd->add_option("--depth-weight", c.calibrate.depth_weight,
                            "Weight of the puncture-depth term (error in units of min(L, thickness)); default 0.1");
  calibrate_cmd->add_option("--force-weight", c.calibrate.force_weight,
                            "Weight of the puncture-force term (relative error, like the RMSE terms of weight 1); "
                            "default 1");
  calibrate_cmd->add_option("--bound-factor", c.calibrate.bound_factor,
                            "Each tuned scale parameter stays within [start / f, start * f] (and its physical "
                            "range); default " +
                                default_text(puncture::validation::kDefaultCalibrationBoundFactor));
  calibrate_cmd->add_flag("--tune-unidentifiable", c.calibrate.tune_unidentifiable,
                          "Also tune the parameters the reference cannot identify (default: they keep the scene's "
                          "values, listed in the identifiability report)");
  calibrate_cmd->add_option("--reference-depth-offset", c.calibrate.reference_depth_offset_mm,
                            "Subtracted from the measured curve's depths (mm): a trace that starts above the tissue "
                            "surface (e.g. 9.5 for the Okamura liver trace); default 0");
  calibrate_cmd->add_option("--puncture-depths", c.calibrate.puncture_depths_mm,
                            "Puncture depths of the reference in mm, one per layer from the top (comma separated); "
                            "default: from its state columns, else from its force drops")
      ->delimiter(',');
  calibrate_cmd->add_option("--fem-speeds", c.calibrate.fem_speeds_mm_per_s,
                            "Also calibrate against the scene's FEM reference at these insertion speeds (mm/s, "
                            "comma separated; withdrawal at the same speed): with a viscoelastic scene, two or more "
                            "speeds identify the damping d; default: the scene's speed only")
      ->delimiter(',');
  calibrate_cmd->add_flag("--surface-fit", c.calibrate.surface_fit,
                          "First identify each layer's force mesh (K, k_s, k_a, z_v: stiffening in the mesh) from the "
                          "FEM's force and surface deflection profiles; those layers lose their tip stiffening, and K "
                          "and the stiffening are kept by the later stages");
  calibrate_cmd->add_flag("--cutting-from-next-puncture", c.calibrate.cutting_from_next_puncture,
                          "Tune the cutting force of a layer whose next layer is met at the tip in that layer's stage, "
                          "from its puncture force and depth (however short the cut; off by default, see "
                          "validation/calibration/README.md)");
  calibrate_cmd->add_option("--keep", c.calibrate.keep,
                            "Keep at the scene's values: K, breakthrough, cutting, friction, stiffening (comma "
                            "separated); default: tune each whose effect is on")
      ->delimiter(',');
  calibrate_cmd->add_option("--layer-thickness", c.calibrate.layer_thickness_mm,
                            "Calibrate on another slab: the scene with these layer thicknesses (mm, one per layer "
                            "from the top, comma separated) and that slab's FEM reference; for the family of a slab "
                            "rule; default: the scene's")
      ->delimiter(',');
  calibrate_cmd->add_flag("-q,--quiet", c.calibrate.quiet, "Nothing on stdout (warnings and errors still on stderr)");
  return calibrate_cmd;
}

CLI::App* add_sweep(CLI::App& app, CommandLine& c) {
  CLI::App* sweep_cmd = app.add_subcommand("sweep", "What accuracy costs in time: every fidelity knob against the finest FEM");
  add_scene_options(sweep_cmd, c, "Output directory; default: out/<scene name>_accuracy_cost", true);
  sweep_cmd->add_flag("--no-fem-knobs", [&c](std::int64_t) { c.sweep.include_fem_knobs = false; },
                      "Do not sweep FEM refinement and degree");
  sweep_cmd->add_flag("-q,--quiet", c.sweep.quiet, "Nothing on stdout (warnings and errors still on stderr)");
  return sweep_cmd;
}

CLI::App* add_slab_rule(CLI::App& app, CommandLine& c) {
  CLI::App* cmd = app.add_subcommand(
      "slab-rule", "Each layer's real-time parameters as power laws in its thickness or depth, fitted on presets calibrated "
                   "on a family of slabs (for validation cases on other slabs)");
  cmd->add_option("presets", c.slab_rule.presets, "Tuned presets, one per slab; the first gives the reference thicknesses")
      ->required();
  cmd->add_option("-o,--output", c.output, "Output directory; default: out/slab_rule");
  cmd->add_flag("-q,--quiet", c.slab_rule.quiet, "Nothing on stdout");
  return cmd;
}

CLI::App* add_grade(CLI::App& app, CommandLine& c) {
  CLI::App* grade_cmd = app.add_subcommand("grade", "Comprehensive weighted grading of models from a CSV of scores");
  grade_cmd->add_option("scores", c.scores, "CSV: model, resident, then one column per indicator")->required();
  grade_cmd->add_option("-o,--output", c.output, "Output directory; default: out/grading");
  grade_cmd->add_option("--mu", c.grade.mu, "Preference coefficient (share of the subjective weights), default 0.4");
  grade_cmd->add_flag("-q,--quiet", c.grade.quiet, "Nothing on stdout");
  return grade_cmd;
}

#ifdef PUNCTURE_HAVE_COMPARE
CLI::App* add_compare(CLI::App& app, CommandLine& c) {
  CLI::App* compare_cmd = app.add_subcommand("compare", "Comparison models of both papers against the FEM, graded (Sec. 3.3)");
  add_scene_options(compare_cmd, c, "Output directory; default: out/<scene name>_comparison", true);
  compare_cmd->add_option("--models", c.compare.models, "Models (comma separated); default: all")->delimiter(',');
  compare_cmd->add_option("--weights", c.compare.weights, "Delphi weights file; default: scenes/delphi_weights.json");
  compare_cmd->add_option("--identify", c.compare.identify, "Identify the mass-spring stiffnesses: simulated_annealing,isres")
      ->delimiter(',');
  compare_cmd->add_option("--identify-evaluations", c.compare.identify_evaluations, "Model runs per identification (40)");
  compare_cmd->add_option("--cases", c.compare.cases,
                          "Judge every model, identified on the scene's trajectory, on these held-out cases "
                          "(e.g. validation/cases/default_heldout.json)");
  compare_cmd->add_flag("--scene-parameters", c.compare.scene_parameters,
                        "No identification against the FEM: the scene's moduli and breakthrough rules");
  compare_cmd->add_flag("--critical-forces-only", c.compare.critical_forces_only,
                        "Identify the layers' critical forces only, not their stiffness factors");
  compare_cmd->add_option("--frames", c.compare.frames, "ParaView frames per model (20; 0: none)");
  compare_cmd->add_flag("--no-vtk", [&c](std::int64_t) { c.compare.write_vtk = false; }, "No VTK output");
  compare_cmd->add_flag("-q,--quiet", c.compare.quiet, "No progress output");
  return compare_cmd;
}
#endif

/// The subcommands, in the order of the help text.
struct Subcommands {
  CLI::App *run, *fem, *validate, *calibrate, *sweep, *grade, *slab_rule, *compare = nullptr;
};

/// Runs the subcommand that was parsed; returns its exit code.
int dispatch(const Subcommands& sub, CommandLine& c) {
  if (*sub.run) {
    c.run.scene = c.scene, c.run.output_dir = c.output;
    return run_command(c.run, std::cout, std::cerr);
  }
  if (*sub.fem) {
    c.fem.scene = c.scene, c.fem.output_dir = c.output;
    return fem_command(c.fem, std::cout, std::cerr);
  }
  if (*sub.validate) {
    c.validate.scene = c.scene, c.validate.output_dir = c.output, c.validate.cache_dir = c.cache;
    return validate_command(c.validate, std::cout, std::cerr);
  }
  if (*sub.calibrate) {
    c.calibrate.scene = c.scene, c.calibrate.output_dir = c.output, c.calibrate.cache_dir = c.cache;
    return calibrate_command(c.calibrate, std::cout, std::cerr);
  }
  if (*sub.sweep) {
    c.sweep.scene = c.scene, c.sweep.output_dir = c.output, c.sweep.cache_dir = c.cache;
    return sweep_command(c.sweep, std::cout, std::cerr);
  }
#ifdef PUNCTURE_HAVE_COMPARE
  if (*sub.compare) {
    c.compare.scene = c.scene, c.compare.output_dir = c.output, c.compare.cache_dir = c.cache;
    return compare_command(c.compare, std::cout, std::cerr);
  }
#endif
  if (*sub.grade) {
    c.grade.scores = c.scores, c.grade.output_dir = c.output;
    return grade_command(c.grade, std::cout, std::cerr);
  }
  if (*sub.slab_rule) {
    c.slab_rule.output_dir = c.output;
    return slab_rule_command(c.slab_rule, std::cout, std::cerr);
  }
  return kExitFailure;
}

}  // namespace

int main(int argc, char** argv) {
  // Before any other thread exists: SIGINT/SIGTERM/SIGHUP remove staged files.
  puncture::io::install_interrupt_cleanup();
  CLI::App app{"puncture: virtual needle-puncture simulation (real-time SHF + MSM model, FEM reference)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("puncture ") + puncture::io::program_version() + " (git " +
                                        puncture::io::git_revision() + ", FEM sources " +
                                        puncture::validation::fem_source_digest() + ")");
  app.footer("Exit codes: 0 success, 1 the run failed, 2 bad input (scene file, CSV, command line), "
             "3 output not writable, 128+n ended by signal n. -q: nothing on stdout (warnings and errors on stderr).");
  CommandLine c;
  Subcommands sub;
  sub.run = add_run(app, c);
  sub.fem = add_fem(app, c);
  sub.validate = add_validate(app, c);
  sub.calibrate = add_calibrate(app, c);
  sub.sweep = add_sweep(app, c);
  sub.grade = add_grade(app, c);
  sub.slab_rule = add_slab_rule(app, c);
#ifdef PUNCTURE_HAVE_COMPARE
  sub.compare = add_compare(app, c);
#endif
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every usage error exits 2 (CLI11's own
    // codes, 100-120, are not documented and would vary by error).
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }
  const int exit_code = dispatch(sub, c);
  puncture::validation::finalize_mpi();  // before static destruction (see fem_reference.hpp)
  return exit_code;
}
