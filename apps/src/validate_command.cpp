// `puncture validate`: the real-time model and the FEM reference (cached) on
// the identical insertion (same scene, same trajectory), aligned on depth.
//
// With --cases FILE the model scene is validated, without retuning, on every
// case of the file (validation_cases.hpp): one report per case in
// <dir>/<case>/ (with the case's scene.json), then heldout_summary.json and
// heldout_summary.md in <dir>.
//
// Algorithm for one scene (top-down):
//   1. load the scene; obtain the FEM reference (cache or solve);
//   2. run the real-time model along the scripted insertion, recording every
//      haptic tick's ring deflections Delta Z_j of each layer (mean over the
//      ring's nodes of the downward displacement) and, when VTK output is on,
//      the layer surfaces at the FEM's frame times, shifted by one sample
//      diameter in x so both models stand side by side in ParaView;
//   3. force-depth metrics per layer (validation::compare_curves);
//   4. deflection before each breakthrough: the last depth at which the layer
//      is intact in BOTH models (the smaller of the two pre-breakthrough
//      depths); real-time Delta Z_j at r_j = (j - 1) L against the FEM u_z(r)
//      of the layer's top surface at the nearest recorded depth;
//   5. recovery after breakthrough: the FEM's spring-back profile (same depth,
//      after the material was removed; fem_recovery_profile.csv) against the
//      real-time ring deflections the layer's resumption time (rounded up to
//      haptic steps) after the breakthrough (when Eq. 8's recovery factor has
//      reached 0);
//   6. report folder: CSV, JSON, VTK (.vtp, .vtu, one validation.pvd), then
//      PNG plots (scripts/plot_validation.py) and validation_summary.md.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "command_errors.hpp"
#include "measured_reference.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/validation/fem_reference.hpp"
#include "puncture/io/atomic_file.hpp"
#include "puncture/io/vtk_xml_field_data.hpp"
#include "puncture/io/provenance_json.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/io/pvd.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/acceptance.hpp"
#include "puncture/validation/metrics.hpp"
#include "puncture/validation/fem_comparison.hpp"
#include "puncture/validation/puncture_force_shares.hpp"
#include "puncture/validation/number_format.hpp"
#include "puncture/validation/validation_cases.hpp"
#ifdef PUNCTURE_HAVE_VTK  // frames are VTK files
#include "puncture/vtk_io/realtime_frames.hpp"
#endif
#include "validate_recordings.hpp"

namespace puncture::apps {

namespace {

constexpr double kMm = 1e-3;

std::string fmt(double x, int precision = 10) {
  if (!std::isfinite(x)) return "nan";
  return validation::significant_digits(x, precision);
}

/// VTK output asked for and built (without VTK: CSV, PNG and markdown only).
bool writes_vtk(const ValidateOptions& options) {
#ifdef PUNCTURE_HAVE_VTK
  return options.write_vtk;
#else
  (void)options;
  return false;
#endif
}

/// What one scene's validation leaves for a held-out summary.
struct SceneValidation {
  std::vector<validation::LayerAcceptance> acceptance;
  nlohmann::json layers;
  nlohmann::json trajectory_terms;  ///< trajectory_terms_json
};

/// The real-time run along the FEM's trajectory: every tick's ring
/// deflections and, with VTK, the surfaces at the FEM's frame times.
struct RealtimeRun {
  ScriptedRunResult run;
  validation::RingRecorder recorder;
  std::vector<io::PvdEntry> frames;
};

/// The run's puncture events view the model's layer names: `model` must
/// outlive the result.
RealtimeRun run_realtime(RealtimeModel& model, const Scene& scene, const validation::FemResultFiles& fem, bool vtk,
                         const io::Provenance& provenance, io::OutputSession& session, const ValidateOptions& options,
                         std::ostream& out) {
  using namespace validation;
  RealtimeRun result{{}, RingRecorder(scene), {}};
  std::vector<double> frame_times = vtk ? fem.frame_times_s : std::vector<double>{};
#ifdef PUNCTURE_HAVE_VTK
  std::optional<io::FrameWriter> writer;
  if (!frame_times.empty()) {
    io::FrameWriterOptions fw;
    fw.provenance = &provenance;
    fw.directory = "realtime";
    fw.pvd_name.clear();
    fw.x_offset_m = scene.sample.diameter_m;
    fw.first_part = 1;
    fw.reference_deflection_mm = [&fem, &scene](std::size_t layer, double r_m, double time_s) {
      return fem_deflection_at_mm(fem, scene, layer, r_m, time_s);
    };
    writer.emplace(session, model, scene, fw);
  }
#else
  (void)provenance, (void)session;
#endif
  std::size_t next_frame = 0;
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  Scene every_tick = scene;  // on_frame every tick: the recorder sees every state
  every_tick.realtime.frame_rate_Hz = scene.realtime.haptic_rate_Hz;
  FrameCallback on_tick = [&](const PunctureSimulator& sim, const TickResult& t, int) {
    result.recorder.record(sim);
#ifdef PUNCTURE_HAVE_VTK
    while (writer && next_frame < frame_times.size() && t.time_s + 0.5 * dt >= frame_times[next_frame]) {
      writer->write(sim, t, static_cast<int>(next_frame));
      ++next_frame;
    }
#else
    (void)t, (void)next_frame, (void)dt;
#endif
  };
  ProgressCallback on_progress;
  if (!options.quiet)
    on_progress = [&](double f) { out << "[validate] real-time " << std::lround(100 * f) << " %\n" << std::flush; };
  result.run = run_scripted_insertion(model, every_tick, on_tick, on_progress);
#ifdef PUNCTURE_HAVE_VTK
  if (writer) result.frames = writer->entries();
#endif
  return result;
}

nlohmann::json acceptance_json(const std::vector<validation::LayerAcceptance>& acceptance) {
  nlohmann::json acc = nlohmann::json::array();
  for (const auto& a : acceptance) {
    auto check = [](const validation::AcceptanceCheck& c) {
      nlohmann::json j = {{"available", c.available}, {"met", c.met}, {"limit", c.limit}, {"note", c.note}};
      if (c.available) j["value"] = c.value;
      return j;
    };
    acc.push_back({{"layer", a.layer},
                   {"accepted", a.accepted()},
                   {"pressing_and_cut_force_rmse_relative", check(a.force_rmse)},
                   {"puncture_depth_error_m", check(a.puncture_depth)},
                   {"puncture_force_error_relative", check(a.puncture_force)},
                   {"deflection_before_relative", check(a.deflection)},
                   {"deflection_after_relative", check(a.recovery)}});
  }
  return acc;
}

nlohmann::json trajectory_terms_json(const validation::TrajectoryComparison& trajectory) {
  nlohmann::json terms = nlohmann::json::array();
  for (const auto& t : trajectory.terms) {
    nlohmann::json j = {{"term", t.name}, {"layer", t.layer}, {"available", t.available},
                        {"samples", t.samples}, {"note", t.note}};
    if (t.available) j["value"] = t.value, j["error"] = t.raw;
    terms.push_back(j);
  }
  return terms;
}

/// The FEM's frames copied into the report (with this command's provenance
/// where they have none) and validation.pvd over both models.
void write_vtk_report(io::OutputSession& session, const validation::FemReference& reference,
                      const validation::FemResultFiles& fem, const std::vector<io::PvdEntry>& realtime_frames,
                      const io::Provenance& provenance) {
  std::vector<io::PvdEntry> entries;
  for (const validation::FemFrame& f : fem.frames) {
    for (const std::string& file : f.files) {
      std::string text = io::read_text_file(reference.dir / file);
      if (text.find("provenance") == std::string::npos) {
        if (std::filesystem::path(file).extension() == ".vtu")
          text = io::add_provenance_field_data(text, provenance, "m");
        else if (std::filesystem::path(file).extension() == ".pvtu")
          text = io::add_provenance_comment(text, provenance);
      }
      session.write_text("fem/" + file, text);
    }
    entries.push_back({f.time_s, 0, "fem/" + f.pvtu});
  }
  for (const io::PvdEntry& e : realtime_frames) entries.push_back(e);
  if (!entries.empty()) io::write_pvd(session, "validation.pvd", entries, &provenance);
}

void print_result(std::ostream& out, const Scene& scene, const validation::FemReference& reference,
                  const validation::CurveComparison& cmp,
                  const std::vector<validation::LayerAcceptance>& acceptance, const nlohmann::json& layers,
                  const std::filesystem::path& dir) {
  out << "\nValidation of " << scene.name << " (FEM reference " << reference.hash.substr(0, 12)
      << (reference.from_cache ? ", from cache" : ", computed") << ")\n";
  out << "  force RMSE over the insertion: " << fmt(cmp.force_rmse_N, 4) << " N (" << fmt(100 * cmp.force_rmse_relative, 3)
      << " % of the FEM peak " << fmt(cmp.reference_peak_force_N, 4) << " N)\n";
  for (const auto& a : acceptance)
    out << "  acceptance " << std::left << std::setw(8) << a.layer << std::right << (a.accepted() ? "met" : "not met")
        << '\n';
  for (const auto& j : layers) {
    out << "  " << std::left << std::setw(8) << j["layer"].get<std::string>() << std::right;
    if (j.contains("force_rmse_N")) out << " force RMSE " << fmt(j["force_rmse_N"].get<double>(), 4) << " N";
    if (j.contains("puncture_depth_error_mm"))
      out << ", puncture depth error " << fmt(j["puncture_depth_error_mm"].get<double>(), 4) << " mm, force error "
          << fmt(j["puncture_force_error_N"].get<double>(), 4) << " N";
    if (j.contains("deflection")) out << ", deflection RMSE " << fmt(j["deflection"]["rmse_mm"].get<double>(), 4) << " mm";
    out << '\n';
  }
  out << "Report: " << (dir / "validation_summary.md").string() << '\n';
}

}  // namespace

namespace {

/// Steps 3-5: the force-depth metrics, the whole-trajectory comparison with
/// the acceptance per layer, and the surfaces before and after each break.
struct Comparison {
  validation::InsertionCurve realtime_curve;
  validation::CurveComparison cmp;
  validation::TrajectoryComparison trajectory;
  std::vector<validation::LayerAcceptance> acceptance;
  std::vector<validation::LayerDeflectionComparison> deflection;
};

Comparison compare_with_fem(const Scene& scene, const RealtimeRun& rt, const validation::FemResultFiles& fem) {
  using namespace validation;
  Comparison c;
  // The model's whole force (d h v included, as it renders) against the FEM's,
  // per layer on the insertion, then over the whole trajectory (dwell and
  // withdrawal) with the acceptance per layer.
  c.realtime_curve = curve_from_run(scene, rt.run, "realtime", /*include_damping=*/true);
  c.cmp = compare_curves(c.realtime_curve, fem.curve);
  const std::vector<LayerGeometry> geometry = layer_geometry(scene);
  c.trajectory = compare_trajectory(c.realtime_curve, fem.curve, reference_events(fem.curve, geometry), geometry);
  c.acceptance = layer_acceptance(geometry, c.trajectory);
  // Deflection before breakthrough and recovery after it, part of the acceptance.
  c.deflection.resize(scene.layers.size());
  std::vector<LayerDeflectionErrors> errors(scene.layers.size());
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    c.deflection[k] = compare_layer_deflection(scene, k, rt.run, rt.recorder, fem);
    errors[k] = {c.deflection[k].compared, c.deflection[k].recovery_compared, c.deflection[k].error.relative_rmse,
                 c.deflection[k].recovery_error.relative_rmse, "no FEM profile of this layer's top surface"};
  }
  add_deflection_acceptance(c.acceptance, errors);
  return c;
}

/// Step 6 (CSV and JSON): returns the per-layer metrics JSON.
nlohmann::json write_report_files(io::OutputSession& session, const Scene& scene, const std::string& scene_file,
                                  const validation::FemReference& reference, const validation::FemResultFiles& fem,
                                  const Comparison& c, const std::vector<validation::PunctureForceShares>& shares,
                                  const io::Provenance& provenance) {
  using namespace validation;
  session.write_text("realtime_curve.csv", insertion_curve_csv(c.realtime_curve, &provenance));
  // The FEM's own files, copied; a copy without provenance of its own gets
  // this command's (with the cache entry it came from).
  auto with_csv_provenance = [&](const std::string& name) {
    const std::string text = io::read_text_file(reference.dir / name);
    if (text.rfind("# command:", 0) == 0) return text;
    return io::provenance_comment_lines(provenance) + "# copied_from: " + (reference.dir / name).string() + "\n" + text;
  };
  session.write_text("fem_force_depth.csv", with_csv_provenance("fem_force_depth.csv"));
  session.write_text("fem_curve.csv", insertion_curve_csv(fem.curve, &provenance));
  session.write_text("force_depth_aligned.csv", aligned_curves_csv(c.realtime_curve, fem.curve, provenance));
  session.write_text("layer_metrics.csv", layer_metrics_csv(scene, c.cmp, c.deflection, provenance));
  session.write_text("deflection_profiles.csv", deflection_profiles_csv(scene, c.deflection, provenance));
  session.write_text("fem_recovery_profile.csv", with_csv_provenance("fem_recovery_profile.csv"));

  nlohmann::json metrics;
  metrics["provenance"] = io::provenance_json(provenance);
  metrics["scene"] = {{"name", scene.name}, {"file", scene_file}};
  metrics["fem_reference"] = {{"hash", reference.hash},
                              {"cache_dir", reference.dir.string()},
                              {"from_cache", reference.from_cache},
                              {"summary", fem.summary}};
  metrics["overall"] = {{"n_compared", c.cmp.n_compared},
                        {"reference_peak_force_N", c.cmp.reference_peak_force_N},
                        {"force_rmse_N", c.cmp.force_rmse_N},
                        {"force_rmse_relative", c.cmp.force_rmse_relative},
                        {"compared_from_depth_mm", c.cmp.compared_from_depth_m / kMm},
                        {"compared_to_depth_mm", c.cmp.compared_to_depth_m / kMm}};
  const nlohmann::json layers = layer_metrics_json(scene, c.cmp, c.deflection);
  metrics["layers"] = layers;
  metrics["acceptance"] = acceptance_json(c.acceptance);
  metrics["trajectory_terms"] = trajectory_terms_json(c.trajectory);
  metrics["puncture_force_shares"] = puncture_force_shares_json(shares);
  session.write_text("validation_metrics.json", metrics.dump(2) + "\n");
  return layers;
}

/// Steps 1-6 for one scene into `dir`. Returns nothing on the MPI ranks that
/// only help with the FEM.
std::optional<SceneValidation> validate_scene(const Scene& scene, const std::string& scene_file,
                                              const std::filesystem::path& dir, const std::string& command_line,
                                              const ValidateOptions& options, std::ostream& out, std::ostream& err) {
  using namespace validation;
  const bool vtk = writes_vtk(options);
  const io::Provenance provenance = io::make_provenance(command_line);
  auto progress = [&](const std::string& line) { out << "[validate] " << line << '\n' << std::flush; };
  progress("scene " + scene_file);

  // 1. FEM reference.
  FemReferenceOptions fem_options;
  if (!options.cache_dir.empty()) fem_options.cache_dir = options.cache_dir;
  fem_options.refinement = options.refinement;
  fem_options.degree = options.degree;
  fem_options.write_vtu = vtk;
  fem_options.verbose = !options.quiet;
  fem_options.on_step = options.fem_step;
  const FemReference reference = obtain_fem_reference(scene, fem_options, out);
  if (!is_mpi_root()) return std::nullopt;  // the other ranks only help with the FEM
  const FemResultFiles fem = read_fem_result(reference.dir, scene);

  // 2. Real-time model along the same trajectory.
  progress("real-time model: SH degree " + std::to_string(scene.realtime.sh_degree) + ", integrator " +
           scene.realtime.integrator);
  io::OutputSession session(dir);
  RealtimeModel model = build_realtime_model(scene);
  const RealtimeRun rt = run_realtime(model, scene, fem, vtk, provenance, session, options, out);

  const Comparison c = compare_with_fem(scene, rt, fem);
  const std::vector<PunctureForceShares> shares = puncture_force_shares(rt.run.events, &fem.curve);
  const nlohmann::json layers = write_report_files(session, scene, scene_file, reference, fem, c, shares, provenance);
  if (vtk) write_vtk_report(session, reference, fem, rt.frames, provenance);
  session.commit();
  progress("data written to " + dir.string());

  // PNG plots from the committed CSV files, then the summary that links them.
  const std::vector<std::string> plots = run_plot_script("plot_validation.py", dir, out, err);
  io::OutputSession summary_session(dir);
  summary_session.write_text(
      "validation_summary.md",
      validation_summary_markdown(scene, provenance, {reference.hash, reference.from_cache}, fem, c.cmp, layers, plots,
                                  vtk && !fem.frames.empty(),
                                  acceptance_markdown(c.acceptance, c.trajectory) +
                                      "\n## The real-time force at each puncture, by term\n\n"
                                      "Eq. 5 on the force mesh's own deflections; the mesh's "
                                      "inertia and damping (its reaction minus Eq. 5); the tip "
                                      "spring's stiffening; the cutting force of the crack above; the "
                                      "rest (shaft friction and d h v of the layers above). Shares of "
                                      "the force just before the break; the last column is Eq. 5's "
                                      "share of the layer's own pressing force (the first three "
                                      "terms: the forces of the layers above left out).\n\n" +
                                      puncture_force_shares_markdown(shares)));
  summary_session.commit();
  print_result(out, scene, reference, c.cmp, c.acceptance, layers, dir);
  return SceneValidation{c.acceptance, layers, trajectory_terms_json(c.trajectory)};
}

std::string vtk_flag(const ValidateOptions& options) { return writes_vtk(options) ? "" : " --no-vtk"; }

/// --cases: the model scene with each case's overrides, one report per case,
/// then the held-out summary. Every case is checked before the first FEM runs.
int validate_cases(const ValidateOptions& options, const std::filesystem::path& model_path, std::ostream& out,
                   std::ostream& err) {
  validation::ValidationCases cases;
  std::optional<validation::SlabRule> slab_rule;
  std::vector<validation::CaseScene> scenes;
  std::vector<validation::MissReason> reasons;
  const Scene model = load_scene(model_path);  // the model itself must be valid
  try {
    cases = validation::read_validation_cases(options.cases);
    if (!options.slab_rule.empty()) slab_rule = validation::read_slab_rule(options.slab_rule);
    if (!options.why_misses.empty()) {
      std::vector<std::string> layer_names;
      for (const Layer& l : model.layers) layer_names.push_back(l.name);
      reasons = validation::read_miss_reasons(options.why_misses, cases, layer_names);
    }
    const std::string model_text = io::read_text_file(model_path);
    for (const validation::ValidationCase& c : cases.cases)
      scenes.push_back(validation::case_scene(model_text, model_path.string(), c, slab_rule ? &*slab_rule : nullptr));
  } catch (const std::invalid_argument& e) {  // SceneError is a runtime_error: it passes through
    throw InputError(e.what());  // the cases file, or an override the model scene does not have
  }
  const std::filesystem::path dir =
      options.output_dir.empty() ? std::filesystem::path("out") / (model.name + "_cases") : options.output_dir;
  const std::string command_line = "puncture validate " + model_path.string() + " --cases " +
                                   options.cases.string() +
                                   (options.slab_rule.empty() ? "" : " --slab-rule " + options.slab_rule.string()) +
                                   (options.why_misses.empty() ? "" : " --why-misses " + options.why_misses.string()) +
                                   " -o " + dir.string() + vtk_flag(options);
  std::vector<validation::CaseOutcome> outcomes;
  for (std::size_t i = 0; i < cases.cases.size(); ++i) {
    const validation::ValidationCase& c = cases.cases[i];
    out << "[validate] case " << i + 1 << "/" << cases.cases.size() << ": " << c.name << '\n' << std::flush;
    const std::filesystem::path case_dir = dir / c.name;
    if (validation::is_mpi_root()) {
      io::OutputSession scene_session(case_dir);
      scene_session.write_text("scene.json", scenes[i].json_text);
      scene_session.commit();
    }
    const std::string scene_file = (case_dir / "scene.json").string();
    const auto result = validate_scene(scenes[i].scene, scene_file, case_dir, command_line, options, out, err);
    if (!result) continue;
    validation::ValidationCase shown = c;
    std::string rule_file;
    if (scenes[i].slab_rule_applied) {
      rule_file = options.slab_rule.string();
      shown.rule = validation::slab_rule_case_text(*slab_rule, rule_file, scenes[i].rule_notes);
    }
    outcomes.push_back({shown, scene_file, rule_file, result->acceptance, result->layers, result->trajectory_terms});
  }
  if (!validation::is_mpi_root()) return 0;
  const io::Provenance provenance = io::make_provenance(command_line);
  const nlohmann::json summary = validation::heldout_summary_json(
      outcomes, model_path.string(), options.model_note, options.cases.string(), io::provenance_json(provenance),
      reasons, options.why_misses.string());
  if (!options.why_misses.empty()) {  // the reasons must follow the results
    for (const nlohmann::json& c : summary["cases"])
      for (const nlohmann::json& l : c["layers"])
        if (!l["accepted"].get<bool>() && l["why"].is_null())
          err << "warning: " << options.why_misses.string() << ": no reason for case " << c["name"].get<std::string>()
              << ", layer " << l["layer"].get<std::string>() << ", which misses\n";
    for (const nlohmann::json& r : summary["stale_reasons"])
      err << "warning: " << options.why_misses.string() << ": case " << r["case"].get<std::string>() << ", layer "
          << r["layer"].get<std::string>() << " is accepted now: its reason is stale\n";
  }
  io::OutputSession session(dir);
  session.write_text("heldout_summary.json", summary.dump(2) + "\n");
  session.write_text("heldout_summary.md",
                     validation::heldout_summary_markdown(summary, command_line,
                                                          "git " + provenance.git_revision + ", " +
                                                              provenance.machine + ", " + provenance.date_utc));
  session.commit();
  out << "Held-out summary: " << (dir / "heldout_summary.md").string() << '\n';
  return 0;
}

}  // namespace

int validate_command(const ValidateOptions& options, std::ostream& stdout_stream, std::ostream& err) {
  NullStream quiet;
  std::ostream& out = options.quiet ? quiet : stdout_stream;
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  if (!options.references.empty())
    return report_errors(err, "", [&]() { return validate_recordings(options, scene_path, out); });
  if (!options.cases.empty())
    return report_errors(err, options.cases.string(), [&]() { return validate_cases(options, scene_path, out, err); });
  return report_errors(err, scene_path.string(), [&]() -> int {
    if (!options.slab_rule.empty())
      throw UsageError("--slab-rule applies to the cases that change the slab: it needs --cases");
    if (!options.why_misses.empty()) throw UsageError("--why-misses explains the misses of cases: it needs --cases");
    const Scene scene = load_scene(scene_path);
    require_axial_for_fem(scene, scene_path.string(), "the FEM reference");
    const std::filesystem::path dir =
        options.output_dir.empty() ? std::filesystem::path("out") / (scene.name + "_validation") : options.output_dir;
    const std::string command_line = "puncture validate " + scene_path.string() + " -o " + dir.string() + vtk_flag(options);
    validate_scene(scene, scene_path.string(), dir, command_line, options, out, err);
    return 0;
  });
}

}  // namespace puncture::apps
