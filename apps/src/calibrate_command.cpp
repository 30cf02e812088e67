// `puncture calibrate`: tunes the real-time model's force-law parameters
// against a reference insertion curve (the scene's FEM reference, cached, or a
// measured curve) and writes a tuned preset with its provenance, the curves of
// the reference and of the model before and after (calibration_curves.csv),
// their plot (calibration_force_depth.png, scripts/plot_calibration.py) and
// calibration_summary.md.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "command_errors.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/validation/fem_reference.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/validation/calibration_report.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/metrics.hpp"
#include "puncture/validation/fem_comparison.hpp"

namespace puncture::apps {
namespace {

/// The command line that reproduces this calibration, every setting spelled out.
std::string command_line(const CalibrateOptions& options, const std::filesystem::path& scene_path,
                         const std::filesystem::path& dir, const std::string& name, const std::string& integrator) {
  std::ostringstream c;
  c << "puncture calibrate " << scene_path.string();
  if (!options.reference.empty()) c << " --reference " << options.reference.string();
  if (options.reference_depth_offset_mm != 0.0) c << " --reference-depth-offset " << options.reference_depth_offset_mm;
  c << " -o " << dir.string() << " --name " << name << " --method " << options.method;
  for (std::size_t i = 0; i < options.also_tune.size(); ++i) c << (i ? "," : " --also-tune ") << options.also_tune[i];
  for (const std::string& layer : options.layers) c << " --layers " << layer;
  if (options.threads > 0) c << " --threads " << options.threads;
  c << " --stage-turn-margin " << options.stage_turn_margin_mm;
  c << " --bound-factor " << options.bound_factor << " --depth-weight " << options.depth_weight
    << " --force-weight " << options.force_weight << " --integrator "
    << integrator;
  for (std::size_t i = 0; i < options.puncture_depths_mm.size(); ++i)
    c << (i ? "," : " --puncture-depths ") << options.puncture_depths_mm[i];
  for (std::size_t i = 0; i < options.keep.size(); ++i) c << (i ? "," : " --keep ") << options.keep[i];
  return c.str();
}

}  // namespace

int calibrate_command(const CalibrateOptions& options, std::ostream& stdout_stream, std::ostream& err) {
  NullStream quiet;
  std::ostream& out = options.quiet ? quiet : stdout_stream;
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  return report_errors(err, "", [&]() -> int {
    const Scene scene = load_scene(scene_path);
    const std::filesystem::path dir =
        options.output_dir.empty() ? std::filesystem::path("out") / (scene.name + "_calibration") : options.output_dir;

    validation::ReferenceCurve reference;
    if (options.reference.empty()) {
      validation::FemReferenceOptions fem;
      if (!options.cache_dir.empty()) fem.cache_dir = options.cache_dir;
      fem.verbose = !options.quiet;
      const validation::FemReference ref = validation::obtain_fem_reference(scene, fem, out);
      if (!validation::is_mpi_root()) return 0;  // the other ranks only help with the FEM
      out << "[calibrate] FEM reference " << ref.hash << (ref.from_cache ? " (from cache)" : " (computed)") << '\n';
      reference.curve = validation::read_insertion_curve(ref.dir / "fem_force_depth.csv");
      reference.kind = "fem";
    } else {
      reference.curve = validation::read_insertion_curve(options.reference);
      reference.kind = "measured";
      if (!std::isfinite(options.reference_depth_offset_mm))
        throw UsageError("--reference-depth-offset must be a finite number (mm)");
      if (options.reference_depth_offset_mm != 0.0) {
        for (double& d : reference.curve.depth_m) d -= options.reference_depth_offset_mm * 1e-3;
        reference.curve.metadata["depth_offset_mm"] = std::to_string(options.reference_depth_offset_mm);
      }
    }

    validation::CalibrationOptions calibration;
    calibration.method = validation::parse_calibration_method(options.method);
    calibration.layers = options.layers;
    calibration.threads = options.threads;
    calibration.stage_turn_margin_m = options.stage_turn_margin_mm * 1e-3;
    if (!(options.bound_factor > 1.0) || !std::isfinite(options.bound_factor))
      throw UsageError("--bound-factor must be a finite number > 1");
    calibration.bound_factor = options.bound_factor;
    calibration.integrator = options.integrator.empty() ? scene.realtime.integrator : options.integrator;
    if (calibration.integrator != "quasi_static" && calibration.integrator != "explicit" &&
        calibration.integrator != "implicit")
      throw UsageError("--integrator must be quasi_static, explicit or implicit (got '" + calibration.integrator + "')");
    if (!(options.depth_weight >= 0.0) || !std::isfinite(options.depth_weight))
      throw UsageError("--depth-weight must be a finite number >= 0");
    calibration.weights.puncture_depth = options.depth_weight;
    if (!(options.force_weight >= 0.0) || !std::isfinite(options.force_weight))
      throw UsageError("--force-weight must be a finite number >= 0");
    calibration.weights.puncture_force = options.force_weight;
    for (const std::string& name : options.also_tune) {
      if (name == "surface_stiffness")
        calibration.parameters.surface_stiffness = true;
      else if (name == "rings")
        calibration.parameters.rings = true;
      else if (name == "spacing")
        calibration.parameters.spacing = true;
      else
        throw UsageError("--also-tune: unknown parameter '" + name +
                                    "' (surface_stiffness, rings or spacing)");
    }
    for (const std::string& name : options.keep) {
      if (name == "K") calibration.parameters.virtual_stiffness = false;
      else if (name == "breakthrough") calibration.parameters.deformed_threshold = false;
      else if (name == "cutting") calibration.parameters.cutting = false;
      else if (name == "friction") calibration.parameters.friction = false;
      else if (name == "stiffening") calibration.parameters.stiffening = false;
      else
        throw UsageError("--keep: unknown parameter '" + name + "' (K, breakthrough, cutting, friction or stiffening)");
    }
    for (double d : options.puncture_depths_mm) {
      if (!(d > 0.0) || !std::isfinite(d)) throw UsageError("--puncture-depths: depths must be finite and > 0 (mm)");
      calibration.puncture_depths_m.push_back(d * 1e-3);
    }
    validation::CalibrationProgressCallback progress;
    if (!options.quiet)
      progress = [&](const validation::CalibrationProgress& p) {
        if (p.evaluations % 25 == 0)
          out << "[calibrate] " << p.stage << ": " << p.evaluations << " model runs, best objective "
              << p.best_objective << '\n'
              << std::flush;
      };
    const auto t_start = std::chrono::steady_clock::now();
    const validation::CalibrationResult result = validation::calibrate(scene, std::vector<validation::ReferenceCurve>{reference}, calibration, progress);
    const double calibration_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();

    io::OutputSession session(dir);
    const std::string name = options.preset_name.empty() ? scene.name + "_tuned" : options.preset_name;
    const std::string command = command_line(options, scene_path, dir, name, calibration.integrator);
    const io::Provenance provenance = io::make_provenance(command);
    validation::write_tuned_preset(session, name, result, {reference}, calibration);
    // The model curves the objective compared, before and after, for the report.
    session.write_text("calibration_curves.csv",
                       validation::calibration_curves_csv({{reference.kind, &reference.curve},
                                                           {"before", &result.model_before.front()},
                                                           {"after", &result.model_after.front()}},
                                                          provenance));
    std::ostringstream md;
    md << "# Calibration of " << scene.name << "\n\nMade by `" << command << "` on " << provenance.machine << ", " << provenance.date_utc << " (program " << provenance.program_version
       << ", git " << provenance.git_revision << ").\n\nReference: " << reference.kind << " ("
       << reference.curve.source << "). Method: " << options.method << " on "
       << (options.threads > 0 ? std::to_string(options.threads) : std::string("every")) << " thread(s), "
       << result.evaluations
       << " model runs in " << std::setprecision(4) << calibration_s
       << " s (wall, reference already available). Objective " << result.objective_before << " -> "
       << result.objective_after << ".\n\n"
       << "## Objective, term by term\n\n" << validation::calibration_terms_table(result) << "\n## Punctures\n\n"
       << validation::calibration_punctures_table(result, scene) << "\n## Tuned parameters\n\n"
       << validation::calibration_parameters_table(result) << "\n## Identifiability\n\n"
       << validation::calibration_identifiability_table(result) << "\nTuned preset: `" << name
       << ".json` (a scene `puncture run` accepts), provenance: `" << name << ".provenance.json`, identifiability: `"
       << name << ".identifiability.md`.\n";
    if (!result.damping_note.empty()) md << "\nDamping d: " << result.damping_note << "\n";
    if (!result.warnings.empty()) {
      md << "\n## Warnings\n\n";
      for (const std::string& w : result.warnings) md << "- " << w << "\n";
    }
    session.commit();
    const std::vector<std::string> plots = validation::run_plot_script("plot_calibration.py", dir, out, err);
    for (const std::string& p : plots) md << "\n![" << p << "](" << p << ")\n";
    io::OutputSession md_session(dir);
    md_session.write_text("calibration_summary.md", md.str());
    md_session.commit();

    out << "\n" << validation::calibration_terms_table(result) << "\n" << validation::calibration_parameters_table(result);
    // Warnings go to stderr: -q silences stdout only.
    for (const std::string& w : result.warnings) err << "warning: " << w << "\n";
    out << "\nTuned preset: " << (dir / (name + ".json")).string()
        << "\n  run it with: puncture run " << (dir / (name + ".json")).string() << '\n';
    return 0;
  });
}

}  // namespace puncture::apps
