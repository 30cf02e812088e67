// `puncture calibrate`: tunes the real-time model's force-law parameters
// against a reference insertion curve (the scene's FEM reference, cached, or a
// measured curve) and writes a tuned preset with its provenance, the curves of
// the reference and of the model before and after (calibration_curves.csv),
// their plot (calibration_force_depth.png, scripts/plot_calibration.py), for a
// measured reference what was detected on it (reference_detection.png,
// scripts/plot_reference_detection.py) and calibration_summary.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "command_errors.hpp"
#include "measured_reference.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/validation/fem_reference.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/validation/calibration_report.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/metrics.hpp"
#include "puncture/validation/recording.hpp"
#include "puncture/validation/recording_scatter.hpp"
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
  for (const std::filesystem::path& r : options.references) c << " --reference " << r.string();
  for (const std::filesystem::path& h : options.held_out) c << " --held-out " << h.string();
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

/// A measured reference (a curve, or a raw recording read with its format):
/// the depth offset applied; marked rate dependent unless its metadata says
/// otherwise (a bench recording is the tissue at its speed: with recordings at
/// two or more speeds d and the rate laws are tuned).
validation::ReferenceCurve read_measured(const std::filesystem::path& path, const CalibrateOptions& options,
                                         const Scene& scene, std::ostream& out) {
  validation::ReferenceCurve reference = read_measured_reference(path, options.recording, scene.insertion);
  auto& meta = reference.curve.metadata;
  if (meta.count("recording_format"))
    out << "[calibrate] raw recording " << path.string() << " (format: " << meta.at("recording_format")
        << "): contact at " << meta.at("contact_time_s") << " s, tare " << meta.at("tare_N") << " N, noise "
        << meta.at("noise_N") << " N, insertion at " << meta.at("speed_mm_per_s") << " mm/s\n";
  if (options.reference_depth_offset_mm != 0.0) {
    for (double& d : reference.curve.depth_m) d -= options.reference_depth_offset_mm * 1e-3;
    meta["depth_offset_mm"] = std::to_string(options.reference_depth_offset_mm);
    validation::insertion_phase(reference.curve);  // still an insertion after the offset (names the file)
  }
  return reference;
}

/// The scene's FEM reference (cached) and, with --fem-speeds, the FEM
/// references of the scene at those speeds. False on the MPI ranks that only help with the FEM.
bool load_fem_references(const CalibrateOptions& options, const Scene& scene, std::ostream& out,
                         std::vector<validation::ReferenceCurve>& references, std::filesystem::path& fem_dir) {
  if (options.held_out.empty() && (!options.recording.format_file.empty() || !options.recording.overrides.empty()))
    throw UsageError("--recording-format and the --time-column ... options describe a raw --reference recording: "
                     "give --reference");
  validation::FemReferenceOptions fem;
  if (!options.cache_dir.empty()) fem.cache_dir = options.cache_dir;
  fem.verbose = !options.quiet;
  fem.on_step = options.fem_step;
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

/// The references (the FEM's, or every --reference) and the --held-out
/// recordings. With more than one recording each must carry its speed.
bool load_references(const CalibrateOptions& options, const Scene& scene, std::ostream& out,
                     std::vector<validation::ReferenceCurve>& references,
                     std::vector<validation::ReferenceCurve>& held_out, std::filesystem::path& fem_dir) {
  if (!std::isfinite(options.reference_depth_offset_mm))
    throw UsageError("--reference-depth-offset must be a finite number (mm)");
  for (const std::filesystem::path& h : options.held_out)
    for (const std::filesystem::path& r : options.references)
      if (std::filesystem::weakly_canonical(h) == std::filesystem::weakly_canonical(r))
        throw UsageError("--held-out " + h.string() + " is also a --reference: a recording is fitted or held out");
  if (options.references.empty()) {
    require_axial_for_fem(scene, scene.source_path, "the FEM reference");
    if (!load_fem_references(options, scene, out, references, fem_dir)) return false;
  } else {
    if (!options.fem_speeds_mm_per_s.empty()) throw UsageError("--fem-speeds takes the scene's FEM reference, not --reference");
    if (options.surface_fit) throw UsageError("--surface-fit needs the scene's FEM reference (its surface profiles), not --reference");
    for (const std::filesystem::path& path : options.references) references.push_back(read_measured(path, options, scene, out));
  }
  for (const std::filesystem::path& path : options.held_out) held_out.push_back(read_measured(path, options, scene, out));
  if (options.references.size() + held_out.size() > 1) {
    std::vector<const validation::ReferenceCurve*> all;
    for (const auto* list : {&references, &held_out})
      for (const validation::ReferenceCurve& r : *list) all.push_back(&r);
    require_insertion_speeds(all);
  }
  return true;
}

/// The curves the report plots: per recording (fitted, then held out), the
/// recording and the model before and after on its trajectory; the first
/// reference's series keep their plain names (reference kind, "before",
/// "after"), the others carry "@<speed>mm_per_s" (and "#<n>" for a repeat of a
/// speed already named); a held-out recording's series is "held_out@...".
std::vector<std::pair<std::string, const validation::InsertionCurve*>> curve_list(
    const std::vector<validation::JudgedRecording>& recordings) {
  std::vector<std::pair<std::string, const validation::InsertionCurve*>> curves;
  std::vector<std::string> used;
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    const validation::JudgedRecording& j = recordings[r];
    std::string suffix;
    if (r > 0) {
      const auto speed = j.reference.curve.metadata.find("speed_mm_per_s");
      suffix = "@" + (speed != j.reference.curve.metadata.end() ? speed->second : std::to_string(r)) + "mm_per_s";
      if (std::find(used.begin(), used.end(), suffix) != used.end()) suffix += "#" + std::to_string(r + 1);
    }
    used.push_back(suffix);
    curves.push_back({(j.held_out ? std::string("held_out") : j.reference.kind) + suffix, &j.reference.curve});
    curves.push_back({"before" + suffix, &j.model_before});
    curves.push_back({"after" + suffix, &j.model_after});
  }
  return curves;
}

/// --surface-fit: each layer with at least kMinPressingProfiles FEM surface
/// profiles gets the force mesh identified from them and no tip stiffening
/// (the mesh carries it); its K and stiffening are then kept, while a layer
/// with fewer profiles has them tuned in its stage as without the surface
/// fit. Returns the identifications for the report.
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
    if (ref.size() < validation::kMinPressingProfiles) {
      out << "[calibrate] surface fit: layer " << layer.name << ": " << ref.size()
          << " pressing profile(s) in the FEM, its force mesh stays\n";
      continue;
    }
    results.push_back(validation::identify_force_mesh(layer.force_mesh, layer.thickness_m, layer.density_kg_per_m3, ref, o));
    layer.force_mesh = results.back().after;
    layer.force_law.stiffening = StiffeningLaw{};  // the mesh stiffens itself
    calibration.parameters.mesh_identified_layers.push_back(layer.name);
    out << "[calibrate] surface fit: layer " << layer.name << ": force RMSE "
        << results.back().quality_before.force_rmse_relative << " -> " << results.back().quality_after.force_rmse_relative
        << ", deflection RMSE " << results.back().quality_before.deflection_rmse_relative << " -> "
        << results.back().quality_after.deflection_rmse_relative << " (" << results.back().status << ")\n";
  }
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

/// The surface fit's section of the summary.
std::string surface_fit_markdown(const std::vector<validation::SurfaceIdentificationResult>& surfaces) {
  return "\n## Force meshes identified from the FEM's surface (--surface-fit)\n\nBefore the stages below, each "
         "layer with FEM surface profiles taken while its surface follows the tip had K, k_s, k_a and z_v "
         "identified from the FEM's tip force and deflection profile together (quasi-static mesh; "
         "validation/calibration/include/puncture/validation/surface_identification.hpp); those layers carry "
         "no tip stiffening (the mesh stiffens itself, so Eq. 5 carries the pressing force) and K and the "
         "stiffening were kept by the stages; a layer with fewer than " +
         std::to_string(validation::kMinPressingProfiles) + " such profiles had its K and stiffening tuned in its "
         "stage instead. Values +- relative standard error (Gauss-Newton); RMSEs before "
         "-> after, over the FEM's largest force and deflection of those samples; per sample and ring in "
         "surface_identification.csv.\n\n" +
         validation::surface_identification_markdown(surfaces);
}

/// What calibrate_command reports on.
struct Calibrated {
  Scene scene;
  std::vector<validation::ReferenceCurve> references, held_out;
  validation::CalibrationOptions calibration;
  std::vector<validation::SurfaceIdentificationResult> surfaces;
  validation::CalibrationResult result;
  double seconds = 0.0;
  std::vector<validation::JudgedRecording> recordings;  ///< fitted, then held out
  std::vector<validation::RepeatGroup> groups;          ///< the scatter of repeats (several recordings)
  bool scatter = false;                                 ///< two or more measured recordings
};

/// Writes the preset, the curves and the summary into dir (the summary after the plots).
void write_report(const CalibrateOptions& options, const std::filesystem::path& scene_path,
                  const std::filesystem::path& dir, const std::string& name, const Calibrated& c, std::ostream& out,
                  std::ostream& err) {
  io::OutputSession session(dir);
  const io::Provenance provenance =
      io::make_provenance(command_line(options, scene_path, dir, name, c.calibration.integrator));
  std::vector<validation::CalibratedValue> surface_values;
  for (const validation::SurfaceIdentificationResult& r : c.surfaces)
    for (const validation::SurfaceParameterStatus& st : validation::surface_parameter_statuses(r))
      surface_values.push_back({r.layer, st.pointer, st.status, st.reason, "surface fit", st.relative_standard_error});
  validation::write_tuned_preset(session, name, c.result, c.references, c.calibration, surface_values);
  // The model curves the objective compared, before and after, for the report.
  session.write_text("calibration_curves.csv", validation::calibration_curves_csv(curve_list(c.recordings), provenance));
  if (c.scatter) session.write_text("repeat_scatter.csv", validation::repeat_scatter_csv(c.groups, provenance));
  if (options.surface_fit)
    session.write_text("surface_identification.csv",
                       io::provenance_comment_lines(provenance) + validation::surface_identification_csv(c.surfaces));
  session.commit();
  const std::string method = options.method + " on " +
                             (options.threads > 0 ? std::to_string(options.threads) : std::string("every")) +
                             " thread(s)";
  std::string md = validation::calibration_summary_markdown(c.result, c.scene, c.references.front(), provenance, method,
                                                            c.seconds, name);
  if (c.recordings.size() > 1) md += validation::recordings_markdown(c.recordings, c.scene);
  if (c.scatter) md += validation::repeat_scatter_markdown(c.recordings, c.groups, c.scene);
  if (options.surface_fit) md += surface_fit_markdown(c.surfaces);
  // A measured reference: what was detected on it (contact, phases, drops), to check before trusting the fit.
  if (!options.references.empty()) validation::run_plot_script("plot_reference_detection.py", dir, out, err);
  for (const std::string& p : validation::run_plot_script("plot_calibration.py", dir, out, err))
    md += "\n![" + p + "](" + p + ")\n";
  io::OutputSession md_session(dir);
  md_session.write_text("calibration_summary.md", md);
  md_session.commit();
}

}  // namespace

int calibrate_command(const CalibrateOptions& options, std::ostream& stdout_stream, std::ostream& err) {
  NullStream quiet;
  std::ostream& out = options.quiet ? quiet : stdout_stream;
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  return report_errors(err, "", [&]() -> int {
    Calibrated c;
    c.scene = load_scene(scene_path);
    if (!options.layer_thickness_mm.empty()) c.scene = scene_on_slab(scene_path, options.layer_thickness_mm);
    const std::filesystem::path dir =
        options.output_dir.empty() ? std::filesystem::path("out") / (c.scene.name + "_calibration") : options.output_dir;
    std::filesystem::path fem_dir;
    if (!load_references(options, c.scene, out, c.references, c.held_out, fem_dir))
      return 0;  // the other ranks only help with the FEM
    c.calibration = calibration_options(options, c.scene);
    if (options.surface_fit) c.surfaces = fit_surfaces(fem_dir, c.scene, c.calibration, options.threads, out);
    validation::CalibrationProgressCallback progress;
    if (!options.quiet || options.progress)
      progress = [&](const validation::CalibrationProgress& p) {
        if (!options.quiet && p.evaluations % 25 == 0)
          out << "[calibrate] " << p.stage << ": " << p.evaluations << " model runs, best objective "
              << p.best_objective << '\n' << std::flush;
        if (options.progress) options.progress(p);
      };
    const auto t_start = std::chrono::steady_clock::now();
    c.result = validation::calibrate(c.scene, c.references, c.calibration, progress);
    c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    c.recordings = validation::judge_recordings(c.scene, c.result, c.references, c.held_out, c.calibration);
    c.scatter = options.references.size() + options.held_out.size() > 1;
    if (c.scatter) c.groups = validation::repeat_scatter(c.recordings);

    const std::string name = options.preset_name.empty() ? c.scene.name + "_tuned" : options.preset_name;
    write_report(options, scene_path, dir, name, c, out, err);
    out << "\n" << validation::calibration_terms_table(c.result) << "\n"
        << validation::calibration_parameters_table(c.result);
    for (const validation::JudgedRecording& j : c.recordings)
      if (j.held_out)
        out << "held out " << j.reference.curve.source << ": objective " << j.before.objective << " -> "
            << j.after.objective << '\n';
    // Warnings go to stderr: -q silences stdout only.
    for (const std::string& w : c.result.warnings) err << "warning: " << w << "\n";
    out << "\nTuned preset: " << (dir / (name + ".json")).string()
        << "\n  run it with: puncture run " << (dir / (name + ".json")).string() << '\n';
    return 0;
  });
}

}  // namespace puncture::apps
