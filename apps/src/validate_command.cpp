// `puncture validate`: the real-time model and the FEM reference (cached) on
// the identical insertion (same scene, same trajectory), aligned on depth.
//
// Algorithm (top-down):
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
#include "run_outputs.hpp"
#include "puncture/validation/fem_comparison.hpp"
#include "puncture/validation/puncture_force_shares.hpp"
#include "puncture/validation/number_format.hpp"

namespace puncture::apps {

namespace {

constexpr double kMm = 1e-3;

std::string fmt(double x, int precision = 10) {
  if (!std::isfinite(x)) return "nan";
  return validation::significant_digits(x, precision);
}

}  // namespace

int validate_command(const ValidateOptions& options, std::ostream& stdout_stream, std::ostream& err) {
  using namespace validation;
  NullStream quiet;
  std::ostream& out = options.quiet ? quiet : stdout_stream;
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  return report_errors(err, scene_path.string(), [&]() -> int {
    const Scene scene = load_scene(scene_path);
    const std::filesystem::path dir =
        options.output_dir.empty() ? std::filesystem::path("out") / (scene.name + "_validation") : options.output_dir;
#ifdef PUNCTURE_HAVE_VTK
    const bool vtk = options.write_vtk;
#else
    const bool vtk = false;  // this build has no VTK: CSV, PNG and markdown only
#endif
    const std::string command_line = "puncture validate " + scene_path.string() + " -o " + dir.string() +
                                     (vtk ? "" : " --no-vtk");
    const io::Provenance provenance = io::make_provenance(command_line);
    auto progress = [&](const std::string& line) {
      out << "[validate] " << line << '\n' << std::flush;
    };
    progress("scene " + scene_path.string());

    // 1. FEM reference.
    validation::FemReferenceOptions fem_options;
    if (!options.cache_dir.empty()) fem_options.cache_dir = options.cache_dir;
    fem_options.refinement = options.refinement;
    fem_options.degree = options.degree;
    fem_options.write_vtu = vtk;
    fem_options.verbose = !options.quiet;
    const validation::FemReference reference = validation::obtain_fem_reference(scene, fem_options, out);
    if (!validation::is_mpi_root()) return 0;  // the other ranks only help with the FEM
    const FemResultFiles fem = read_fem_result(reference.dir, scene);

    // 2. Real-time model along the same trajectory.
    progress("real-time model: SH degree " + std::to_string(scene.realtime.sh_degree) + ", integrator " +
             scene.realtime.integrator);
    RealtimeModel model = build_realtime_model(scene);
    io::OutputSession session(dir);
    std::vector<double> frame_times = vtk ? fem.frame_times_s : std::vector<double>{};
#ifdef PUNCTURE_HAVE_VTK
    std::optional<FrameWriter> writer;
    if (!frame_times.empty()) {
      FrameWriterOptions fw;
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
#endif
    RingRecorder recorder(scene);
    std::size_t next_frame = 0;
    const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
    Scene every_tick = scene;  // on_frame every tick: the recorder sees every state
    every_tick.realtime.frame_rate_Hz = scene.realtime.haptic_rate_Hz;
    FrameCallback on_tick = [&](const PunctureSimulator& sim, const TickResult& t, int) {
      recorder.record(sim);
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
    const ScriptedRunResult run = run_scripted_insertion(model, every_tick, on_tick, on_progress);

    // 3. Force-depth metrics: the model's whole force (d h v included, as it
    // renders) against the FEM's, per layer on the insertion, then over the
    // whole trajectory (dwell and withdrawal) with the acceptance per layer.
    const validation::InsertionCurve realtime_curve =
        validation::curve_from_run(scene, run, "realtime", /*include_damping=*/true);
    const validation::CurveComparison cmp = validation::compare_curves(realtime_curve, fem.curve);
    const std::vector<validation::LayerGeometry> geometry = validation::layer_geometry(scene);
    const validation::ReferenceEvents fem_events = validation::reference_events(fem.curve, geometry);
    const validation::TrajectoryComparison trajectory =
        validation::compare_trajectory(realtime_curve, fem.curve, fem_events, geometry);
    std::vector<validation::LayerAcceptance> acceptance = validation::layer_acceptance(geometry, trajectory);

    // 4-5. Deflection before breakthrough and recovery after it, part of the acceptance.
    std::vector<LayerDeflectionComparison> defl(scene.layers.size());
    std::vector<validation::LayerDeflectionErrors> deflection_errors(scene.layers.size());
    for (std::size_t k = 0; k < scene.layers.size(); ++k) {
      defl[k] = compare_layer_deflection(scene, k, run, recorder, fem);
      deflection_errors[k] = {defl[k].compared, defl[k].recovery_compared, defl[k].error.relative_rmse,
                              defl[k].recovery_error.relative_rmse, "no FEM profile of this layer's top surface"};
    }
    validation::add_deflection_acceptance(acceptance, deflection_errors);

    // 6. Report files.
    session.write_text("realtime_curve.csv", insertion_curve_csv(realtime_curve, &provenance));
    // The FEM's own files, copied; a copy without provenance of its own gets
    // this command's (with the cache entry it came from).
    auto with_csv_provenance = [&](const std::string& name) {
      const std::string text = io::read_text_file(reference.dir / name);
      if (text.rfind("# command:", 0) == 0) return text;
      return io::provenance_comment_lines(provenance) + "# copied_from: " + (reference.dir / name).string() + "\n" +
             text;
    };
    session.write_text("fem_force_depth.csv", with_csv_provenance("fem_force_depth.csv"));
    session.write_text("fem_curve.csv", insertion_curve_csv(fem.curve, &provenance));
    session.write_text("force_depth_aligned.csv", aligned_curves_csv(realtime_curve, fem.curve, provenance));
    session.write_text("layer_metrics.csv", layer_metrics_csv(scene, cmp, defl, provenance));
    session.write_text("deflection_profiles.csv", deflection_profiles_csv(scene, defl, provenance));
    session.write_text("fem_recovery_profile.csv", with_csv_provenance("fem_recovery_profile.csv"));

    nlohmann::json metrics;
    metrics["provenance"] = io::provenance_json(provenance);
    metrics["scene"] = {{"name", scene.name}, {"file", scene_path.string()}};
    metrics["fem_reference"] = {{"hash", reference.hash},
                                {"cache_dir", reference.dir.string()},
                                {"from_cache", reference.from_cache},
                                {"summary", fem.summary}};
    metrics["overall"] = {{"n_compared", cmp.n_compared},
                          {"reference_peak_force_N", cmp.reference_peak_force_N},
                          {"force_rmse_N", cmp.force_rmse_N},
                          {"force_rmse_relative", cmp.force_rmse_relative},
                          {"compared_from_depth_mm", cmp.compared_from_depth_m / kMm},
                          {"compared_to_depth_mm", cmp.compared_to_depth_m / kMm}};
    const nlohmann::json layers = layer_metrics_json(scene, cmp, defl);
    metrics["layers"] = layers;
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
    metrics["acceptance"] = acc;
    nlohmann::json terms = nlohmann::json::array();
    for (const auto& t : trajectory.terms) {
      nlohmann::json j = {{"term", t.name}, {"layer", t.layer}, {"available", t.available},
                          {"samples", t.samples}, {"note", t.note}};
      if (t.available) j["value"] = t.value, j["error"] = t.raw;
      terms.push_back(j);
    }
    metrics["trajectory_terms"] = terms;
    const std::vector<validation::PunctureForceShares> shares = validation::puncture_force_shares(run.events);
    metrics["puncture_force_shares"] = validation::puncture_force_shares_json(shares);
    session.write_text("validation_metrics.json", metrics.dump(2) + "\n");

    if (vtk) {
      std::vector<io::PvdEntry> entries;
      for (const FemFrame& f : fem.frames) {
        for (const std::string& file : f.files)
        {
          // Copies of FEM frames without provenance of their own get this
          // command's: field data in a .vtu, a comment in a .pvtu.
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
#ifdef PUNCTURE_HAVE_VTK
      if (writer)
        for (const io::PvdEntry& e : writer->entries()) entries.push_back(e);
#endif
      if (!entries.empty()) io::write_pvd(session, "validation.pvd", entries, &provenance);
    }
    session.commit();
    progress("data written to " + dir.string());

    // PNG plots from the committed CSV files, then the summary that links them.
    const std::vector<std::string> plots = run_plot_script("plot_validation.py", dir, out, err);
    io::OutputSession summary_session(dir);
    summary_session.write_text("validation_summary.md",
                               validation_summary_markdown(scene, provenance, {reference.hash, reference.from_cache},
                                                           fem, cmp, layers, plots, vtk && !fem.frames.empty(),
                                                           validation::acceptance_markdown(acceptance, trajectory) +
                                                               "\n## The real-time force at each puncture, by term\n\n"
                                                               "Eq. 5 on the force mesh's own deflections; the mesh's "
                                                               "inertia and damping (its reaction minus Eq. 5); the tip "
                                                               "spring's stiffening; the rest (shaft friction and d h v of "
                                                               "the layers above). Shares of the force just before the "
                                                               "break.\n\n" +
                                                               validation::puncture_force_shares_markdown(shares)));
    summary_session.commit();

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
    return 0;
  });
}

}  // namespace puncture::apps
