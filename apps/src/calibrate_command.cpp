// `puncture calibrate`: tunes the real-time model's force-mesh parameters
// against a reference insertion curve (the scene's FEM reference, cached, or a
// measured curve) and writes a tuned preset with its provenance.
#include <iomanip>
#include <iostream>
#include <sstream>

#include "command_errors.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/apps/fem_reference.hpp"
#include "puncture/apps/provenance.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/metrics.hpp"

namespace puncture::apps {
namespace {

std::string metrics_table(const validation::CalibrationResult& r) {
  std::ostringstream s;
  s << "| layer | force RMSE before (N) | after (N) | puncture depth error before (mm) | after (mm) |\n"
       "|---|---|---|---|---|\n";
  if (r.before.empty() || r.after.empty()) return s.str();
  for (const auto& before : r.before.front().layers) {
    const validation::LayerMetrics* after = r.after.front().layer(before.layer);
    s << "| " << before.layer << " | " << std::setprecision(4) << before.force_rmse_N << " | "
      << (after ? after->force_rmse_N : 0.0) << " | " << before.puncture_depth_error_m * 1e3 << " | "
      << (after ? after->puncture_depth_error_m * 1e3 : 0.0) << " |\n";
  }
  return s.str();
}

}  // namespace

int calibrate_command(const CalibrateOptions& options, std::ostream& out, std::ostream& err) {
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  return report_errors(err, "", [&]() -> int {
    const Scene scene = load_scene(scene_path);
    const std::filesystem::path dir =
        options.output_dir.empty() ? std::filesystem::path("out") / (scene.name + "_calibration") : options.output_dir;

    validation::ReferenceCurve reference;
    if (options.reference.empty()) {
      FemReferenceOptions fem;
      if (!options.cache_dir.empty()) fem.cache_dir = options.cache_dir;
      fem.verbose = !options.quiet;
      const FemReference ref = obtain_fem_reference(scene, fem, out);
      out << "[calibrate] FEM reference " << ref.hash << (ref.from_cache ? " (from cache)" : " (computed)") << '\n';
      reference.curve = validation::read_insertion_curve(ref.dir / "fem_force_depth.csv");
      reference.kind = "fem";
    } else {
      reference.curve = validation::read_insertion_curve(options.reference);
      reference.kind = "measured";
    }

    validation::CalibrationOptions calibration;
    calibration.method = validation::parse_calibration_method(options.method);
    calibration.layers = options.layers;
    validation::CalibrationProgressCallback progress;
    if (!options.quiet)
      progress = [&](const validation::CalibrationProgress& p) {
        if (p.evaluations % 25 == 0)
          out << "[calibrate] " << p.stage << ": " << p.evaluations << " model runs, best objective "
              << p.best_objective << '\n'
              << std::flush;
      };
    const validation::CalibrationResult result = validation::calibrate(scene, reference.curve, calibration, progress);

    io::OutputSession session(dir);
    const std::string name = options.preset_name.empty() ? scene.name + "_tuned" : options.preset_name;
    validation::write_tuned_preset(session, name, result, {reference}, calibration);
    std::ostringstream md;
    md << "# Calibration of " << scene.name << "\n\nMade by `puncture calibrate " << scene_path.string()
       << (options.reference.empty() ? "" : " --reference " + options.reference.string()) << " -o " << dir.string()
       << "` on " << machine_summary() << ", " << utc_timestamp() << ".\n\nReference: " << reference.kind << " ("
       << reference.curve.source << "). Method: " << options.method << ", " << result.evaluations
       << " model runs. Objective " << result.objective_before << " -> " << result.objective_after << ".\n\n"
       << metrics_table(result) << "\nTuned preset: `" << name << ".json` (a scene `puncture run` accepts), provenance: `"
       << name << ".provenance.json`.\n";
    if (!result.damping_note.empty()) md << "\nDamping d: " << result.damping_note << "\n";
    session.write_text("calibration_summary.md", md.str());
    session.commit();

    out << "\n" << metrics_table(result) << "\nTuned preset: " << (dir / (name + ".json")).string()
        << "\n  run it with: puncture run " << (dir / (name + ".json")).string() << '\n';
    return 0;
  });
}

}  // namespace puncture::apps
