// axisymmetric_insertion.cc: the needle insertion in the meridian plane (see
// needle_insertion.hpp and reference_fem/README.md). Reads top-down as the
// algorithm: build the mesh and the solver, then walk the needle along the
// scene's trajectory (approach, insertion, dwell, withdrawal) step by step:
// advance the needle, solve (cutting the step when Newton fails), detect
// punctures, record the row, the profiles and the frames; then write.
#include <deal.II/base/mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include <puncture/fem/axisymmetric_solver.hpp>
#include <puncture/fem/field_output.hpp>
#include <puncture/fem/needle_insertion.hpp>
#include <puncture/meshing/axisymmetric_slab_mesh.hpp>

namespace puncture::fem {

namespace {

constexpr double kPi = 3.14159265358979323846;

enum class LayerState { untouched, pressed, punctured };
const char* to_string(LayerState s) {
  switch (s) {
    case LayerState::untouched: return "untouched";
    case LayerState::pressed: return "pressed";
    case LayerState::punctured: return "punctured";
  }
  return "?";
}

std::string fmt(double v, int precision = 9) {
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

/// One point of the needle's trajectory: time, tip depth (m below the skin
/// surface; negative above it) and phase.
struct TrajectoryPoint {
  double time_s;
  double depth_m;
  const char* phase;
};

/// The scene's trajectory as the list of step end points: the approach to the
/// surface in one step, insertion in steps of load_step, the dwell in two
/// steps, withdrawal in steps of twice the load step back to the start height.
std::vector<TrajectoryPoint> trajectory(const Scene& scene, double stop_depth_m) {
  const Insertion& in = scene.insertion;
  const double step = scene.fem.load_step_m;
  const double target = stop_depth_m > 0.0 ? std::min(stop_depth_m, in.target_depth_m) : in.target_depth_m;
  std::vector<TrajectoryPoint> out;
  double t = in.start_height_m / in.speed_m_per_s;
  out.push_back({t, 0.0, "approach"});
  const int n_in = static_cast<int>(std::ceil(target / step - 1e-9));
  for (int k = 1; k <= n_in; ++k) {
    const double d = std::min(k * step, target);
    out.push_back({t + d / in.speed_m_per_s, d, "insertion"});
  }
  t += target / in.speed_m_per_s;
  if (stop_depth_m > 0.0) return out;  // a study stops at this depth
  if (in.dwell_s > 0.0) {
    out.push_back({t + 0.5 * in.dwell_s, target, "dwell"});
    out.push_back({t + in.dwell_s, target, "dwell"});
    t += in.dwell_s;
  }
  const double w_step = 2.0 * step, end = -in.start_height_m;
  const int n_out = static_cast<int>(std::ceil((target - end) / w_step - 1e-9));
  for (int k = 1; k <= n_out; ++k) {
    const double d = std::max(target - k * w_step, end);
    out.push_back({t + (target - d) / in.withdrawal_speed_m_per_s, d, "withdrawal"});
  }
  return out;
}

/// Per-layer crack laws and friction from the scene.
struct LayerLaws {
  std::vector<LayerMaterial> materials;
  std::vector<LayerCrack> cracks;
  std::vector<FrictionCoefficients> friction;
};

LayerLaws layer_laws(const Scene& scene, double crack_radius_m) {
  LayerLaws laws;
  const bool bevel = scene.needle.tip == "bevel";
  const double a = scene.needle.radius_m;
  for (const Layer& l : scene.layers) {
    laws.materials.emplace_back(l.material);
    LayerCrack c;
    if (l.puncture.kind == PunctureCriterion::Kind::FractureEnergy) {
      c.kind = LayerCrack::Kind::Cohesive;
      c.law.strength_Pa = l.puncture.cohesive_strength_Pa;
      c.law.toughness_J_per_m2 = l.puncture.toughness_J_per_m2;
      c.law.viscosity_s = scene.fem.cohesive_viscosity_s;
      if (bevel) {
        c.area_scale = 2.0 * a / (2.0 * kPi * crack_radius_m);
        c.opening_scale = 2.0 * a / (a - crack_radius_m);
      }
    } else {
      c.kind = LayerCrack::Kind::TiedUntilBroken;
    }
    laws.cracks.push_back(c);
    laws.friction.push_back({l.shaft_friction.dynamic_coefficient, l.shaft_friction.static_coefficient});
  }
  return laws;
}

struct Row {
  double time_s, depth_m, velocity_m_per_s, force_N, tip_N, cutting_N, friction_N, tip_stretch;
  std::string phase;
  std::vector<LayerState> states;
};

}  // namespace

FemRunSummary run_axisymmetric_insertion(const Scene& scene, const FemRunOptions& options, MPI_Comm comm) {
  using dealii::Utilities::MPI::this_mpi_process;
  const bool root = this_mpi_process(comm) == 0;
  FemRunSummary summary;
  std::string error;
  if (root) {
    try {
      const auto wall_start = std::chrono::steady_clock::now();
      auto log = [&](const std::string& s) {
        if (options.verbose) std::cout << s << std::endl;
      };

      // ---- 0. What the scene asks for --------------------------------------------
      if (scene.layers.empty()) throw std::invalid_argument("fem: the scene has no layers");
      if (scene.insertion.angle_deg != 0.0)
        throw std::invalid_argument("fem: only insertions along the sample axis (angle_deg = 0) are modelled");
      if (!(scene.insertion.speed_m_per_s > 0.0)) throw std::invalid_argument("fem: insertion speed must be > 0");
      const int degree = options.degree_override > 0 ? options.degree_override : scene.fem.element_degree;
      const int refinement = options.refinement_override >= 0 ? options.refinement_override : scene.fem.refinement;
      if (degree != 1 && degree != 2) throw std::invalid_argument("fem: element degree must be 1 or 2");
      const bool cutting = scene.needle.tip != "blunt";
      const std::size_t n_layers = scene.layers.size();
      const double a = scene.needle.radius_m;

      // ---- 1. Mesh and solver ----------------------------------------------------
      const meshing::AxisymmetricSlabMesh mesh = meshing::build_axisymmetric_slab_mesh(scene, refinement);
      LayerLaws laws = layer_laws(scene, mesh.crack_radius_m);
      AxisymmetricSettings settings;
      settings.degree = static_cast<unsigned>(degree);
      settings.max_newton_iterations = scene.fem.max_newton_iterations;
      settings.newton_tolerance = scene.fem.newton_tolerance;
      settings.verbose = std::getenv("PUNCTURE_FEM_DEBUG") != nullptr;
      settings.stabilization_time_s = scene.fem.stabilization_time_s;
      AxisymmetricSolver solver(mesh, laws.materials, laws.cracks, laws.friction, settings);
      solver.setup(0.5 * scene.sample.diameter_m, scene.total_thickness_m());
      summary.geometry = "axisymmetric";
      summary.n_dofs = solver.n_dofs();
      summary.n_cells = solver.n_cells();
      summary.n_ranks = static_cast<int>(dealii::Utilities::MPI::n_mpi_processes(comm));
      summary.degree = degree;
      summary.refinement = refinement;
      summary.tip_element_size_m = mesh.tip_element_size_m;
      summary.elements_through_layer = mesh.elements_through_layer;
      // Resolution the mesh-convergence study found within 3 % of the converged
      // indentation force (results/fem_mesh_convergence.md).
      const double per_radius = a / mesh.tip_element_size_m;
      const double needed = degree == 1 ? 8.0 : 4.0;
      if (per_radius < needed - 1e-9)
        summary.warnings.push_back("mesh: " + fmt(per_radius, 3) + " elements per needle radius with Q" +
                                   std::to_string(degree) + "; at least " + fmt(needed, 2) +
                                   " are needed for the indentation force to be within 3 % of its converged value");
      for (std::size_t i = 0; i < n_layers; ++i)
        if (mesh.elements_through_layer[i] < 4)
          summary.warnings.push_back("mesh: layer '" + scene.layers[i].name + "' has only " +
                                     std::to_string(mesh.elements_through_layer[i]) + " elements through its thickness");
      {
        std::ostringstream s;
        s << "fem: scene '" << scene.name << "', axisymmetric, " << summary.n_cells << " cells, Q" << degree << " ("
          << summary.n_dofs << " dofs), tip element " << mesh.tip_element_size_m * 1e3 << " mm, needle tip '"
          << scene.needle.tip << "', crack radius " << mesh.crack_radius_m * 1e3 << " mm";
        log(s.str());
        for (const auto& w : summary.warnings) std::cerr << "warning: " << w << std::endl;
      }

      // The needle at a given tip depth.
      const double flank = scene.needle.tip_angle_deg * kPi / 180.0;
      auto place_needle = [&](double depth) {
        if (cutting) {
          RigidNeedle n;
          n.edge_radius_m = mesh.crack_radius_m;
          n.shaft_radius_m = a;
          n.flank_angle_rad = flank;
          n.z_tip_m = -depth;
          solver.set_cutting_needle(n);
        } else {
          solver.set_flat_punch(a, -depth);
        }
      };

      // ---- 2. Outputs being collected ---------------------------------------------
      const std::filesystem::path out_dir = options.output_dir;
      if (options.write_files) std::filesystem::create_directories(out_dir);
      std::vector<Row> rows;
      std::ostringstream newton_log, profile_csv, recovery_csv;
      profile_csv << "step,depth_mm,r_mm,uz_mm,surface\n";
      recovery_csv << "layer,phase,depth_mm,r_mm,uz_mm\n";
      std::vector<std::pair<double, std::string>> frames;
      const auto plan = trajectory(scene, options.stop_depth_m);
      const int frame_every = std::max<int>(1, static_cast<int>(plan.size()) / std::max(1, options.max_vtu_frames));
      auto write_frame = [&](double time) {
        if (!options.write_files || !options.write_vtu) return;
        std::ostringstream name;
        name << "fem_fields_" << std::setw(4) << std::setfill('0') << frames.size() << ".vtu";
        const std::filesystem::path tmp = out_dir / (name.str() + ".part");
        solver.write_vtu(tmp.string());
        std::filesystem::rename(tmp, out_dir / name.str());
        frames.emplace_back(time, name.str());
        summary.files_written.push_back(name.str());
      };
      auto layer_top_profile = [&](std::size_t layer) {
        return solver.vertical_displacement_along(-scene.layer_top_depth_m(layer));
      };

      // ---- 3. State of the layers --------------------------------------------------
      std::vector<LayerState> states(n_layers, LayerState::untouched);
      std::vector<double> peak_force(n_layers, 0.0), peak_depth(n_layers, 0.0), peak_time(n_layers, 0.0);
      std::vector<std::vector<std::pair<double, double>>> peak_profile(n_layers);
      auto pressed_layer = [&]() -> int {
        for (std::size_t i = 0; i < n_layers; ++i)
          if (states[i] != LayerState::punctured) return static_cast<int>(i);
        return -1;
      };
      // Layer i is punctured once its crack is fully open a little below its top.
      auto crack_through_top = [&](std::size_t i) {
        const double top = scene.layer_top_depth_m(i);
        const double margin = std::min(0.25 * scene.layers[i].thickness_m, a);
        return solver.crack_front_depth_m(static_cast<int>(i)) >= top + margin - 1e-12;
      };

      // ---- 4. Walk the trajectory ---------------------------------------------------
      double depth = -scene.insertion.start_height_m, time = 0.0;
      double dissipated_before = 0.0;
      auto record = [&](const std::string& phase, double velocity, double cutting_N) {
        const NeedleForce f = solver.needle_force();
        const int p = pressed_layer();
        double stretch = 1.0;
        if (p >= 0 && f.nodes_in_contact > 0)
          stretch = solver.max_principal_stretch(p, 2.0 * a, -depth - 2.0 * a, -depth + 2.0 * a);
        const double total = f.nodes_in_contact > 0 ? f.total_N : 0.0;
        const double friction = f.nodes_in_contact > 0 ? f.friction_N : 0.0;
        rows.push_back({time, depth, velocity, total, total - friction - cutting_N, cutting_N, friction, stretch, phase,
                        states});
        summary.time_s.push_back(time);
        summary.depth_m.push_back(depth);
        summary.force_N.push_back(total);
        summary.tip_force_N.push_back(total - friction - cutting_N);
        summary.cutting_force_N.push_back(cutting_N);
        summary.friction_force_N.push_back(friction);
        summary.phase.push_back(phase);
        if (total > summary.peak_force_N) {
          summary.peak_force_N = total;
          summary.peak_force_depth_m = depth;
        }
      };
      record("approach", scene.insertion.speed_m_per_s, 0.0);
      write_frame(time);

      const double min_fraction = 1.0 / 256.0;
      double fraction = 1.0;  // of the planned step, grows back after cuts
      int step_index = 0;
      double last_advance = 0.0;  // depth change of the last converged step (for the predictor)
      for (std::size_t k = 0; k < plan.size(); ++k) {
        const TrajectoryPoint& goal = plan[k];
        const std::string phase = goal.phase;
        if (phase == "approach") {  // nothing touches the tissue above its surface
          depth = goal.depth_m;
          time = goal.time_s;
          record(phase, scene.insertion.speed_m_per_s, 0.0);
          continue;
        }
        while (time < goal.time_s - 1e-12 * std::max(1.0, goal.time_s)) {
          const double t0 = time, d0 = depth;
          double t1 = std::min(goal.time_s, t0 + fraction * (goal.time_s - plan[k - 1].time_s));
          // Sub-steps of a planned step follow the trajectory linearly.
          const double s = (t1 - plan[k - 1].time_s) / (goal.time_s - plan[k - 1].time_s);
          double d1 = plan[k - 1].depth_m + s * (goal.depth_m - plan[k - 1].depth_m);
          place_needle(d1);
          solver.set_time_step(t1 - t0);
          const double advance = d1 - d0;
          const double predictor = (last_advance != 0.0 && advance * last_advance > 0.0) ? advance / last_advance : 0.0;
          const auto snapshot_dissipation = solver.cohesive_dissipation_J();
          const auto t_solve = std::chrono::steady_clock::now();
          const AxisymmetricNewtonReport report = solver.solve_step(predictor);
          summary.solve_time_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t_solve).count();
          summary.newton_iterations += report.iterations;
          newton_log << "step " << step_index << "  " << phase << "  depth " << d1 * 1e3 << " mm  t " << t1 << " s\n";
          for (const auto& line : report.table) newton_log << line << "\n";
          if (!report.converged) {
            ++summary.step_cuts;
            newton_log << "  -> " << report.failure << "; step cut\n";
            fraction *= 0.5;
            if (fraction < min_fraction) {
              std::ostringstream m;
              m << "no convergence at tip depth " << d1 * 1e3 << " mm (" << phase << ") even with 1/256 of the load step: "
                << report.failure;
              throw std::runtime_error(m.str());
            }
            place_needle(d0);
            continue;
          }
          ++step_index;
          ++summary.load_steps;
          time = t1;
          depth = d1;
          last_advance = advance;
          fraction = std::min(1.0, 2.0 * fraction);
          const double dissipated = solver.cohesive_dissipation_J();
          const double cutting_N = advance > 0.0 ? (dissipated - snapshot_dissipation) / advance : 0.0;
          (void)dissipated_before;

          // ---- detect punctures and layer states
          const NeedleForce f = solver.needle_force();
          for (std::size_t i = 0; i < n_layers; ++i) {
            if (states[i] == LayerState::punctured) continue;
            const bool first_intact = static_cast<int>(i) == pressed_layer();
            if (states[i] == LayerState::untouched && first_intact && f.nodes_in_contact > 0) {
              const auto u = solver.displacement_at(mesh.crack_radius_m, -scene.layer_top_depth_m(i));
              if (i == 0 || depth >= scene.layer_top_depth_m(i) - u[1] - 1e-9) states[i] = LayerState::pressed;
            }
            if (states[i] != LayerState::pressed) continue;
            if (f.total_N > peak_force[i]) {
              peak_force[i] = f.total_N;
              peak_depth[i] = depth;
              peak_time[i] = time;
              peak_profile[i] = layer_top_profile(i);
            }
            bool broken = false;
            const PunctureCriterion& c = scene.layers[i].puncture;
            if (c.kind == PunctureCriterion::Kind::FractureEnergy) {
              broken = crack_through_top(i);
            } else if (first_intact) {
              const double value =
                  c.kind == PunctureCriterion::Kind::CriticalForce
                      ? f.total_N
                      : solver.max_principal_stretch(static_cast<int>(i), 2.0 * a, -depth - 2.0 * a, -depth + 2.0 * a);
              broken = value >= (c.kind == PunctureCriterion::Kind::CriticalForce ? c.critical_force_N : c.critical_stretch);
              if (broken && !cutting)
                throw std::runtime_error("the puncture criterion of layer '" + scene.layers[i].name +
                                         "' is met, but a blunt (flat) punch cannot cut in the axisymmetric reference: "
                                         "use needle tip bevel or hollow, or fem.geometry 3d");
              if (broken) solver.break_layer(static_cast<int>(i));
            }
            if (!broken) continue;
            states[i] = LayerState::punctured;
            PunctureEvent e;
            e.layer = static_cast<int>(i);
            e.layer_name = scene.layers[i].name;
            e.depth_m = peak_depth[i];
            e.force_N = peak_force[i];
            e.force_after_N = f.total_N;
            e.time_s = peak_time[i];
            summary.punctures.push_back(e);
            for (const auto& [r, uz] : peak_profile[i])
              recovery_csv << i << ",before," << fmt(peak_depth[i] * 1e3) << "," << fmt(r * 1e3) << ","
                           << fmt(uz * 1e3) << "\n";
            for (const auto& [r, uz] : layer_top_profile(i))
              recovery_csv << i << ",after," << fmt(depth * 1e3) << "," << fmt(r * 1e3) << ","
                           << fmt(uz * 1e3) << "\n";
            std::ostringstream m;
            m << "fem: " << e.layer_name << " punctured: peak " << e.force_N << " N at " << e.depth_m * 1e3
              << " mm, " << e.force_after_N << " N at " << depth * 1e3 << " mm";
            log(m.str());
            write_frame(time);
          }

          const double velocity = phase == "dwell" ? 0.0 : (t1 > t0 ? advance / (t1 - t0) : 0.0);
          record(phase, velocity, cutting_N);
          const int p = pressed_layer();
          if (p >= 0 && states[p] == LayerState::pressed && step_index % 2 == 0)
            for (const auto& [r, uz] : layer_top_profile(p))
              profile_csv << step_index << "," << fmt(depth * 1e3) << "," << fmt(r * 1e3) << "," << fmt(uz * 1e3) << ","
                          << scene.layers[p].name << "\n";
          if (step_index % frame_every == 0) write_frame(time);
          if (options.verbose && step_index % 10 == 0) {
            std::ostringstream m;
            m << "  step " << step_index << "  " << phase << "  depth " << std::fixed << std::setprecision(3)
              << depth * 1e3 << " mm  force " << std::setprecision(4) << rows.back().force_N << " N (friction "
              << rows.back().friction_N << " N)  newton " << report.iterations;
            log(m.str());
          }
        }
      }
      summary.cohesive_dissipation_J = solver.cohesive_dissipation_J();
      summary.stabilization_dissipation_J = solver.stabilization_dissipation_J();
      // Needle work over the insertion (trapezoid rule on force x depth).
      for (std::size_t k = 1; k < rows.size(); ++k)
        if (rows[k].phase == "insertion")
          summary.needle_work_J += 0.5 * (rows[k].force_N + rows[k - 1].force_N) * (rows[k].depth_m - rows[k - 1].depth_m);

      // ---- 5. Write ---------------------------------------------------------------------
      summary.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
      if (options.write_files) {
        std::ostringstream csv;
        csv << "time_s,depth_mm,velocity_mm_per_s,force_N,tip_force_N,cutting_force_N,friction_force_N,tip_stretch,phase";
        for (const auto& layer : scene.layers) csv << "," << layer.name << "_state";
        csv << "\n";
        for (const Row& r : rows) {
          csv << fmt(r.time_s) << "," << fmt(r.depth_m * 1e3) << "," << fmt(r.velocity_m_per_s * 1e3) << ","
              << fmt(r.force_N) << "," << fmt(r.tip_N) << "," << fmt(r.cutting_N) << "," << fmt(r.friction_N) << ","
              << fmt(r.tip_stretch) << "," << r.phase;
          for (const auto st : r.states) csv << "," << to_string(st);
          csv << "\n";
        }
        write_file_atomically(out_dir / "fem_force_depth.csv", csv.str());
        write_file_atomically(out_dir / "fem_surface_profile.csv", profile_csv.str());
        write_file_atomically(out_dir / "fem_recovery_profile.csv", recovery_csv.str());
        write_file_atomically(out_dir / "fem_newton_log.txt", newton_log.str());
        if (!frames.empty()) {
          std::ostringstream pvd;
          pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
          for (const auto& [t, name] : frames)
            pvd << "    <DataSet timestep=\"" << fmt(t) << "\" part=\"0\" file=\"" << name << "\"/>\n";
          pvd << "  </Collection>\n</VTKFile>\n";
          write_file_atomically(out_dir / "fem_fields.pvd", pvd.str());
          summary.files_written.push_back("fem_fields.pvd");
        }
        for (const char* f : {"fem_force_depth.csv", "fem_surface_profile.csv", "fem_recovery_profile.csv",
                              "fem_newton_log.txt", "fem_summary.json"})
          summary.files_written.push_back(f);
        nlohmann::json j;
        j["status"] = "ok";
        j["scene"] = scene.name;
        j["geometry"] = "axisymmetric";
        j["n_dofs"] = summary.n_dofs;
        j["n_cells"] = summary.n_cells;
        j["n_ranks_used"] = 1;
        j["element_degree"] = degree;
        j["refinement"] = refinement;
        j["tip_element_size_mm"] = mesh.tip_element_size_m * 1e3;
        j["crack_radius_mm"] = mesh.crack_radius_m * 1e3;
        j["elements_through_layer"] = mesh.elements_through_layer;
        j["load_step_mm"] = scene.fem.load_step_m * 1e3;
        j["peak_force_N"] = summary.peak_force_N;
        j["peak_force_depth_mm"] = summary.peak_force_depth_m * 1e3;
        j["cohesive_dissipation_J"] = summary.cohesive_dissipation_J;
        j["stabilization_dissipation_J"] = summary.stabilization_dissipation_J;
        j["needle_work_insertion_J"] = summary.needle_work_J;
        j["load_steps"] = summary.load_steps;
        j["step_cuts"] = summary.step_cuts;
        j["newton_iterations"] = summary.newton_iterations;
        j["wall_time_s"] = summary.wall_time_s;
        j["solve_time_s"] = summary.solve_time_s;
        j["warnings"] = summary.warnings;
        j["punctures"] = nlohmann::json::array();
        for (const auto& e : summary.punctures)
          j["punctures"].push_back({{"layer", e.layer}, {"name", e.layer_name}, {"depth_mm", e.depth_m * 1e3},
                                    {"force_N", e.force_N}, {"force_after_N", e.force_after_N}, {"time_s", e.time_s}});
        j["files"] = summary.files_written;
        write_file_atomically(out_dir / "fem_summary.json", j.dump(2) + "\n");
      }
    } catch (const std::exception& e) {
      error = e.what();
      if (error.empty()) error = "unknown error";
    }
  }
  // Rank 0 computed; the others learn the outcome (and the curve) from it.
  if (dealii::Utilities::MPI::n_mpi_processes(comm) > 1) {
    nlohmann::json j;
    if (root) {
      j["error"] = error;
      j["time_s"] = summary.time_s;
      j["depth_m"] = summary.depth_m;
      j["force_N"] = summary.force_N;
      j["peak_force_N"] = summary.peak_force_N;
      j["n_dofs"] = summary.n_dofs;
      j["wall_time_s"] = summary.wall_time_s;
      nlohmann::json ev = nlohmann::json::array();
      for (const auto& e : summary.punctures)
        ev.push_back({e.layer, e.layer_name, e.depth_m, e.force_N, e.force_after_N, e.time_s});
      j["punctures"] = ev;
    }
    const std::string text = dealii::Utilities::MPI::broadcast(comm, root ? j.dump() : std::string(), 0);
    if (!root) {
      j = nlohmann::json::parse(text);
      error = j["error"].get<std::string>();
      summary.geometry = "axisymmetric";
      summary.time_s = j["time_s"].get<std::vector<double>>();
      summary.depth_m = j["depth_m"].get<std::vector<double>>();
      summary.force_N = j["force_N"].get<std::vector<double>>();
      summary.peak_force_N = j["peak_force_N"].get<double>();
      summary.n_dofs = j["n_dofs"].get<std::size_t>();
      summary.wall_time_s = j["wall_time_s"].get<double>();
      for (const auto& e : j["punctures"]) {
        PunctureEvent p;
        p.layer = e[0].get<int>();
        p.layer_name = e[1].get<std::string>();
        p.depth_m = e[2].get<double>();
        p.force_N = e[3].get<double>();
        p.force_after_N = e[4].get<double>();
        p.time_s = e[5].get<double>();
        summary.punctures.push_back(p);
      }
    }
  }
  if (!error.empty()) throw std::runtime_error(error);
  return summary;
}

}  // namespace puncture::fem
