// The steps of `puncture compare` before its tables (see comparison_runs.hpp).
#include "comparison_runs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include "comparison_tables.hpp"
#include "side_by_side.hpp"
#include "puncture/comparison/model_factory.hpp"
#include "puncture/comparison/sparse_spd_factor.hpp"
#include "puncture/needle.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/model_identification.hpp"
#include "puncture/validation/mass_spring_identification.hpp"

namespace puncture::validation::comparison_report_detail {

namespace {

constexpr double kMm = 1e-3;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Identifications run side by side (one per core of the reference machine).
constexpr int kIdentificationsAtOnce = 2;

bool has_column(const std::filesystem::path& csv, const std::string& column) {
  std::ifstream in(csv);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#') return ("," + line + ",").find("," + column + ",") != std::string::npos;
  return false;
}

/// The FEM's own row: its curve against itself, its wall time per load step.
void append_fem_row(const Scene& scene, const FemResultFiles& fem, ComparisonRows& rows) {
  ModelMetrics f;
  f.model = "fem";
  f.compared_samples = fem.curve.size();
  f.force_rmse_N = f.force_rmse_relative = f.peak_force_error_relative = 0.0;
  f.puncture_depth_error_m = 0.0;
  f.deflection_rmse_m = f.deflection_rmse_relative = 0.0;
  double peak = 0.0;
  for (std::size_t i = 0; i < fem.curve.size(); ++i)
    if (fem.curve.velocity_m_per_s[i] > 0.0) peak = std::max(peak, fem.curve.force_N[i]);
  f.model_peak_force_N = f.reference_peak_force_N = peak;
  for (const Layer& l : scene.layers) {
    LayerPunctureComparison p;
    p.layer = l.name;
    const PunctureEventMetrics e = puncture_event(fem.curve, l.name);
    p.reference_punctured = p.model_punctured = e.found;
    p.reference_depth_m = p.model_depth_m = e.found ? e.depth_m : kNaN;
    f.punctures.push_back(p);
  }
  const double wall = fem.summary.value("wall_time_s", kNaN);
  const double steps = fem.summary.value("load_steps", 0.0);
  f.step_time_mean_s = steps > 0 ? wall / steps : kNaN;
  f.step_time_p99_s = f.step_time_mean_s;  // the FEM records no per-step times
  f.step_time_max_s = kNaN;
  f.completed_fraction = fem.summary.value("status", std::string("ok")) == "failed" ? 0.5 : 1.0;
  f.dofs = fem.summary.value("n_dofs", 0L);
  rows.metrics.push_back(f);
  rows.runs.push_back(nullptr);
  rows.descriptions.push_back("deal.II finite-strain FEM reference (" + std::to_string(f.dofs) + " dofs, " +
                              std::to_string(fem.summary.value("n_ranks", 1)) + " rank(s)); time per load step of " +
                              fmt(scene.fem.load_step_m / kMm) + " mm");
}

}  // namespace

ComparisonReference read_comparison_reference(const Scene& scene, const std::filesystem::path& fem_dir) {
  ComparisonReference r;
  r.fem = read_fem_result(fem_dir, scene);
  r.data.curve = r.fem.curve;
  if (r.fem.profiles.count(scene.layers[0].name)) r.data.skin_profiles = r.fem.profiles.at(scene.layers[0].name);
  const std::filesystem::path fem_csv = fem_dir / "fem_force_depth.csv";
  r.data.has_shaft_forces = has_column(fem_csv, "friction_force_N") || has_column(fem_csv, "cutting_force_N");
  for (const RadialProfile& p : r.data.skin_profiles)
    if (p.depth_m > 0.0) r.profile_depths_m.push_back(p.depth_m);
  if (!r.data.skin_profiles.empty()) r.profile_radii_m = r.data.skin_profiles.front().r_m;
  return r;
}

ComparisonMesh build_comparison_mesh(const Scene& scene, const ComparisonReportOptions& options,
                                     io::OutputSession& session, std::ostream& out) {
  ComparisonMesh m;
  const bool needed = !options.identify.empty() ||
                      std::any_of(options.models.begin(), options.models.end(),
                                  [](const std::string& key) { return comparison::is_volumetric_model(key); });
  if (!needed) return m;
  if (!options.quiet)
    out << "[compare] tetrahedral mesh of the slab (" << scene.comparison.mesh.kind << ") ...\n" << std::flush;
  auto mesh = std::make_shared<meshing::TetMesh>(meshing::build_comparison_tet_mesh(scene, &m.report));
  if (!options.quiet)
    out << "[compare] mesh: " << m.report.vertices << " vertices, " << m.report.tetrahedra << " tetrahedra in "
        << shown(m.report.wall_time_s) << " s; " << meshing::describe(m.report.quality) << "\n";
  if (options.write_vtk) write_mesh_vtu(session, "mesh.vtu", *mesh);
  m.mesh = mesh;
  return m;
}

ComparisonRunner::ComparisonRunner(const Scene& scene, const ComparisonReportOptions& options,
                                   const ComparisonReference& reference,
                                   std::shared_ptr<const meshing::TetMesh> mesh, io::OutputSession& session,
                                   std::ostream& out, std::ostream& err)
    : scene_(scene), options_(options), reference_(reference), mesh_(std::move(mesh)), session_(session), out_(out),
      err_(err), discs_(scene) {
  const ScriptedTrajectory trajectory(scene.insertion);
  frame_interval_s_ = options.frames > 0 ? trajectory.duration() / options.frames : 0.0;
}

std::size_t ComparisonRunner::add_slot(const std::string& key, const Scene& model_scene,
                                      const std::string& factory_name) {
  const std::lock_guard<std::mutex> lock(mutex_);
  Slot slot;
  slot.first_part = next_part_;
  if (options_.write_vtk && frame_interval_s_ > 0.0)
    next_part_ += static_cast<int>(scene_.layers.size()) + (comparison::is_volumetric_model(factory_name) ? 1 : 0);
  slots_.push_back(slot);
  runs_.push_back(nullptr);
  if (key == factory_name) model_scenes_.insert_or_assign(key, model_scene);
  return runs_.size() - 1;
}

ModelRunOptions ComparisonRunner::run_options(const std::string& key, std::size_t slot, int& last_tenth) {
  ModelRunOptions o;
  o.profile_depths_m = reference_.profile_depths_m;
  o.profile_radii_m = reference_.profile_radii_m;
  o.measure_inversion = true;
  const double x_offset = 1.25 * scene_.sample.diameter_m * (static_cast<int>(slot) + 1);
  if (options_.write_vtk && frame_interval_s_ > 0.0) {
    o.frame_interval_s = frame_interval_s_;
    const int first_part = slots_[slot].first_part;
    o.on_frame = [this, key, x_offset, first_part](const comparison::ComparisonModel& m, double t, int frame) {
      char index[16];
      std::snprintf(index, sizeof index, "%04d", frame);
      const std::lock_guard<std::mutex> lock(mutex_);
      for (std::size_t k = 0; k < scene_.layers.size(); ++k) {
        const std::string name = "frames/" + key + "/" + scene_.layers[k].name + "_surface_" + index + ".vtp";
        discs_.write(session_, name, m, k, x_offset);
        pvd_.push_back({t, first_part + static_cast<int>(k), name});
      }
      if (m.has_volume()) {
        const std::string name = std::string("frames/") + key + "/volume_" + index + ".vtu";
        write_volume_frame(session_, name, m, x_offset);
        pvd_.push_back({t, first_part + static_cast<int>(scene_.layers.size()), name});
      }
    };
  }
  if (!options_.quiet || options_.check_interrupt)
    o.on_progress = [this, key, &last_tenth](double fraction) {
      if (options_.check_interrupt) options_.check_interrupt();
      if (options_.quiet) return;
      const int tenth = static_cast<int>(fraction * 10.0);
      if (tenth != last_tenth) {
        last_tenth = tenth;
        const std::lock_guard<std::mutex> lock(mutex_);
        out_ << "[compare] " << key << ": " << tenth * 10 << " %\n" << std::flush;
      }
    };
  return o;
}

void ComparisonRunner::run(const std::string& key, const Scene& model_scene, const std::string& factory_name) {
  run_in_slot(add_slot(key, model_scene, factory_name), key, model_scene, factory_name);
}

void ComparisonRunner::run_in_slot(std::size_t slot, const std::string& key, const Scene& model_scene,
                                   const std::string& factory_name) {
  const auto build_start = std::chrono::steady_clock::now();
  if (!options_.quiet) {
    const std::lock_guard<std::mutex> lock(mutex_);
    out_ << "[compare] " << key << ": building ...\n" << std::flush;
  }
  std::unique_ptr<comparison::ComparisonModel> model = comparison::make_comparison_model(
      factory_name, model_scene, comparison::is_volumetric_model(factory_name) ? mesh_ : nullptr);
  const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();
  int last_tenth = -1;
  const ModelRunOptions options = run_options(key, slot, last_tenth);
  auto run = std::make_unique<ModelRun>(run_comparison_model(*model, model_scene, options));
  run->model = key;
  run->build_wall_time_s = build_s;
  const std::lock_guard<std::mutex> lock(mutex_);
  if (run->failed()) err_ << "warning: " << key << " failed " << run->failure << "\n";
  if (!options_.quiet)
    out_ << "[compare] " << key << ": " << run->steps() << " steps in " << shown(run->run_wall_time_s) << " s"
         << (run->integrator_report.empty() ? "" : "; " + run->integrator_report) << "\n";
  session_.write_text("curves/" + key + ".csv", curve_csv(model_scene, *run, reference_.data.has_shaft_forces));
  runs_[slot] = std::move(run);
}

nlohmann::json ComparisonRunner::identify(const std::string& method) {
  IdentificationOptions id_options;
  id_options.method = method;
  id_options.max_evaluations = options_.identify_evaluations;
  if (!options_.quiet) out_ << "[compare] identifying the mass-spring stiffnesses by " << method << " ...\n" << std::flush;
  // From the msm row's scene (its identified moduli and critical forces) when it was run.
  const auto msm = model_scenes_.find("msm");
  const Scene& base = msm != model_scenes_.end() ? msm->second : scene_;
  const IdentificationResult r = identify_mass_spring_stiffness(
      base, mesh_, reference_.data, id_options, [&](int evaluation, double objective, double best) {
        if (options_.check_interrupt) options_.check_interrupt();
        if (!options_.quiet)
          out_ << "[identify " << method << "] evaluation " << evaluation << ": objective " << shown(objective, 4)
               << " (best " << shown(best, 4) << ")\n" << std::flush;
      });
  nlohmann::json record = identification_record(method, r, id_options.step_m);
  Scene identified = base;
  identified.comparison.mass_spring_stiffness_scale = r.scale_after;
  run(std::string("msm_") + (method == "isres" ? "isres" : "sa"), identified, "msm");
  return record;
}

Scene ComparisonRunner::identify_model(const std::string& key) {
  if (!options_.quiet) {
    const std::lock_guard<std::mutex> lock(mutex_);
    out_ << "[compare] " << key << ": identifying against the FEM ...\n" << std::flush;
  }
  const ModelIdentification id = identify_comparison_model(
      key, scene_, comparison::is_volumetric_model(key) ? mesh_ : nullptr, reference_.data,
      options_.identify_stiffness, [&](const std::string& line) {
        if (options_.check_interrupt) options_.check_interrupt();
        if (options_.quiet) return;
        const std::lock_guard<std::mutex> lock(mutex_);
        out_ << "[compare] " << key << ": " << line << "\n" << std::flush;
      });
  nlohmann::json layers = nlohmann::json::array();
  for (const LayerIdentification& l : id.layers) {
    nlohmann::json j = {{"layer", l.layer}, {"identified", l.identified}};
    if (std::isfinite(l.reference_depth_m)) j["reference_depth_mm"] = l.reference_depth_m / kMm;
    if (l.identified) {
      j["stiffness_scale"] = l.stiffness_scale;
      if (l.stiffness_scale_near_bound())  // the bound it is near
        j["stiffness_scale_near_bound"] = l.stiffness_scale > 1.0 ? kStiffnessScaleBound : 1.0 / kStiffnessScaleBound;
      j["critical_force_N"] = l.critical_force_N;
      j["window_samples"] = l.window_samples;
      if (std::isfinite(l.window_rmse_before_N)) j["window_rmse_before_N"] = l.window_rmse_before_N;
      if (std::isfinite(l.window_rmse_after_N)) j["window_rmse_after_N"] = l.window_rmse_after_N;
    }
    if (!l.note.empty()) j["note"] = l.note;
    layers.push_back(j);
  }
  nlohmann::json record = {{"layers", layers},
                           {"stiffness_identified", id.stiffness_identified},
                           {"model_runs", id.model_runs},
                           {"wall_time_s", id.wall_time_s}};
  if (!id.joint_note.empty()) record["joint_fit"] = id.joint_note;
  Scene identified = with_identified_parameters(scene_, id);
  identified.name = scene_.name + "_" + key + "_identified";
  identified.description = "The scene of `puncture compare` with model " + key +
                           "'s layer stiffness factors and critical contact forces identified against the FEM "
                           "reference on this scene's trajectory (model_identification.hpp).";
  const std::lock_guard<std::mutex> lock(mutex_);
  identification_records_[key] = std::move(record);
  session_.write_text("identified/" + key + ".json", scene_to_json_text(identified));
  return identified;
}

std::map<std::string, Scene> ComparisonRunner::identify_models(const std::vector<std::string>& keys,
                                                               double& wall_time_s) {
  const auto start = std::chrono::steady_clock::now();
  // The volumetric models first: they take nearly all the time, so they
  // start together and the cheap ones fill in beside the longer one.
  std::vector<std::string> order;
  for (const std::string& key : keys)
    if (comparison::is_volumetric_model(key)) order.push_back(key);
  for (const std::string& key : keys)
    if (!comparison::is_volumetric_model(key)) order.push_back(key);
  std::map<std::string, Scene> identified;
  run_side_by_side(order.size(), comparison::concurrent_solver_threads(kIdentificationsAtOnce), [&](std::size_t i) {
    Scene s = identify_model(order[i]);  // an exception (e.g. an interrupt): the others stop at their next check
    const std::lock_guard<std::mutex> lock(mutex_);
    identified.insert_or_assign(order[i], std::move(s));
  });
  wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return identified;
}

std::size_t trajectory_steps(const Scene& scene) {
  const ScriptedTrajectory trajectory(scene.insertion);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  return static_cast<std::size_t>(std::ceil(trajectory.duration() / dt - 1e-9)) + 1;
}

ComparisonRows comparison_rows(const Scene& scene, const std::vector<std::unique_ptr<ModelRun>>& runs,
                               const ComparisonReference& reference, bool with_fem_row) {
  const std::size_t total_steps = trajectory_steps(scene);
  ComparisonRows rows;
  for (const auto& run : runs) {
    rows.metrics.push_back(metrics_against_reference(scene, *run, reference.data, total_steps));
    rows.runs.push_back(run.get());
    rows.descriptions.push_back(run->description);
  }
  if (with_fem_row) append_fem_row(scene, reference.fem, rows);
  return rows;
}

}  // namespace puncture::validation::comparison_report_detail
