// `puncture calibrate`: tunes the real-time model's force-law parameters
// against a reference insertion curve (the scene's FEM reference, cached, or a
// measured curve) and writes a tuned preset with its provenance, the curves of
// the reference and of the model before and after (calibration_curves.csv),
// their plot (calibration_force_depth.png, scripts/plot_calibration.py), for a
// measured reference what was detected on it (reference_detection.png,
// scripts/plot_reference_detection.py) and calibration_summary.md.
#include <chrono>
#include <cmath>
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
#include "puncture/validation/recording.hpp"
#include "puncture/validation/fem_comparison.hpp"
#include "puncture/validation/fem_reference_curve.hpp"
#include "puncture/validation/surface_identification.hpp"
#include "puncture/validation/number_format.hpp"
#include "puncture/validation/validation_cases.hpp"
#include "puncture/io/atomic_file.hpp"

namespace puncture::apps {
namespace {

/// The raw-recording options as given (empty for a curve in the reader's schema).
std::string recording_options_text(const validation::ReferenceRecordingOptions& r) {
  std::ostringstream c;
  const validation::RecordingFormat& o = r.overrides;
  if (!r.format_file.empty()) c << " --recording-format " << r.format_file.string();
  const std::pair<const char*, const std::string*> texts[] = {
      {"--time-column", &o.time.name},         {"--time-unit", &o.time.unit}, {"--position-column", &o.position.name},
      {"--position-unit", &o.position.unit}, {"--force-column", &o.force.name}, {"--force-unit", &o.force.unit}};
  for (const auto& [flag, value] : texts)
    if (!value->empty()) c << ' ' << flag << ' ' << *value;
  if (o.into_tissue != validation::StageDirection::Unset)
    c << " --stage-direction " << (o.into_tissue == validation::StageDirection::Increasing ? "increasing" : "decreasing");
  if (o.force_sign != 0) c << " --force-sign " << o.force_sign;
  return c.str();
}

/// The command line that reproduces this calibration, every setting spelled out.
std::string command_line(const CalibrateOptions& options, const std::filesystem::path& scene_path,
                         const std::filesystem::path& dir, const std::string& name, const std::string& integrator) {
  std::ostringstream c;
  c << "puncture calibrate " << scene_path.string();
  if (!options.reference.empty()) c << " --reference " << options.reference.string();
  c << recording_options_text(options.recording);
  if (options.reference_depth_offset_mm != 0.0) c << " --reference-depth-offset " << options.reference_depth_offset_mm;
  c << " -o " << dir.string() << " --name " << name << " --method " << options.method;
  for (std::size_t i = 0; i < options.also_tune.size(); ++i) c << (i ? "," : " --also-tune ") << options.also_tune[i];
  for (const std::string& layer : options.layers) c << " --layers " << layer;
  if (options.threads > 0) c << " --threads " << options.threads;
  if (options.tune_unidentifiable) c << " --tune-unidentifiable";
  c << " --stage-turn-margin " << options.stage_turn_margin_mm;
  c << " --bound-factor " << options.bound_factor << " --depth-weight " << options.depth_weight
    << " --force-weight " << options.force_weight << " --integrator "
    << integrator;
  for (std::size_t i = 0; i < options.puncture_depths_mm.size(); ++i)
    c << (i ? "," : " --puncture-depths ") << options.puncture_depths_mm[i];
  for (std::size_t i = 0; i < options.keep.size(); ++i) c << (i ? "," : " --keep ") << options.keep[i];
  for (std::size_t i = 0; i < options.fem_speeds_mm_per_s.size(); ++i)
    c << (i ? "," : " --fem-speeds ") << options.fem_speeds_mm_per_s[i];
  if (options.surface_fit) c << " --surface-fit";
  if (options.cutting_from_next_puncture) c << " --cutting-from-next-puncture";
  for (std::size_t i = 0; i < options.layer_thickness_mm.size(); ++i)
    c << (i ? "," : " --layer-thickness ") << options.layer_thickness_mm[i];
  return c.str();
}

/// The references: the scene's FEM reference (cached) and, with
/// --fem-speeds, the FEM references of the scene at those speeds; or the
/// measured curve. False on the MPI ranks that only help with the FEM.
bool load_references(const CalibrateOptions& options, const Scene& scene, std::ostream& out,
                     std::vector<validation::ReferenceCurve>& references, std::filesystem::path& fem_dir) {
  if (options.reference.empty()) {
    if (!options.recording.format_file.empty() || !options.recording.overrides.empty())
      throw UsageError("--recording-format and the --time-column ... options describe a raw --reference recording: "
                       "give --reference");
    validation::FemReferenceOptions fem;
    if (!options.cache_dir.empty()) fem.cache_dir = options.cache_dir;
    fem.verbose = !options.quiet;
    std::vector<Scene> scenes{scene};
    for (double v : options.fem_speeds_mm_per_s) {
      if (!(v > 0.0) || !std::isfinite(v)) throw UsageError("--fem-speeds: speeds must be finite and > 0 (mm/s)");
      if (std::abs(v * 1e-3 - scene.insertion.speed_m_per_s) <= 1e-9) continue;  // the scene's own reference
      scenes.push_back(validation::scene_at_insertion_speed(scene, v * 1e-3));
    }
    for (const Scene& s : scenes) {
      const validation::FemReference ref = validation::obtain_fem_reference(s, fem, out);
      if (!validation::is_mpi_root()) continue;
      out << "[calibrate] FEM reference " << ref.hash << " at " << s.insertion.speed_m_per_s * 1e3 << " mm/s"
          << (ref.from_cache ? " (from cache)" : " (computed)") << '\n';
      if (references.empty()) fem_dir = ref.dir;
      references.push_back({validation::fem_insertion_curve(s, ref.dir / "fem_force_depth.csv"), "fem"});
    }
    return validation::is_mpi_root();
  }
  if (!options.fem_speeds_mm_per_s.empty()) throw UsageError("--fem-speeds takes the scene's FEM reference, not --reference");
  if (options.surface_fit) throw UsageError("--surface-fit needs the scene's FEM reference (its surface profiles), not --reference");
  validation::ReferenceCurve reference;
  reference.curve = validation::read_reference_recording(options.reference, options.recording);
  reference.kind = "measured";
  const auto& meta = reference.curve.metadata;
  if (meta.count("recording_format"))
    out << "[calibrate] raw recording " << options.reference.string() << " (format: " << meta.at("recording_format")
        << "): contact at " << meta.at("contact_time_s") << " s, tare " << meta.at("tare_N") << " N, noise "
        << meta.at("noise_N") << " N, insertion at " << meta.at("speed_mm_per_s") << " mm/s\n";
  if (!std::isfinite(options.reference_depth_offset_mm))
    throw UsageError("--reference-depth-offset must be a finite number (mm)");
  if (options.reference_depth_offset_mm != 0.0) {
    for (double& d : reference.curve.depth_m) d -= options.reference_depth_offset_mm * 1e-3;
    reference.curve.metadata["depth_offset_mm"] = std::to_string(options.reference_depth_offset_mm);
  }
  references.push_back(reference);
  return true;
}

/// The curves the report plots: per reference, the reference and the model
/// before and after; the first reference's series keep their plain names
/// (reference kind, "before", "after"), the others carry "@<speed>mm_per_s".
std::vector<std::pair<std::string, const validation::InsertionCurve*>> curve_list(
    const std::vector<validation::ReferenceCurve>& references, const validation::CalibrationResult& result) {
  std::vector<std::pair<std::string, const validation::InsertionCurve*>> curves;
  for (std::size_t r = 0; r < references.size(); ++r) {
    std::string suffix;
    const auto speed = references[r].curve.metadata.find("speed_mm_per_s");
    if (r > 0) suffix = "@" + (speed != references[r].curve.metadata.end() ? speed->second : std::to_string(r)) + "mm_per_s";
    curves.push_back({references[r].kind + suffix, &references[r].curve});
    curves.push_back({"before" + suffix, &result.model_before[r]});
    curves.push_back({"after" + suffix, &result.model_after[r]});
  }
  return curves;
}

/// --surface-fit: each layer with FEM surface profiles gets the force mesh
/// identified from them and no tip stiffening (the mesh carries it); K and
/// the stiffening are then kept. Returns the identifications for the report.
std::vector<validation::SurfaceIdentificationResult> fit_surfaces(const std::filesystem::path& fem_dir, Scene& scene,
                                                                  validation::CalibrationOptions& calibration,
                                                                  int threads, std::ostream& out) {
  const validation::FemResultFiles fem = validation::read_fem_result(fem_dir, scene);
  std::vector<validation::SurfaceIdentificationResult> results;
  validation::SurfaceIdentificationOptions o;
  o.threads = threads;
  o.bound_factor = calibration.bound_factor;
  o.rings_search_radius = 2;  // w from the extent of the FEM's deformed surface
  o.max_extent_m = 0.5 * scene.sample.diameter_m;
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    Layer& layer = scene.layers[k];
    const validation::SurfacePressingReference ref = validation::surface_pressing_reference(fem, scene, k);
    if (ref.size() < 3) {
      out << "[calibrate] surface fit: layer " << layer.name << ": " << ref.size()
          << " pressing profile(s) in the FEM, its force mesh stays\n";
      continue;
    }
    results.push_back(validation::identify_force_mesh(layer.force_mesh, layer.thickness_m, layer.density_kg_per_m3, ref, o));
    layer.force_mesh = results.back().after;
    layer.force_law.stiffening = StiffeningLaw{};  // the mesh stiffens itself
    out << "[calibrate] surface fit: layer " << layer.name << ": force RMSE "
        << results.back().quality_before.force_rmse_relative << " -> " << results.back().quality_after.force_rmse_relative
        << ", deflection RMSE " << results.back().quality_before.deflection_rmse_relative << " -> "
        << results.back().quality_after.deflection_rmse_relative << " (" << results.back().status << ")\n";
  }
  calibration.parameters.virtual_stiffness = false;
  calibration.parameters.stiffening = false;
  return results;
}

void check_option(bool ok, const std::string& message) {
  if (!ok) throw UsageError(message);
}

/// The parameters --also-tune adds and --keep removes.
void select_parameters(const CalibrateOptions& options, validation::TunedParameterSet& p) {
  for (const std::string& name : options.also_tune) {
    if (name == "surface_stiffness") p.surface_stiffness = true;
    else if (name == "rings") p.rings = true;
    else if (name == "spacing") p.spacing = true;
    else throw UsageError("--also-tune: unknown parameter '" + name + "' (surface_stiffness, rings or spacing)");
  }
  for (const std::string& name : options.keep) {
    if (name == "K") p.virtual_stiffness = false;
    else if (name == "breakthrough") p.deformed_threshold = false;
    else if (name == "cutting") p.cutting = false;
    else if (name == "friction") p.friction = false;
    else if (name == "stiffening") p.stiffening = false;
    else throw UsageError("--keep: unknown parameter '" + name + "' (K, breakthrough, cutting, friction or stiffening)");
  }
}

/// The library's options from the command line's (UsageError for bad values).
validation::CalibrationOptions calibration_options(const CalibrateOptions& options, const Scene& scene) {
  validation::CalibrationOptions c;
  c.method = validation::parse_calibration_method(options.method);
  c.layers = options.layers;
  c.threads = options.threads;
  c.keep_unidentifiable_at_start = !options.tune_unidentifiable;
  c.cutting_from_next_puncture = options.cutting_from_next_puncture;
  c.stage_turn_margin_m = options.stage_turn_margin_mm * 1e-3;
  check_option(std::isfinite(options.bound_factor) && options.bound_factor > 1.0, "--bound-factor must be a finite number > 1");
  c.bound_factor = options.bound_factor;
  c.integrator = options.integrator.empty() ? scene.realtime.integrator : options.integrator;
  if (c.integrator != "quasi_static" && c.integrator != "explicit" && c.integrator != "implicit")
    throw UsageError("--integrator must be quasi_static, explicit or implicit (got '" + c.integrator + "')");
  check_option(std::isfinite(options.depth_weight) && options.depth_weight >= 0.0,
               "--depth-weight must be a finite number >= 0");
  c.weights.puncture_depth = options.depth_weight;
  check_option(std::isfinite(options.force_weight) && options.force_weight >= 0.0,
               "--force-weight must be a finite number >= 0");
  c.weights.puncture_force = options.force_weight;
  select_parameters(options, c.parameters);
  for (double d : options.puncture_depths_mm) {
    if (!(d > 0.0) || !std::isfinite(d)) throw UsageError("--puncture-depths: depths must be finite and > 0 (mm)");
    c.puncture_depths_m.push_back(d * 1e-3);
  }
  return c;
}

/// --layer-thickness: the scene with other layer thicknesses (the override of
/// a validation case, validation_cases.hpp; named <scene>_slab_<thicknesses>).
Scene scene_on_slab(const std::filesystem::path& scene_path, const std::vector<double>& thickness_mm) {
  validation::ValidationCase slab;
  slab.name = "slab";
  for (double t : thickness_mm) {
    if (!(t > 0.0) || !std::isfinite(t)) throw UsageError("--layer-thickness: thicknesses must be finite and > 0 (mm)");
    slab.name += "_" + validation::significant_digits(t, 4);
  }
  slab.layer_thickness_mm = thickness_mm;
  try {
    return validation::case_scene(io::read_text_file(scene_path), scene_path.string(), slab).scene;
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--layer-thickness: ") + e.what());
  }
}

/// The summary's section on every reference when there are several (the term
/// tables compare the model with the first; the objective sums them all).
std::string every_reference_markdown(const std::vector<validation::ReferenceCurve>& references,
                                     const validation::CalibrationResult& result) {
  std::ostringstream refs;
  refs << "\n## Every reference\n\nThe term tables above compare the model with the first reference; the "
          "calibration's objective is the sum over all of them:\n\n| reference | speed (mm/s) | objective before | "
          "after |\n|---|---|---|---|\n";
  for (std::size_t r = 0; r < references.size(); ++r) {
    const auto speed = references[r].curve.metadata.find("speed_mm_per_s");
    refs << "| " << references[r].kind << " (" << references[r].curve.source << ") | "
         << (speed != references[r].curve.metadata.end() ? speed->second : std::string("the scene's")) << " | "
         << std::setprecision(4) << result.trajectory_before[r].objective << " | " << result.trajectory_after[r].objective
         << " |\n";
  }
  return refs.str();
}

}  // namespace

int calibrate_command(const CalibrateOptions& options, std::ostream& stdout_stream, std::ostream& err) {
  NullStream quiet;
  std::ostream& out = options.quiet ? quiet : stdout_stream;
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  return report_errors(err, "", [&]() -> int {
    Scene scene = load_scene(scene_path);
    if (!options.layer_thickness_mm.empty()) scene = scene_on_slab(scene_path, options.layer_thickness_mm);
    const std::filesystem::path dir =
        options.output_dir.empty() ? std::filesystem::path("out") / (scene.name + "_calibration") : options.output_dir;
    std::vector<validation::ReferenceCurve> references;
    std::filesystem::path fem_dir;
    if (!load_references(options, scene, out, references, fem_dir)) return 0;  // the other ranks only help with the FEM
    const validation::ReferenceCurve& reference = references.front();
    validation::CalibrationOptions calibration = calibration_options(options, scene);
    std::vector<validation::SurfaceIdentificationResult> surfaces;
    if (options.surface_fit) surfaces = fit_surfaces(fem_dir, scene, calibration, options.threads, out);
    validation::CalibrationProgressCallback progress;
    if (!options.quiet || options.progress)
      progress = [&](const validation::CalibrationProgress& p) {
        if (!options.quiet && p.evaluations % 25 == 0)
          out << "[calibrate] " << p.stage << ": " << p.evaluations << " model runs, best objective "
              << p.best_objective << '\n' << std::flush;
        if (options.progress) options.progress(p);
      };
    const auto t_start = std::chrono::steady_clock::now();
    const validation::CalibrationResult result = validation::calibrate(scene, references, calibration, progress);
    const double calibration_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();

    io::OutputSession session(dir);
    const std::string name = options.preset_name.empty() ? scene.name + "_tuned" : options.preset_name;
    const io::Provenance provenance = io::make_provenance(command_line(options, scene_path, dir, name, calibration.integrator));
    std::vector<validation::CalibratedValue> surface_values;
    for (const validation::SurfaceIdentificationResult& r : surfaces)
      for (const validation::SurfaceParameterStatus& st : validation::surface_parameter_statuses(r))
        surface_values.push_back({r.layer, st.pointer, st.status, st.reason, "surface fit", st.relative_standard_error});
    validation::write_tuned_preset(session, name, result, references, calibration, surface_values);
    // The model curves the objective compared, before and after, for the report.
    session.write_text("calibration_curves.csv", validation::calibration_curves_csv(curve_list(references, result), provenance));
    if (options.surface_fit)
      session.write_text("surface_identification.csv",
                         io::provenance_comment_lines(provenance) + validation::surface_identification_csv(surfaces));
    session.commit();
    const std::string method = options.method + " on " +
                               (options.threads > 0 ? std::to_string(options.threads) : std::string("every")) +
                               " thread(s)";
    std::string md = validation::calibration_summary_markdown(result, scene, reference, provenance, method, calibration_s, name);
    if (references.size() > 1) md += every_reference_markdown(references, result);
    if (options.surface_fit)
      md += "\n## Force meshes identified from the FEM's surface (--surface-fit)\n\nBefore the stages below, each "
            "layer with FEM surface profiles taken while its surface follows the tip had K, k_s, k_a and z_v "
            "identified from the FEM's tip force and deflection profile together (quasi-static mesh; "
            "validation/calibration/include/puncture/validation/surface_identification.hpp); those layers carry "
            "no tip stiffening (the mesh stiffens itself, so Eq. 5 carries the pressing force) and K and the "
            "stiffening were kept by the stages. Values +- relative standard error (Gauss-Newton); RMSEs before "
            "-> after, over the FEM's largest force and deflection of those samples; per sample and ring in "
            "surface_identification.csv.\n\n" +
            validation::surface_identification_markdown(surfaces);
    // A measured reference: what was detected on it (contact, phases, drops), to check before trusting the fit.
    if (!options.reference.empty()) validation::run_plot_script("plot_reference_detection.py", dir, out, err);
    for (const std::string& p : validation::run_plot_script("plot_calibration.py", dir, out, err))
      md += "\n![" + p + "](" + p + ")\n";
    io::OutputSession md_session(dir);
    md_session.write_text("calibration_summary.md", md);
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
