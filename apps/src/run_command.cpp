// `puncture run`: the real-time SHF + MSM model along a scene's scripted
// insertion, with CSV, JSON summary, SH fit-error table and ParaView frames.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "command_errors.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/apps/provenance.hpp"
#include "run_outputs.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/io/pvd.hpp"
#include "puncture/io/vtk_polydata.hpp"
#include "puncture/model/force_mesh_field.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"

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

std::string fmt(double x, int precision = 17) {
  std::ostringstream s;
  s << std::setprecision(precision) << x;
  return s.str();
}

/// realtime_curve.csv: one row per haptic tick.
std::string curve_csv(const Scene& scene, const ScriptedRunResult& run) {
  std::ostringstream csv;
  csv << "time_s,depth_mm,velocity_mm_per_s,force_N,tip_force_N,cutting_force_N,friction_force_N,phase";
  for (const Layer& l : scene.layers)
    csv << ',' << l.name << "_state," << l.name << "_surface_force_N," << l.name << "_cutting_force_N," << l.name
        << "_friction_force_N," << l.name << "_damping_force_N," << l.name << "_deformed_rings";
  csv << '\n';
  const ScriptedTrajectory trajectory(scene.insertion);
  for (const TickResult& t : run.ticks) {
    const char* phase = t.time_s < trajectory.insertion_end_s()      ? "insertion"
                        : t.time_s < trajectory.withdrawal_start_s() ? "dwell"
                                                                     : "withdrawal";
    csv << fmt(t.time_s) << ',' << fmt(t.depth_m / kMm) << ',' << fmt(t.velocity_m_per_s / kMm) << ','
        << fmt(t.total_force_N) << ',' << fmt(t.tip_force_N) << ',' << fmt(t.cutting_force_N) << ','
        << fmt(t.friction_force_N) << ',' << phase;
    for (const LayerTickResult& l : t.layers)
      csv << ',' << to_string(l.state) << ',' << fmt(l.surface_force_N) << ',' << fmt(l.cutting_force_N) << ','
          << fmt(l.friction_force_N) << ',' << fmt(l.damping_force_N) << ',' << l.deformed_rings;
    csv << '\n';
  }
  return csv.str();
}

/// sh_fit_error.csv: the SH degree accuracy knob, per layer.
std::string fit_error_csv(const std::vector<LayerFitErrorEntry>& rows) {
  std::ostringstream csv;
  csv << "layer,degree,top_face_max_error_mm,top_face_rms_error_mm,whole_surface_rms_error_mm,condition_number\n";
  for (const auto& e : rows)
    csv << e.layer << ',' << e.row.degree << ',' << fmt(e.row.top_face_max_error_m / kMm, 6) << ','
        << fmt(e.row.top_face_rms_error_m / kMm, 6) << ',' << fmt(e.row.whole_surface_rms_error_m / kMm, 6) << ','
        << fmt(e.row.condition_number, 6) << '\n';
  return csv.str();
}

nlohmann::json summary_json(const Scene& scene, const RealtimeModel& model, const ScriptedRunResult& run,
                            const std::string& command_line) {
  nlohmann::json j;
  j["provenance"] = provenance_json(command_line);
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

int run_command(const RunOptions& options, std::ostream& out, std::ostream& err) {
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  return report_errors(err, scene_path.string(), [&]() -> int {
    const Scene scene = load_scene(scene_path);
    const std::filesystem::path dir =
        options.output_dir.empty() ? std::filesystem::path("out") / scene.name : options.output_dir;
    if (!options.quiet) out << "[run] scene " << scene_path.string() << " (" << scene.layers.size() << " layers, SH degree "
                            << scene.realtime.sh_degree << ", integrator " << scene.realtime.integrator << ")\n";

    RealtimeModel model = build_realtime_model(scene);
    io::OutputSession session(dir);

    std::vector<int> degrees{4, 8, 12, 16, 24, 32};
    if (std::find(degrees.begin(), degrees.end(), scene.realtime.sh_degree) == degrees.end())
      degrees.push_back(scene.realtime.sh_degree);
    std::sort(degrees.begin(), degrees.end());
    session.write_text("sh_fit_error.csv", fit_error_csv(scene_fit_error_sweep(scene, degrees)));

    const bool frames = options.write_frames && scene.effects.surface_output;
    std::optional<FrameWriter> writer;
    if (frames) writer.emplace(session, model, scene);
    FrameCallback on_frame;
    if (writer) on_frame = [&](const PunctureSimulator& sim, const TickResult& t, int f) { writer->write(sim, t, f); };
    ProgressCallback on_progress;
    if (!options.quiet)
      on_progress = [&](double f) { out << "[run] " << std::setw(3) << static_cast<int>(std::lround(100 * f)) << " %\n" << std::flush; };

    const ScriptedRunResult run = run_scripted_insertion(model, scene, on_frame, on_progress);
    if (writer) writer->finish();

    session.write_text("realtime_curve.csv", curve_csv(scene, run));
    const std::string command_line = "puncture run " + scene_path.string() + " -o " + dir.string();
    session.write_text("summary.json", summary_json(scene, model, run, command_line).dump(2) + "\n");
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
        << "  summary.json        puncture events, peak forces, SH fit, tick timing, settings\n"
        << "  sh_fit_error.csv    SH surface fit error versus degree l\n";
    if (writer)
      out << "  realtime.pvd        " << writer->frames() << " frames of layer surfaces and force meshes (open in ParaView)\n";
    return 0;
  });
}

}  // namespace puncture::apps
