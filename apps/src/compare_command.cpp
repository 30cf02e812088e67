// `puncture compare`: the comparison models of both seed papers and the
// real-time model on the identical insertion (same scene: slab, needle,
// trajectory), measured against the FEM reference (cached), graded by the
// paper's Sec. 3.3 method.
//
// Algorithm (top-down):
//   1. load the scene and the Delphi weights file; obtain the FEM reference
//      (cache or solve; MPI ranks other than 0 stop after it);
//   2. if a volumetric model is asked for: the CGAL tetrahedral mesh (mesh.vtu,
//      quality in the summary);
//   3. every model: build, run the scripted insertion one haptic step at a time
//      (validation/comparison), timing each step; per-model curve CSV; skin
//      deflection at the FEM's recorded depths; ParaView frames;
//   4. optional mass-spring identification (simulated annealing, ISRES): the
//      identified layer factors are run as extra rows msm_<method>;
//   5. metrics against the FEM (comparison.csv), the weighted grading
//      (ranking.csv, ranking.md), comparison.pvd, plots, comparison.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "command_errors.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/validation/fem_reference.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/io/provenance_json.hpp"
#include "puncture/validation/fem_comparison.hpp"
#include "puncture/comparison/model_factory.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/io/pvd.hpp"
#include "puncture/io/vtk_polydata.hpp"
#include "puncture/io/vtk_unstructured.hpp"
#include "puncture/meshing/tet_slab_mesh.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/comparison_grading.hpp"
#include "puncture/validation/mass_spring_identification.hpp"
#include "puncture/validation/model_comparison.hpp"
#include "puncture/validation/number_format.hpp"


namespace puncture::apps {

namespace {

constexpr double kMm = 1e-3;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

std::string fmt(double x, int precision = 6) {
  if (!std::isfinite(x)) return "nan";
  return validation::significant_digits(x, precision);
}
std::string shown(double x, int precision = 3) { return std::isfinite(x) ? fmt(x, precision) : "n/a"; }

/// Every model's key: the comparison models and the FEM reference.
std::vector<std::string> all_model_names() {
  std::vector<std::string> names = comparison::comparison_model_names();
  names.push_back("fem");
  return names;
}

std::string curve_csv(const Scene& scene, const validation::ModelRun& run, bool with_post) {
  std::ostringstream csv;
  csv << "# model: " << run.model << "\n# description: " << run.description << "\n# force: "
      << (with_post ? "contact + post-puncture (compared with the FEM's total)" : "contact (compared with the quasi-static FEM)")
      << "\ntime_s,depth_mm,velocity_mm_per_s,force_N,contact_force_N,post_puncture_force_N,step_wall_time_us";
  for (const Layer& l : scene.layers) csv << ',' << l.name << "_state";
  csv << '\n';
  for (std::size_t i = 0; i < run.steps(); ++i) {
    const double force = run.contact_force_N[i] + (with_post ? run.post_puncture_force_N[i] : 0.0);
    csv << fmt(run.time_s[i], 10) << ',' << fmt(run.depth_m[i] / kMm, 10) << ',' << fmt(run.velocity_m_per_s[i] / kMm, 10)
        << ',' << fmt(force, 10) << ',' << fmt(run.contact_force_N[i], 10) << ',' << fmt(run.post_puncture_force_N[i], 10)
        << ',' << fmt(run.step_wall_time_s[i] * 1e6, 6);
    for (LayerState s : run.states[i]) csv << ',' << to_string(s);
    csv << '\n';
  }
  return csv.str();
}

/// Top surfaces of every layer as polar discs displaced by the model's
/// azimuthal-mean deflection (the same picture for every model).
class DiscFrames {
 public:
  DiscFrames(const Scene& scene, int radial = 40, int azimuths = 36) : scene_(scene) {
    const double R = 0.5 * scene.sample.diameter_m;
    radii_.push_back(0.0);
    for (int i = 1; i <= radial; ++i) radii_.push_back(R * std::pow(static_cast<double>(i) / radial, 1.7));
    azimuths_ = azimuths;
    const int n = 1 + radial * azimuths;
    triangles_.resize(azimuths * (2 * radial - 1), 3);
    int t = 0;
    for (int j = 0; j < azimuths; ++j) triangles_.row(t++) << 0, 1 + j, 1 + (j + 1) % azimuths;
    for (int i = 1; i < radial; ++i)
      for (int j = 0; j < azimuths; ++j) {
        const int a = 1 + (i - 1) * azimuths + j, b = 1 + (i - 1) * azimuths + (j + 1) % azimuths;
        const int c = a + azimuths, d = b + azimuths;
        triangles_.row(t++) << a, c, d;
        triangles_.row(t++) << a, d, b;
      }
    (void)n;
  }
  void write(io::OutputSession& session, const std::string& name, const comparison::ComparisonModel& model,
             std::size_t layer, double x_offset_m) const {
    const std::vector<double> d = model.surface_deflection_m(layer, radii_);
    const int n = 1 + static_cast<int>(radii_.size() - 1) * azimuths_;
    Eigen::MatrixX3d v(n, 3);
    Eigen::VectorXd deflection(n), state = Eigen::VectorXd::Constant(n, static_cast<double>(model.layer_state(layer)));
    const double top = -scene_.layer_top_depth_m(layer);
    auto value = [&](std::size_t i) { return std::isfinite(d[i]) ? d[i] : 0.0; };
    v.row(0) << x_offset_m, 0.0, top - value(0);
    deflection[0] = value(0) / kMm;
    for (std::size_t i = 1; i < radii_.size(); ++i)
      for (int j = 0; j < azimuths_; ++j) {
        const int row = 1 + static_cast<int>(i - 1) * azimuths_ + j;
        const double phi = 2.0 * kPi * j / azimuths_;
        v.row(row) << x_offset_m + radii_[i] * std::cos(phi), radii_[i] * std::sin(phi), top - value(i);
        deflection[row] = value(i) / kMm;
      }
    io::write_polydata(session, name, v, triangles_, {{"deflection_mm", deflection}, {"layer_state", state}});
  }

 private:
  const Scene& scene_;
  std::vector<double> radii_;
  int azimuths_ = 36;
  Eigen::MatrixX3i triangles_;
};

std::string comparison_csv(const Scene& scene, const std::vector<validation::ModelMetrics>& metrics,
                           const std::vector<validation::ModelRun*>& runs, const std::vector<std::string>& descriptions) {
  std::ostringstream csv;
  csv << "model,dofs,nodes,memory_MB,force_rmse_N,force_rmse_relative,peak_force_N,reference_peak_force_N,"
         "peak_force_error_relative,puncture_depth_error_mm,puncture_layers_disagreeing";
  for (const Layer& l : scene.layers) csv << ',' << l.name << "_puncture_mm";
  csv << ",deflection_rmse_mm,deflection_rmse_relative,deflection_depths,withdrawal_force_rmse_N,"
         "step_time_mean_ms,step_time_p99_ms,step_time_max_ms,build_s,run_s,completed_fraction,recovered_steps,"
         "description\n";
  for (std::size_t i = 0; i < metrics.size(); ++i) {
    const validation::ModelMetrics& m = metrics[i];
    const validation::ModelRun* run = runs[i];
    csv << m.model << ',' << m.dofs << ',' << (run ? std::to_string(run->size.nodes) : "nan") << ','
        << fmt(m.memory_bytes / 1e6) << ',' << fmt(m.force_rmse_N) << ',' << fmt(m.force_rmse_relative) << ','
        << fmt(m.model_peak_force_N) << ',' << fmt(m.reference_peak_force_N) << ',' << fmt(m.peak_force_error_relative)
        << ',' << fmt(m.puncture_depth_error_m / kMm) << ',' << m.puncture_layers_disagreeing;
    for (const auto& p : m.punctures) csv << ',' << fmt(p.model_depth_m / kMm);
    csv << ',' << fmt(m.deflection_rmse_m / kMm) << ',' << fmt(m.deflection_rmse_relative) << ',' << m.deflection_depths
        << ',' << fmt(m.withdrawal_force_rmse_N) << ',' << fmt(m.step_time_mean_s * 1e3) << ','
        << fmt(m.step_time_p99_s * 1e3) << ',' << fmt(m.step_time_max_s * 1e3) << ','
        << (run ? fmt(run->build_wall_time_s) : "nan") << ',' << (run ? fmt(run->run_wall_time_s) : "nan") << ','
        << fmt(m.completed_fraction) << ',' << (run ? std::to_string(run->recovered_steps) : "0") << ",\""
        << descriptions[i] << "\"\n";
  }
  return csv.str();
}

bool has_column(const std::filesystem::path& csv, const std::string& column) {
  std::ifstream in(csv);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#') return ("," + line + ",").find("," + column + ",") != std::string::npos;
  return false;
}

}  // namespace

std::filesystem::path default_delphi_weights_path() {
  return default_scene_path().parent_path() / "delphi_weights.json";
}

int compare_command(const CompareOptions& options, std::ostream& out, std::ostream& err) {
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  return report_errors(err, scene_path.string(), [&]() -> int {
    const auto wall_start = std::chrono::steady_clock::now();
    const Scene scene = load_scene(scene_path);
    std::vector<std::string> models = options.models.empty() ? all_model_names() : options.models;
    const std::vector<std::string> known = all_model_names();
    std::set<std::string> seen;
    for (const std::string& m : models) {
      if (std::find(known.begin(), known.end(), m) == known.end()) {
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        throw std::invalid_argument("--models: unknown model '" + m + "' (known: " + list + ")");
      }
      if (!seen.insert(m).second) throw std::invalid_argument("--models: '" + m + "' listed twice");
    }
    for (const std::string& method : options.identify)
      if (method != "simulated_annealing" && method != "isres")
        throw std::invalid_argument("--identify: unknown method '" + method + "' (known: simulated_annealing, isres)");
    if (options.frames < 0) throw std::invalid_argument("--frames must be >= 0");
    const std::filesystem::path weights_path =
        options.weights.empty() ? default_delphi_weights_path() : options.weights;
    const validation::DelphiWeights weights = validation::read_delphi_weights(weights_path);
    const std::filesystem::path dir =
        options.output_dir.empty() ? std::filesystem::path("out") / (scene.name + "_comparison") : options.output_dir;

    // 1. The FEM reference (all MPI ranks help; only rank 0 goes on).
    validation::FemReferenceOptions fem_options;
    if (!options.cache_dir.empty()) fem_options.cache_dir = options.cache_dir;
    fem_options.verbose = !options.quiet;
    const validation::FemReference reference = validation::obtain_fem_reference(scene, fem_options, out);
    if (!validation::is_mpi_root()) return 0;
    const validation::FemResultFiles fem = validation::read_fem_result(reference.dir, scene);
    validation::ReferenceData ref;
    ref.curve = fem.curve;
    if (fem.profiles.count(scene.layers[0].name)) ref.skin_profiles = fem.profiles.at(scene.layers[0].name);
    const std::filesystem::path fem_csv = reference.dir / "fem_force_depth.csv";
    ref.has_shaft_forces = has_column(fem_csv, "friction_force_N") || has_column(fem_csv, "cutting_force_N");
    std::vector<double> profile_depths, profile_radii;
    for (const validation::RadialProfile& p : ref.skin_profiles)
      if (p.depth_m > 0.0) profile_depths.push_back(p.depth_m);
    if (!ref.skin_profiles.empty()) profile_radii = ref.skin_profiles.front().r_m;

    io::OutputSession session(dir);
    // The command as given: every option that changes the outputs.
    std::string command_line = "puncture compare " + scene_path.string();
    auto joined = [](const std::vector<std::string>& v) {
      std::string s;
      for (const std::string& x : v) s += (s.empty() ? "" : ",") + x;
      return s;
    };
    if (!options.models.empty()) command_line += " --models " + joined(options.models);
    command_line += " -o " + dir.string();
    if (!options.cache_dir.empty()) command_line += " --cache " + options.cache_dir.string();
    if (!options.weights.empty()) command_line += " --weights " + options.weights.string();
    if (!options.identify.empty())
      command_line += " --identify " + joined(options.identify) + " --identify-evaluations " +
                      std::to_string(options.identify_evaluations);
    if (options.frames != CompareOptions{}.frames) command_line += " --frames " + std::to_string(options.frames);
    if (!options.write_vtk) command_line += " --no-vtk";
    const io::Provenance run_provenance = io::make_provenance(command_line);
    const nlohmann::json provenance = io::provenance_json(run_provenance);

    // 2. The tetrahedral mesh.
    std::shared_ptr<const comparison::TetMesh> mesh;
    meshing::TetSlabMeshReport mesh_report;
    const bool need_mesh = !options.identify.empty() || std::any_of(models.begin(), models.end(), [](const std::string& m) {
                             return comparison::is_volumetric_model(m);
                           });
    if (need_mesh) {
      if (!options.quiet) out << "[compare] CGAL tetrahedral mesh of the slab ...\n" << std::flush;
      mesh = std::make_shared<comparison::TetMesh>(
          meshing::build_tet_slab_mesh(scene, meshing::tet_slab_mesh_options(scene), &mesh_report));
      if (!options.quiet)
        out << "[compare] mesh: " << mesh_report.vertices << " vertices, " << mesh_report.tetrahedra
            << " tetrahedra in " << shown(mesh_report.wall_time_s) << " s; " << comparison::describe(mesh_report.quality)
            << "\n";
      Eigen::MatrixX4i tets(mesh->tet_count(), 4);
      Eigen::VectorXd layer(mesh->tet_count()), column(mesh->tet_count());
      for (int t = 0; t < mesh->tet_count(); ++t) {
        tets.row(t) = mesh->tets[static_cast<std::size_t>(t)].transpose();
        layer[t] = mesh->layer[static_cast<std::size_t>(t)];
        column[t] = mesh->needle_column[static_cast<std::size_t>(t)];
      }
      if (options.write_vtk)
        io::write_tetrahedra(session, "mesh.vtu", mesh->points_m.transpose(), tets, {}, {},
                             {{"layer", layer}, {"needle_column", column}});
    }

    // 3. Every model along the insertion.
    const ScriptedTrajectory trajectory(scene.insertion);
    const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
    const std::size_t total_steps = static_cast<std::size_t>(std::ceil(trajectory.duration() / dt - 1e-9)) + 1;
    const DiscFrames discs(scene);
    std::vector<io::PvdEntry> pvd;
    std::vector<std::unique_ptr<validation::ModelRun>> runs;
    std::vector<std::string> run_names;
    const double frame_interval = options.frames > 0 ? trajectory.duration() / options.frames : 0.0;
    int part = 0;

    auto run_model = [&](const std::string& key, Scene model_scene, const std::string& factory_name) {
      const auto build_start = std::chrono::steady_clock::now();
      if (!options.quiet) out << "[compare] " << key << ": building ...\n" << std::flush;
      std::unique_ptr<comparison::ComparisonModel> model =
          comparison::make_comparison_model(factory_name, model_scene, comparison::is_volumetric_model(factory_name) ? mesh : nullptr);
      const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();
      validation::ModelRunOptions run_options;
      run_options.profile_depths_m = profile_depths;
      run_options.profile_radii_m = profile_radii;
      const int model_index = static_cast<int>(runs.size());
      const double x_offset = 1.25 * scene.sample.diameter_m * (model_index + 1);
      if (options.write_vtk && frame_interval > 0.0) {
        run_options.frame_interval_s = frame_interval;
        const int first_part = part;
        part += static_cast<int>(scene.layers.size()) + (model->has_volume() ? 1 : 0);
        run_options.on_frame = [&, key, x_offset, first_part](const comparison::ComparisonModel& m, double t, int frame) {
          char index[16];
          std::snprintf(index, sizeof index, "%04d", frame);
          for (std::size_t k = 0; k < scene.layers.size(); ++k) {
            const std::string name = "frames/" + key + "/" + scene.layers[k].name + "_surface_" + index + ".vtp";
            discs.write(session, name, m, k, x_offset);
            pvd.push_back({t, first_part + static_cast<int>(k), name});
          }
          if (m.has_volume()) {
            comparison::VolumeFrame f = m.volume_frame();
            f.points_m.col(0).array() += x_offset;
            const std::string name = std::string("frames/") + key + "/volume_" + index + ".vtu";
            io::write_tetrahedra(session, name, f.points_m, f.tets, {}, {{"displacement_m", f.displacement_m}},
                                 {{"layer", f.layer}});
            pvd.push_back({t, first_part + static_cast<int>(scene.layers.size()), name});
          }
        };
      }
      int last_tenth = -1;
      if (!options.quiet)
        run_options.on_progress = [&, key](double fraction) {
          const int tenth = static_cast<int>(fraction * 10.0);
          if (tenth != last_tenth) {
            last_tenth = tenth;
            out << "[compare] " << key << ": " << tenth * 10 << " %\n" << std::flush;
          }
        };
      auto run = std::make_unique<validation::ModelRun>(validation::run_comparison_model(*model, model_scene, run_options));
      run->model = key;
      run->build_wall_time_s = build_s;
      if (run->failed()) err << "warning: " << key << " failed " << run->failure << "\n";
      if (!options.quiet)
        out << "[compare] " << key << ": " << run->steps() << " steps in " << shown(run->run_wall_time_s) << " s"
            << (run->integrator_report.empty() ? "" : "; " + run->integrator_report) << "\n";
      session.write_text("curves/" + key + ".csv", curve_csv(model_scene, *run, ref.has_shaft_forces));
      run_names.push_back(key);
      runs.push_back(std::move(run));
    };

    for (const std::string& m : models)
      if (m != "fem") run_model(m, scene, m);

    // 4. Mass-spring identification.
    nlohmann::json identification = nlohmann::json::array();
    for (const std::string& method : options.identify) {
      validation::IdentificationOptions id_options;
      id_options.method = method;
      id_options.max_evaluations = options.identify_evaluations;
      if (!options.quiet) out << "[compare] identifying the mass-spring stiffnesses by " << method << " ...\n" << std::flush;
      const validation::IdentificationResult r = validation::identify_mass_spring_stiffness(
          scene, mesh, ref, id_options, [&](int evaluation, double objective, double best) {
            if (!options.quiet)
              out << "[identify " << method << "] evaluation " << evaluation << ": objective " << shown(objective, 4)
                  << " (best " << shown(best, 4) << ")\n" << std::flush;
          });
      nlohmann::json j;
      j["method"] = method;
      j["library"] = method == "isres" ? "NLopt GN_ISRES (evolution strategy)" : "GSL gsl_siman (simulated annealing)";
      j["scale_before"] = r.scale_before;
      j["scale_after"] = r.scale_after;
      j["objective_before"] = r.before.objective;
      j["objective_after"] = r.after.objective;
      j["force_rmse_relative_before"] = r.before.force_rmse_relative;
      j["force_rmse_relative_after"] = r.after.force_rmse_relative;
      nlohmann::json punctures = nlohmann::json::array();
      for (std::size_t k = 0; k < r.punctures_after.size(); ++k)
        punctures.push_back({{"layer", r.punctures_after[k].layer},
                             {"reference_mm", fmt(r.punctures_after[k].reference_depth_m / kMm)},
                             {"before_mm", fmt(r.punctures_before[k].model_depth_m / kMm)},
                             {"after_mm", fmt(r.punctures_after[k].model_depth_m / kMm)}});
      j["puncture_depths"] = punctures;
      j["evaluations"] = r.evaluations;
      j["wall_time_s"] = r.wall_time_s;
      j["seconds_per_evaluation"] = r.seconds_per_evaluation;
      j["model_runs"] = "quasi-static mass-spring on the comparison mesh, steps of " + fmt(id_options.step_m / kMm) + " mm";
      nlohmann::json history = nlohmann::json::array();
      for (const auto& e : r.history) history.push_back({{"scale", e.scale}, {"objective", e.objective}});
      j["history"] = history;
      identification.push_back(j);
      Scene identified = scene;
      identified.comparison.mass_spring_stiffness_scale = r.scale_after;
      run_model(std::string("msm_") + (method == "isres" ? "isres" : "sa"), identified, "msm");
    }

    // 5. Metrics, grading, outputs.
    std::vector<validation::ModelMetrics> metrics;
    std::vector<validation::ModelRun*> metric_runs;
    std::vector<std::string> descriptions;
    for (auto& run : runs) {
      metrics.push_back(validation::metrics_against_reference(scene, *run, ref, total_steps));
      metric_runs.push_back(run.get());
      descriptions.push_back(run->description);
    }
    if (std::find(models.begin(), models.end(), "fem") != models.end()) {
      validation::ModelMetrics f;
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
        validation::LayerPunctureComparison p;
        p.layer = l.name;
        const validation::PunctureEventMetrics e = validation::puncture_event(fem.curve, l.name);
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
      metrics.push_back(f);
      metric_runs.push_back(nullptr);
      descriptions.push_back("deal.II finite-strain FEM reference (" + std::to_string(f.dofs) + " dofs, " +
                             std::to_string(fem.summary.value("n_ranks", 1)) + " rank(s)); time per load step of " +
                             fmt(scene.fem.load_step_m / kMm) + " mm");
    }
    session.write_text("comparison.csv", comparison_csv(scene, metrics, metric_runs, descriptions));
    session.write_text("fem_curve.csv", validation::insertion_curve_csv(fem.curve));
    {  // skin deflection profiles, model and FEM, at the FEM's depths
      std::ostringstream csv;
      csv << "model,depth_mm,r_mm,deflection_mm\n";
      for (const validation::RadialProfile& p : ref.skin_profiles)
        for (std::size_t i = 0; i < p.r_m.size(); ++i)
          csv << "fem," << fmt(p.depth_m / kMm) << ',' << fmt(p.r_m[i] / kMm) << ',' << fmt(-p.uz_m[i] / kMm) << '\n';
      for (const auto& run : runs)
        for (const validation::SurfaceSnapshot& s : run->skin_profiles)
          for (std::size_t i = 0; i < s.r_m.size(); ++i)
            csv << run->model << ',' << fmt(s.depth_m / kMm) << ',' << fmt(s.r_m[i] / kMm) << ','
                << fmt(s.deflection_m[i] / kMm) << '\n';
      session.write_text("deflection_profiles.csv", csv.str());
    }
    const validation::ComparisonGrade grade = validation::grade_models(metrics, weights);
    session.write_text("ranking.csv", validation::ranking_csv(grade));
    nlohmann::json summary;
    summary["provenance"] = provenance;
    summary["scene"] = scene.name;
    summary["fem_reference"] = {{"hash", reference.hash},
                                {"from_cache", reference.from_cache},
                                {"summary", fem.summary},
                                {"has_cutting_or_friction_columns", ref.has_shaft_forces}};
    summary["compared_force"] = ref.has_shaft_forces ? "total (contact + post-puncture)" : "contact force only";
    if (mesh)
      summary["mesh"] = {{"vertices", mesh_report.vertices},
                         {"tetrahedra", mesh_report.tetrahedra},
                         {"wall_time_s", mesh_report.wall_time_s},
                         {"min_dihedral_deg", mesh_report.quality.min_dihedral_deg},
                         {"max_radius_edge_ratio", mesh_report.quality.max_radius_edge_ratio},
                         {"options", {{"size_at_axis_mm", scene.comparison.mesh.size_at_axis_m / kMm},
                                      {"size_far_mm", scene.comparison.mesh.size_far_m / kMm},
                                      {"grading", scene.comparison.mesh.grading}}}};
    nlohmann::json integrators = nlohmann::json::object();
    for (const auto& run : runs) {
      integrators[run->model] = {{"description", run->description}, {"integrator", run->integrator_report}};
      if (run->failed()) integrators[run->model]["failure"] = run->failure;
    }
    summary["models"] = integrators;
    summary["identification"] = identification;
    summary["weights_file"] = weights_path.string();
    summary["wall_time_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    session.write_text("comparison_summary.json", summary.dump(2) + "\n");
    if (!pvd.empty()) io::write_pvd(session, "comparison.pvd", pvd);
    session.commit();

    const std::vector<std::string> plots = validation::run_plot_script("plot_comparison.py", dir, out, err);

    // comparison.md: command, machine, date, FEM version, table, ranking.
    std::ostringstream md;
    md << "# Model comparison: " << scene.name << "\n\n"
       << "Made by `" << command_line << "` on " << provenance["machine"].get<std::string>() << ", "
       << provenance["date_utc"].get<std::string>() << " (puncture " << provenance["program_version"].get<std::string>()
       << ", git " << provenance["git_revision"].get<std::string>() << "); wall time "
       << shown(summary["wall_time_s"].get<double>(), 4) << " s.\n\n"
       << "FEM reference: cache key `" << reference.hash << "` (" << (reference.from_cache ? "from the cache" : "computed now")
       << "), " << fem.summary.value("n_dofs", 0L) << " dofs, " << fem.summary.value("load_steps", 0L)
       << " load steps in " << shown(fem.summary.value("wall_time_s", kNaN), 4) << " s. "
       << (ref.has_shaft_forces ? "Its curve has cutting/friction columns: every model's force includes the same shaft forces (cutting, Karnopp friction and Table 1's d h v)."
                                : "Its curve is quasi-static and frictionless (no cutting/friction columns): the "
                                  "models' contact force is compared, without Table 1's post-puncture d h v.")
       << "\n\n";
    if (mesh)
      md << "Tetrahedral mesh (CGAL Mesh_3): " << mesh_report.vertices << " vertices, " << mesh_report.tetrahedra
         << " tetrahedra; " << comparison::describe(mesh_report.quality) << ".\n\n";
    md << "| model | dofs | memory MB | force RMSE / FEM peak | peak force error | puncture depth error mm | "
          "skin deflection RMSE / max | step mean ms | step p99 ms |\n|---|---|---|---|---|---|---|---|---|\n";
    for (const validation::ModelMetrics& m : metrics)
      md << "| " << m.model << " | " << m.dofs << " | " << shown(m.memory_bytes / 1e6) << " | "
         << shown(m.force_rmse_relative) << " | " << shown(m.peak_force_error_relative) << " | "
         << shown(m.puncture_depth_error_m / kMm) << (m.puncture_layers_disagreeing ? " (" + std::to_string(m.puncture_layers_disagreeing) + " layer(s) broken by one only)" : "")
         << " | " << shown(m.deflection_rmse_relative) << " | " << shown(m.step_time_mean_s * 1e3) << " | "
         << shown(m.step_time_p99_s * 1e3) << " |\n";
    md << "\nTimes per step are over the steps with the tip in the tissue; the FEM's is its wall time per load step.\n\n"
       << "## Ranking (seed paper Sec. 3.3)\n\n" << validation::ranking_markdown(grade, weights) << "\n";
    if (!identification.empty()) {
      md << "## Mass-spring identification\n\n| method | factors before | factors after | objective before | "
            "objective after | force RMSE before | after | evaluations | wall time s |\n|---|---|---|---|---|---|---|---|---|\n";
      for (const auto& j : identification) {
        auto list = [](const nlohmann::json& v) {
          std::string s;
          for (const auto& x : v) s += (s.empty() ? "" : ", ") + fmt(x.get<double>(), 3);
          return s;
        };
        md << "| " << j["library"].get<std::string>() << " | " << list(j["scale_before"]) << " | " << list(j["scale_after"])
           << " | " << shown(j["objective_before"].get<double>()) << " | " << shown(j["objective_after"].get<double>())
           << " | " << shown(j["force_rmse_relative_before"].get<double>()) << " | "
           << shown(j["force_rmse_relative_after"].get<double>()) << " | " << j["evaluations"].get<int>() << " | "
           << shown(j["wall_time_s"].get<double>(), 4) << " |\n";
      }
      md << "\n";
    }
    md << "## Models\n\n";
    for (std::size_t i = 0; i < metrics.size(); ++i) md << "- **" << metrics[i].model << "**: " << descriptions[i] << "\n";
    for (const auto& run : runs)
      if (!run->integrator_report.empty()) md << "- " << run->model << " integration: " << run->integrator_report << "\n";
    md << "\n";
    for (const std::string& png : plots) md << "![" << png << "](" << png << ")\n\n";
    md << "Files: `comparison.csv` (one row per model), `ranking.csv`, `curves/<model>.csv` (every step), "
          "`deflection_profiles.csv`, `fem_curve.csv`, `comparison_summary.json`"
       << (options.write_vtk ? ", `mesh.vtu`, `comparison.pvd` (every model side by side in ParaView, shifted along x)" : "")
       << ".\n";
    io::OutputSession md_session(dir);
    md_session.write_text("comparison.md", md.str());
    md_session.commit();

    out << "\nModel comparison against the FEM (" << (ref.has_shaft_forces ? "total force" : "contact force") << "):\n";
    for (std::size_t i = 0; i < metrics.size(); ++i)
      out << "  " << std::left << std::setw(26) << metrics[i].model << std::right << " force RMSE "
          << std::setw(8) << shown(metrics[i].force_rmse_relative) << " of the FEM peak, step p99 "
          << std::setw(9) << shown(metrics[i].step_time_p99_s * 1e3) << " ms, score "
          << shown(grade.final_scores[i]) << " (rank " << grade.rank[i] << ")\n";
    out << "Outputs in " << dir.string() << "/ (comparison.md, comparison.csv, ranking.csv"
        << (options.write_vtk ? ", comparison.pvd" : "") << ")\n";
    return 0;
  });
}

}  // namespace puncture::apps
