// `puncture run`: the real-time SHF + MSM model along a scene's scripted
// insertion, with CSV, JSON summary, SH fit-error table and ParaView frames.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "command_errors.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/io/csv_writer.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/io/provenance_json.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/scene_limits.hpp"
#include "puncture/validation/plausibility.hpp"
#ifdef PUNCTURE_HAVE_VTK  // frames are VTK files
#include "puncture/vtk_io/realtime_frames.hpp"
#endif

namespace puncture::apps {

std::filesystem::path default_scene_path() {
  const std::filesystem::path local = "scenes/default.json";
  if (std::filesystem::exists(local)) return local;
  return std::filesystem::path(PUNCTURE_SOURCE_DIR) / "scenes" / "default.json";
}

namespace {

constexpr double kMm = 1e-3;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

/// realtime_curve.csv: one row per kept haptic tick (every tick unless the
/// run is longer than scene_limits::kMaxCurveRows ticks): force along the
/// needle, its parts (tip, cutting, friction), the phase, the depth along the
/// needle, the force across it, the force vector on the needle (scene frame)
/// and its moment about the entry point, and per layer its state and forces.
std::string curve_csv(const Scene& scene, const ScriptedRunResult& run, const std::vector<std::size_t>& kept,
                      std::size_t stride, const io::Provenance& provenance) {
  std::vector<std::string> columns{"time_s",      "depth_mm",        "velocity_mm_per_s", "force_N",
                                   "tip_force_N", "cutting_force_N", "friction_force_N",  "phase",
                                   // The needle at an angle (needle.hpp): the force as a vector and its moment.
                                   "path_depth_mm", "lateral_force_N", "force_x_N", "force_y_N", "force_z_N",
                                   "torque_x_N_m", "torque_y_N_m", "torque_z_N_m"};
  for (const Layer& l : scene.layers)
    for (const char* c : {"_state", "_surface_force_N", "_cutting_force_N", "_friction_force_N", "_damping_force_N",
                          "_deformed_rings"})
      columns.push_back(l.name + c);
  io::CsvWriter csv(columns);
  csv.add_provenance(provenance);
  if (stride > 1)
    csv.add_metadata("decimation", "every " + std::to_string(stride) + "-th of " + std::to_string(run.ticks.size()) +
                                       " ticks, plus every tick at which a layer changes state");
  const ScriptedTrajectory trajectory(scene.insertion);
  for (std::size_t i : kept) {
    const TickResult& t = run.ticks[i];
    const char* phase = t.time_s < trajectory.insertion_end_s()      ? "insertion"
                        : t.time_s < trajectory.withdrawal_start_s() ? "dwell"
                                                                     : "withdrawal";
    csv.number(t.time_s).number(t.depth_m / kMm).number(t.velocity_m_per_s / kMm).number(t.total_force_N);
    csv.number(t.tip_force_N).number(t.cutting_force_N).number(t.friction_force_N).text(phase);
    csv.number(t.path_depth_m / kMm).number(t.lateral_force_N);
    for (int i = 0; i < 3; ++i) csv.number(t.force_on_needle_N[i]);
    for (int i = 0; i < 3; ++i) csv.number(t.torque_about_entry_N_m[i]);
    for (const LayerTickResult& l : t.layers)
      csv.text(to_string(l.state))
          .number(l.surface_force_N)
          .number(l.cutting_force_N)
          .number(l.friction_force_N)
          .number(l.damping_force_N)
          .integer(l.deformed_rings);
    csv.end_row();
  }
  return csv.str();
}

/// sh_fit_error.csv: the SH degree accuracy knob, per layer.
std::string fit_error_csv(const std::vector<LayerFitErrorEntry>& rows, const io::Provenance& provenance) {
  io::CsvWriter csv({"layer", "degree", "top_face_max_error_mm", "top_face_rms_error_mm", "whole_surface_rms_error_mm",
                     "condition_number"});
  csv.add_provenance(provenance);
  for (const auto& e : rows)
    csv.text(e.layer).integer(e.row.degree).number(e.row.top_face_max_error_m / kMm, 6)
        .number(e.row.top_face_rms_error_m / kMm, 6).number(e.row.whole_surface_rms_error_m / kMm, 6)
        .number(e.row.condition_number, 6).end_row();
  return csv.str();
}

nlohmann::json summary_json(const Scene& scene, const RealtimeModel& model, const ScriptedRunResult& run,
                            const io::Provenance& provenance, const std::vector<std::string>& warnings,
                            std::size_t curve_rows, std::size_t stride) {
  nlohmann::json j;
  j["provenance"] = io::provenance_json(provenance);
  j["warnings"] = warnings;
  j["realtime_curve"] = {{"ticks", run.ticks.size()}, {"rows", curve_rows}, {"decimation_stride", stride}};
  j["scene"] = {{"name", scene.name}, {"file", scene.source_path}};
  j["settings"] = nlohmann::json::parse(scene_to_json_text(scene));
  nlohmann::json events = nlohmann::json::array();
  for (const PunctureEvent& e : run.events)
    events.push_back({{"layer", std::string(e.layer_name)},
                      {"time_s", e.time_s},
                      {"depth_mm", e.depth_m / kMm},
                      {"surface_force_N", e.surface_force_N},
                      {"total_force_N", e.total_force_N}});
  j["puncture_events"] = events;
  double peak = 0.0, peak_depth = 0.0;
  std::vector<double> layer_peak(scene.layers.size(), 0.0);
  for (const TickResult& t : run.ticks) {
    if (std::abs(t.total_force_N) > std::abs(peak)) peak = t.total_force_N, peak_depth = t.depth_m;
    for (std::size_t k = 0; k < t.layers.size(); ++k)
      layer_peak[k] = std::max(layer_peak[k], t.layers[k].surface_force_N);
  }
  j["peak_force_N"] = peak;
  j["peak_force_depth_mm"] = peak_depth / kMm;
  nlohmann::json layers = nlohmann::json::array();
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const LayerSurfaceFitInfo& f = model.fits[k];
    layers.push_back({{"name", scene.layers[k].name},
                      {"peak_surface_force_N", layer_peak[k]},
                      {"final_state", to_string(run.ticks.empty() ? LayerState::Untouched : run.ticks.back().layers[k].state)},
                      {"sh_degree", f.degree},
                      {"sh_top_face_max_error_mm", f.top_face_max_error_m / kMm},
                      {"sh_fit_condition_number", f.report.condition_number}});
  }
  j["layers"] = layers;
  std::vector<double> us(run.tick_wall_time_s.size());
  std::transform(run.tick_wall_time_s.begin(), run.tick_wall_time_s.end(), us.begin(), [](double s) { return s * 1e6; });
  const TickCost cost = tick_cost(run);
  auto or_null = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  j["tick_timing_us"] = {
      {"contact_mean", or_null(cost.contact_mean_s * 1e6)},
      {"contact_p99", or_null(cost.contact_p99_s * 1e6)},
      {"contact_ticks", cost.contact_ticks},
      {"all_median", median(us)},
      {"all_p99", quantile(us, 0.99)},
      {"ticks", us.size()},
      {"note", "wall time of tick() measured inside this run. The cost is where the work is: mean and p99 over the "
               "ticks with contact (tip below the skin surface or a layer pressed); the median over all ticks is a "
               "tick without contact. See results/benchmarks for the benchmarks."}};
  j["time_step_s"] = run.time_step_s;
  return j;
}

}  // namespace

int run_command(const RunOptions& options, std::ostream& stdout_stream, std::ostream& err) {
  NullStream quiet;
  std::ostream& out = options.quiet ? quiet : stdout_stream;
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  return report_errors(err, scene_path.string(), [&]() -> int {
    const Scene scene = load_scene(scene_path);
    const std::filesystem::path dir =
        options.output_dir.empty() ? std::filesystem::path("out") / scene.name : options.output_dir;
    out << "[run] scene " << scene_path.string() << " (" << scene.layers.size() << " layers, SH degree "
        << scene.realtime.sh_degree << ", integrator " << scene.realtime.integrator << ")\n";
    const std::string command_line = "puncture run " + scene_path.string() + " -o " + dir.string() +
                                     (options.write_frames ? "" : " --no-frames");
    const io::Provenance provenance = io::make_provenance(command_line);

    RealtimeModel model = build_realtime_model(scene);
    io::OutputSession session(dir);

    std::vector<int> degrees{4, 8, 12, 16, 24, 32};
    if (std::find(degrees.begin(), degrees.end(), scene.realtime.sh_degree) == degrees.end())
      degrees.push_back(scene.realtime.sh_degree);
    std::sort(degrees.begin(), degrees.end());
    session.write_text("sh_fit_error.csv", fit_error_csv(scene_fit_error_sweep(scene, degrees), provenance));

    FrameCallback on_frame;
#ifdef PUNCTURE_HAVE_VTK
    const bool frames = options.write_frames && scene.effects.surface_output;
    std::optional<io::FrameWriter> writer;
    if (frames) {
      io::FrameWriterOptions frame_options;
      frame_options.provenance = &provenance;
      writer.emplace(session, model, scene, frame_options);
    }
    if (writer) on_frame = [&](const PunctureSimulator& sim, const TickResult& t, int f) { writer->write(sim, t, f); };
#else
    if (options.write_frames && scene.effects.surface_output)
      err << "warning: this build has no VTK (PUNCTURE_WITH_VTK=OFF): no surface frames are written\n";
#endif
    ProgressCallback on_progress;
    if (!options.quiet)
      on_progress = [&](double f) { out << "[run] " << std::setw(3) << static_cast<int>(std::lround(100 * f)) << " %\n" << std::flush; };

    const ScriptedRunResult run = run_scripted_insertion(model, scene, on_frame, on_progress);
#ifdef PUNCTURE_HAVE_VTK
    if (writer) writer->finish();
#endif

    std::vector<std::string> warnings = validation::plausibility_warnings(scene, run);
    std::size_t stride = 1;
    const std::vector<std::size_t> kept =
        validation::decimated_tick_indices(run, scene_limits::kMaxCurveRows, stride);
    if (stride > 1)
      warnings.push_back("realtime_curve.csv: " + std::to_string(run.ticks.size()) + " ticks are more than " +
                         std::to_string(scene_limits::kMaxCurveRows) + " rows; written every " +
                         std::to_string(stride) + "-th tick plus every tick at which a layer changes state (" +
                         std::to_string(kept.size()) + " rows)");
    for (const std::string& w : warnings) err << "warning: " << w << '\n';

    session.write_text("realtime_curve.csv", curve_csv(scene, run, kept, stride, provenance));
    session.write_text("summary.json",
                       summary_json(scene, model, run, provenance, warnings, kept.size(), stride).dump(2) + "\n");
    session.commit();

    out << "\nPuncture events (" << run.events.size() << "):\n";
    for (const PunctureEvent& e : run.events)
      out << "  " << std::left << std::setw(8) << e.layer_name << std::right << " t = " << std::fixed
          << std::setprecision(3) << e.time_s << " s   depth = " << std::setprecision(2) << e.depth_m / kMm
          << " mm   surface force = " << std::setprecision(3) << e.surface_force_N << " N   needle force = "
          << e.total_force_N << " N\n";
    out.unsetf(std::ios::floatfield);
    out << "\nOutputs in " << dir.string() << "/:\n"
        << "  realtime_curve.csv  force, depth, per-layer states and forces per haptic tick\n"
        << "  summary.json        puncture events, peak forces, SH fit, tick timing, settings, warnings\n"
        << "  sh_fit_error.csv    SH surface fit error versus degree l\n";
#ifdef PUNCTURE_HAVE_VTK
    if (writer)
      out << "  realtime.pvd        " << writer->frames() << " frames of layer surfaces and force meshes (open in ParaView)\n";
#endif
    return 0;
  });
}

}  // namespace puncture::apps
