// puncture: command-line front end of the needle-puncture framework.
//   puncture run       [SCENE] [-o DIR]   real-time SHF + MSM model
//   puncture fem       [SCENE] [-o DIR]   deal.II FEM reference (mpirun-able)
//   puncture validate  [SCENE] [-o DIR]   both models on the same insertion, metrics, report
//   puncture calibrate [SCENE] [--reference CSV] [-o DIR]   tuned preset
//   puncture sweep     [SCENE] [-o DIR]   accuracy versus time of every fidelity knob
//   puncture grade SCORES.csv [-o DIR]    comprehensive weighted grading (paper Sec. 3.3)
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
/// A default value as the help text shows it (e.g. 1000).
std::string default_text(double value) {
  std::ostringstream s;
  s << value;
  return s.str();
}
}  // namespace

int main(int argc, char** argv) {
  using namespace puncture::apps;
  // Before any other thread exists: SIGINT/SIGTERM/SIGHUP remove staged files.
  puncture::io::install_interrupt_cleanup();
  CLI::App app{"puncture: virtual needle-puncture simulation (real-time SHF + MSM model, FEM reference)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("puncture ") + puncture::io::program_version() + " (git " +
                                        puncture::io::git_revision() + ")");
  app.footer("Exit codes: 0 success, 1 the run failed, 2 bad input (scene file, CSV, command line), "
             "3 output not writable, 128+n ended by signal n. -q: nothing on stdout (warnings and errors on stderr).");
  std::string scene, output, cache;

  RunOptions run;
  auto* run_cmd = app.add_subcommand("run", "Run the real-time model along the scene's scripted insertion");
  run_cmd->add_option("scene", scene, "Scene file (JSON); default: scenes/default.json");
  run_cmd->add_option("-o,--output", output, "Output directory; default: out/<scene name>");
  run_cmd->add_flag("--no-frames", [&](std::int64_t) { run.write_frames = false; }, "Do not write VTK frames");
  run_cmd->add_flag("-q,--quiet", run.quiet, "Nothing on stdout (warnings and errors still on stderr)");

  FemOptions fem;
  auto* fem_cmd = app.add_subcommand("fem", "Run the deal.II FEM reference along the same insertion (MPI-aware)");
  fem_cmd->add_option("scene", scene, "Scene file (JSON); default: scenes/default.json");
  fem_cmd->add_option("-o,--output", output, "Output directory; default: out/<scene name>_fem");
  fem_cmd->add_option("--refinement", fem.refinement, "Global refinements (overrides the scene)")->check(CLI::Range(0, 4));
  fem_cmd->add_option("--degree", fem.degree, "Element degree 1 (Q1) or 2 (Q2) (overrides the scene)")->check(CLI::Range(1, 2));
  fem_cmd->add_flag("--no-vtu", [&](std::int64_t) { fem.write_vtu = false; }, "Do not write .vtu field output");
  fem_cmd->add_option("--stop-depth", fem.stop_depth_mm,
                      "Stop the insertion at this tip depth (mm; no dwell, no withdrawal): for studies")
      ->check(CLI::PositiveNumber);
  fem_cmd->add_flag("-q,--quiet", fem.quiet, "Nothing on stdout");

  ValidateOptions validate;
  auto* validate_cmd = app.add_subcommand("validate", "Real-time model against the FEM reference on the same insertion");
  validate_cmd->add_option("scene", scene, "Scene file (JSON); default: scenes/default.json");
  validate_cmd->add_option("-o,--output", output, "Report directory; default: out/<scene name>_validation");
  validate_cmd->add_option("--cache", cache, "FEM cache directory; default: out/.fem_cache");
  validate_cmd->add_option("--refinement", validate.refinement, "FEM refinement (overrides the scene)")->check(CLI::Range(0, 4));
  validate_cmd->add_option("--degree", validate.degree, "FEM element degree (overrides the scene)")->check(CLI::Range(1, 2));
  validate_cmd->add_option("--cases", validate.cases,
                           "Cases file (JSON; validation/cases/default_heldout.json): validate the scene, without "
                           "retuning, on each case (other speeds, depths, slabs); one report per case and "
                           "heldout_summary.json / .md");
  validate_cmd->add_option("--model-note", validate.model_note,
                           "With --cases: how the model was calibrated (which references), for the summary page");
  validate_cmd->add_flag("--no-vtk", [&](std::int64_t) { validate.write_vtk = false; },
                         "CSV, PNG and markdown only (no .vtp, .vtu, validation.pvd)");
  validate_cmd->add_flag("-q,--quiet", validate.quiet, "Nothing on stdout (warnings and errors still on stderr)");

  CalibrateOptions calibrate;
  std::string reference;
  auto* calibrate_cmd = app.add_subcommand("calibrate", "Tune the force law per layer (K, breakthrough, cutting, friction, stiffening; optionally w, L, k_s, d); write a preset");
  calibrate_cmd->add_option("scene", scene, "Scene file (JSON); default: scenes/default.json");
  calibrate_cmd->add_option("--reference", reference,
                            "Measured insertion curve (CSV with depth_mm and force_N at least; see "
                            "validation/README.md); default: the scene's FEM reference (cached)");
  calibrate_cmd->add_option("-o,--output", output, "Output directory; default: out/<scene name>_calibration");
  calibrate_cmd->add_option("--cache", cache, "FEM cache directory; default: out/.fem_cache");
  calibrate_cmd->add_option("--method", calibrate.method,
                            "levenberg_marquardt (default), nelder_mead, bobyqa or simulated_annealing")
      ->check(CLI::IsMember({"levenberg_marquardt", "nelder_mead", "bobyqa", "simulated_annealing"}));
  calibrate_cmd->add_option("--threads", calibrate.threads, "Model runs at once; default 0: every core")
      ->check(CLI::Range(0, 256));
  calibrate_cmd->add_option("--stage-turn-margin", calibrate.stage_turn_margin_mm,
                            "Per-layer stages run the model this far (mm) past their compared depth range and "
                            "turn; 0: every run the whole trajectory; default " +
                                default_text(puncture::validation::CalibrationOptions{}.stage_turn_margin_m * 1e3))
      ->check(CLI::Range(0.0, 1e3));
  calibrate_cmd->add_option("--name", calibrate.preset_name, "Preset name; default: <scene name>_tuned");
  calibrate_cmd->add_option("--layers", calibrate.layers, "Layers to calibrate; default: all");
  calibrate_cmd->add_option("--also-tune", calibrate.also_tune,
                            "Also tune: surface_stiffness, rings, spacing (comma separated)")
      ->delimiter(',');
  calibrate_cmd->add_option("--integrator", calibrate.integrator,
                            "Integrator of the model runs: quasi_static, explicit or implicit; default: the scene's");
  calibrate_cmd->add_option("--depth-weight", calibrate.depth_weight,
                            "Weight of the puncture-depth term (error in units of min(L, thickness)); default 0.1");
  calibrate_cmd->add_option("--force-weight", calibrate.force_weight,
                            "Weight of the puncture-force term (relative error, like the RMSE terms of weight 1); "
                            "default 1");
  calibrate_cmd->add_option("--bound-factor", calibrate.bound_factor,
                            "Each tuned scale parameter stays within [start / f, start * f] (and its physical "
                            "range); default " +
                                default_text(puncture::validation::kDefaultCalibrationBoundFactor));
  calibrate_cmd->add_flag("--tune-unidentifiable", calibrate.tune_unidentifiable,
                          "Also tune the parameters the reference cannot identify (default: they keep the scene's "
                          "values, listed in the identifiability report)");
  calibrate_cmd->add_option("--reference-depth-offset", calibrate.reference_depth_offset_mm,
                            "Subtracted from the measured curve's depths (mm): a trace that starts above the tissue "
                            "surface (e.g. 9.5 for the Okamura liver trace); default 0");
  calibrate_cmd->add_option("--puncture-depths", calibrate.puncture_depths_mm,
                            "Puncture depths of the reference in mm, one per layer from the top (comma separated); "
                            "default: from its state columns, else from its force drops")
      ->delimiter(',');
  calibrate_cmd->add_option("--fem-speeds", calibrate.fem_speeds_mm_per_s,
                            "Also calibrate against the scene's FEM reference at these insertion speeds (mm/s, "
                            "comma separated; withdrawal at the same speed): with a viscoelastic scene, two or more "
                            "speeds identify the damping d; default: the scene's speed only")
      ->delimiter(',');
  calibrate_cmd->add_flag("--surface-fit", calibrate.surface_fit,
                          "First identify each layer's force mesh (K, k_s, k_a, z_v: stiffening in the mesh) from the "
                          "FEM's force and surface deflection profiles; those layers lose their tip stiffening, and K "
                          "and the stiffening are kept by the later stages");
  calibrate_cmd->add_option("--keep", calibrate.keep,
                            "Keep at the scene's values: K, breakthrough, cutting, friction, stiffening (comma "
                            "separated); default: tune each whose effect is on")
      ->delimiter(',');
  calibrate_cmd->add_flag("-q,--quiet", calibrate.quiet, "Nothing on stdout (warnings and errors still on stderr)");

  SweepOptions sweep;
  auto* sweep_cmd = app.add_subcommand("sweep", "What accuracy costs in time: every fidelity knob against the finest FEM");
  sweep_cmd->add_option("scene", scene, "Scene file (JSON); default: scenes/default.json");
  sweep_cmd->add_option("-o,--output", output, "Output directory; default: out/<scene name>_accuracy_cost");
  sweep_cmd->add_option("--cache", cache, "FEM cache directory; default: out/.fem_cache");
  sweep_cmd->add_flag("--no-fem-knobs", [&](std::int64_t) { sweep.include_fem_knobs = false; },
                      "Do not sweep FEM refinement and degree");
  sweep_cmd->add_flag("-q,--quiet", sweep.quiet, "Nothing on stdout (warnings and errors still on stderr)");

  GradeOptions grade;
  std::string scores;
  auto* grade_cmd = app.add_subcommand("grade", "Comprehensive weighted grading of models from a CSV of scores");
  grade_cmd->add_option("scores", scores, "CSV: model, resident, then one column per indicator")->required();
  grade_cmd->add_option("-o,--output", output, "Output directory; default: out/grading");
  grade_cmd->add_option("--mu", grade.mu, "Preference coefficient (share of the subjective weights), default 0.4");
  grade_cmd->add_flag("-q,--quiet", grade.quiet, "Nothing on stdout");

#ifdef PUNCTURE_HAVE_COMPARE
  CompareOptions compare;
  auto* compare_cmd = app.add_subcommand("compare", "Comparison models of both papers against the FEM, graded (Sec. 3.3)");
  compare_cmd->add_option("scene", scene, "Scene file (JSON); default: scenes/default.json");
  compare_cmd->add_option("--models", compare.models, "Models (comma separated); default: all")->delimiter(',');
  compare_cmd->add_option("-o,--output", output, "Output directory; default: out/<scene name>_comparison");
  compare_cmd->add_option("--cache", cache, "FEM cache directory; default: out/.fem_cache");
  compare_cmd->add_option("--weights", compare.weights, "Delphi weights file; default: scenes/delphi_weights.json");
  compare_cmd->add_option("--identify", compare.identify, "Identify the mass-spring stiffnesses: simulated_annealing,isres")
      ->delimiter(',');
  compare_cmd->add_option("--identify-evaluations", compare.identify_evaluations, "Model runs per identification (40)");
  compare_cmd->add_option("--frames", compare.frames, "ParaView frames per model (20; 0: none)");
  compare_cmd->add_flag("--no-vtk", [&](std::int64_t) { compare.write_vtk = false; }, "No VTK output");
  compare_cmd->add_flag("-q,--quiet", compare.quiet, "No progress output");
#endif

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every usage error exits 2 (CLI11's own
    // codes, 100-120, are not documented and would vary by error).
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }

  const auto dispatch = [&]() -> int {
    if (*run_cmd) {
      run.scene = scene, run.output_dir = output;
      return run_command(run, std::cout, std::cerr);
    }
    if (*fem_cmd) {
      fem.scene = scene, fem.output_dir = output;
      return fem_command(fem, std::cout, std::cerr);
    }
    if (*validate_cmd) {
      validate.scene = scene, validate.output_dir = output, validate.cache_dir = cache;
      return validate_command(validate, std::cout, std::cerr);
    }
    if (*calibrate_cmd) {
      calibrate.scene = scene, calibrate.output_dir = output, calibrate.cache_dir = cache, calibrate.reference = reference;
      return calibrate_command(calibrate, std::cout, std::cerr);
    }
    if (*sweep_cmd) {
      sweep.scene = scene, sweep.output_dir = output, sweep.cache_dir = cache;
      return sweep_command(sweep, std::cout, std::cerr);
    }
#ifdef PUNCTURE_HAVE_COMPARE
    if (*compare_cmd) {
      compare.scene = scene, compare.output_dir = output, compare.cache_dir = cache;
      return compare_command(compare, std::cout, std::cerr);
    }
#endif
    if (*grade_cmd) {
      grade.scores = scores, grade.output_dir = output;
      return grade_command(grade, std::cout, std::cerr);
    }
    return kExitFailure;
  };
  const int exit_code = dispatch();
  puncture::validation::finalize_mpi();  // before static destruction (see fem_reference.hpp)
  return exit_code;
}
