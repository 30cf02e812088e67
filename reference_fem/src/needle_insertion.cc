// needle_insertion.cc: the needle-insertion problem on the layered slab (see
// needle_insertion.hpp). Reads top-down as the algorithm: build the slab, set
// up the solver, then for every load step advance the tip, solve, check the
// puncture criterion, record.
#include <puncture/fem/needle_insertion.hpp>

#include <deal.II/base/mpi.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/manifold_lib.h>
#include <deal.II/grid/tria.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include <puncture/fem/field_output.hpp>
#include <puncture/fem/finite_strain_solver.hpp>

namespace puncture::fem {

using namespace dealii;

namespace {

constexpr types::boundary_id kTop = 0, kBase = 1, kLateral = 2;

enum class LayerState { untouched, pressed, punctured };
const char* to_string(LayerState s) {
  switch (s) {
    case LayerState::untouched: return "untouched";
    case LayerState::pressed: return "pressed";
    case LayerState::punctured: return "punctured";
  }
  return "?";
}

/// A node (support point) with its three displacement dofs.
struct Node {
  Point<3> X;
  types::global_dof_index dof[3] = {0, 0, 0};
  double r() const { return std::hypot(X[0], X[1]); }
};

/// Groups the locally relevant dof points into nodes, keyed by position.
std::vector<Node> group_nodes(const std::vector<DofPoint>& points, double length_scale) {
  std::map<std::array<long long, 3>, Node> by_key;
  const double q = 1e-9 * length_scale;
  for (const auto& p : points) {
    const std::array<long long, 3> key = {std::llround(p.X[0] / q), std::llround(p.X[1] / q),
                                          std::llround(p.X[2] / q)};
    Node& n = by_key[key];
    n.X = p.X;
    n.dof[p.component] = p.dof;
  }
  std::vector<Node> out;
  out.reserve(by_key.size());
  for (auto& [k, n] : by_key) out.push_back(n);
  return out;
}

struct Row {
  double time_s, depth_m, velocity_m_per_s, force_N;
  double tip_stretch;  ///< max principal stretch at the tip in the pressed layer (1: no contact)
  std::vector<LayerState> states;
};

std::string format_double(double v, int precision = 9) {
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

}  // namespace

void build_slab_triangulation(const Scene& scene, const meshing::SlabMeshOptions& options,
                              int refinement, parallel::distributed::Triangulation<3>& tria) {
  const meshing::HexMesh mesh = meshing::build_layered_cylinder_mesh(scene, options);
  std::vector<Point<3>> vertices;
  vertices.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices) vertices.emplace_back(v.x(), v.y(), v.z());
  std::vector<CellData<3>> cells(mesh.cells.size());
  for (std::size_t c = 0; c < mesh.cells.size(); ++c) {
    for (unsigned i = 0; i < 8; ++i) cells[c].vertices[i] = mesh.cells[c][i];
    cells[c].material_id = static_cast<types::material_id>(mesh.material_id[c]);
  }
  GridTools::consistently_order_cells(cells);
  tria.create_triangulation(vertices, cells, SubCellData());

  const double thickness = scene.total_thickness_m();
  const double tol = 1e-9 * std::max(thickness, scene.sample.diameter_m);
  for (const auto& cell : tria.active_cell_iterators())
    for (const auto& face : cell->face_iterators()) {
      if (!face->at_boundary()) continue;
      const double z = face->center()[2];
      if (z > -tol)
        face->set_boundary_id(kTop);
      else if (z < -thickness + tol)
        face->set_boundary_id(kBase);
      else {
        face->set_boundary_id(kLateral);
        face->set_all_manifold_ids(1);
      }
    }
  tria.set_manifold(1, CylindricalManifold<3>(2));
  if (refinement > 0) tria.refine_global(refinement);
}

namespace {
FemRunSummary run_needle_insertion_3d(const Scene& scene, const FemRunOptions& options, MPI_Comm comm);
}  // namespace

FemRunSummary run_needle_insertion(const Scene& scene, const FemRunOptions& options, MPI_Comm comm) {
  std::string geometry = scene.fem.geometry;
  if (geometry == "auto") geometry = scene.needle.tip == "blunt" ? "3d" : "axisymmetric";
  if (geometry == "axisymmetric") return run_axisymmetric_insertion(scene, options, comm);
  if (scene.needle.tip != "blunt")
    throw std::invalid_argument("fem: the 3d reference models a flat (blunt) punch only; needle tip '" +
                                scene.needle.tip + "' needs geometry axisymmetric");
  for (const Layer& l : scene.layers)
    if (l.puncture.kind == PunctureCriterion::Kind::FractureEnergy)
      throw std::invalid_argument("fem: the 3d reference has no fracture_energy criterion (layer '" + l.name +
                                  "'); use geometry axisymmetric");
  return run_needle_insertion_3d(scene, options, comm);
}

namespace {
FemRunSummary run_needle_insertion_3d(const Scene& scene, const FemRunOptions& options, MPI_Comm comm) {
  const auto wall_start = std::chrono::steady_clock::now();
  const bool root = Utilities::MPI::this_mpi_process(comm) == 0;
  auto log = [&](const std::string& s) {
    if (root && options.verbose) std::cout << s << std::endl;
  };

  // ---- 0. What the scene asks for -------------------------------------------------
  if (scene.layers.empty()) throw std::invalid_argument("fem: the scene has no layers");
  if (scene.insertion.angle_deg != 0.0)
    throw std::invalid_argument("fem: only insertions along the sample axis (angle_deg = 0) are modelled");
  if (!(scene.insertion.speed_m_per_s > 0.0))
    throw std::invalid_argument("fem: insertion speed must be > 0");
  if (!(scene.fem.load_step_m > 0.0)) throw std::invalid_argument("fem: load_step_m must be > 0");
  if (options.spring_back_stages < 1) throw std::invalid_argument("fem: spring_back_stages must be >= 1");
  const int degree = options.degree_override > 0 ? options.degree_override : scene.fem.element_degree;
  const int refinement = options.refinement_override >= 0 ? options.refinement_override : scene.fem.refinement;
  if (degree != 1 && degree != 2) throw std::invalid_argument("fem: element degree must be 1 or 2");
  if (refinement < 0 || refinement > 4) throw std::invalid_argument("fem: refinement must lie in 0..4");
  const std::size_t n_layers = scene.layers.size();
  const double needle_radius = scene.needle.radius_m;
  const double thickness = scene.total_thickness_m();
  const double tol = 1e-9 * std::max(thickness, scene.sample.diameter_m);
  const double speed = scene.insertion.speed_m_per_s;
  const double start_height = scene.insertion.start_height_m;
  double final_depth = std::min(scene.insertion.target_depth_m, thickness);
  if (options.stop_depth_m > 0.0) final_depth = std::min(final_depth, options.stop_depth_m);
  const std::filesystem::path out_dir(options.output_dir);
  if (options.write_files) {
    if (options.output_dir.empty()) throw std::invalid_argument("fem: output_dir is empty");
    if (root) std::filesystem::create_directories(out_dir);
    MPI_Barrier(comm);
  }

  // ---- 1. Geometry and material from the same scene --------------------------------
  parallel::distributed::Triangulation<3> tria(comm);
  build_slab_triangulation(scene, options.mesh, refinement, tria);
  std::vector<LayerMaterial> materials;
  for (const auto& layer : scene.layers) materials.emplace_back(layer.material);

  SolverSettings settings;
  settings.degree = degree;
  settings.formulation = options.formulation == "one_field" ? VolumetricFormulation::one_field
                                                            : VolumetricFormulation::three_field;
  if (options.formulation != "one_field" && options.formulation != "three_field")
    throw std::invalid_argument("fem: formulation must be three_field or one_field");
  settings.max_newton_iterations = scene.fem.max_newton_iterations;
  settings.newton_tolerance = scene.fem.newton_tolerance;
  settings.max_stalled_iterations = 4;  // the load step is cut instead (see below)
  settings.verbose = false;
  if (options.linear_solver != "auto" && options.linear_solver != "direct" && options.linear_solver != "iterative")
    throw std::invalid_argument("fem: linear_solver must be auto, direct or iterative");
  const std::size_t approx_dofs = 3 * tria.n_global_active_cells() * degree * degree * degree;
  settings.direct_linear_solver =
      options.linear_solver == "direct" ||
      (options.linear_solver == "auto" && approx_dofs <= options.direct_solver_max_dofs);
  FiniteStrainSolver solver(tria, materials, settings);
  solver.setup();

  FemRunSummary summary;
  summary.n_dofs = solver.n_dofs();
  summary.n_cells = tria.n_global_active_cells();
  summary.n_ranks = Utilities::MPI::n_mpi_processes(comm);
  summary.degree = degree;
  summary.refinement = refinement;
  {
    std::ostringstream s;
    s << "fem: scene '" << scene.name << "', " << summary.n_cells << " cells, Q" << degree << " ("
       << options.formulation << "), " << summary.n_dofs << " dofs, "
      << (settings.direct_linear_solver ? "MUMPS" : "CG+AMG") << ", " << summary.n_ranks << " rank(s)";
    log(s.str());
  }

  // ---- 2. Boundary conditions and the node sets ------------------------------------
  std::map<types::global_dof_index, double> fixed;
  VectorTools::interpolate_boundary_values(solver.dof_handler(), kBase, Functions::ZeroFunction<3>(3), fixed);
  VectorTools::interpolate_boundary_values(solver.dof_handler(), kLateral, Functions::ZeroFunction<3>(3), fixed);

  const std::vector<Node> nodes = group_nodes(solver.locally_relevant_dof_points(), thickness);
  std::vector<double> interface_z(n_layers);
  for (std::size_t i = 0; i < n_layers; ++i) interface_z[i] = -scene.layer_top_depth_m(i);
  // Per layer: every node of its top interface (profiles) and those under the needle.
  std::vector<std::vector<std::size_t>> interface_nodes(n_layers), tip_nodes(n_layers);
  for (std::size_t n = 0; n < nodes.size(); ++n)
    for (std::size_t i = 0; i < n_layers; ++i)
      if (std::abs(nodes[n].X[2] - interface_z[i]) < tol) {
        interface_nodes[i].push_back(n);
        if (nodes[n].r() <= needle_radius * (1.0 + 1e-6)) tip_nodes[i].push_back(n);
      }

  // Contact state: joined node -> held lateral displacement.
  std::map<std::size_t, std::array<double, 2>> contact;
  std::vector<LayerState> states(n_layers, LayerState::untouched);
  std::size_t current_layer = 0;  // first layer not punctured

  auto u_of = [&](const Node& n, unsigned c) { return solver.displacement(n.dof[c]); };
  // Collective: does any rank hold contact nodes? (A rank may own none of them.)
  auto any_contact = [&]() { return Utilities::MPI::max(contact.empty() ? 0 : 1, comm) == 1; };

  auto apply_targets = [&](double z_tip) {
    std::map<types::global_dof_index, double> targets = fixed;
    for (const auto& [n, hold] : contact) {
      targets[nodes[n].dof[0]] = hold[0];
      targets[nodes[n].dof[1]] = hold[1];
      targets[nodes[n].dof[2]] = z_tip - nodes[n].X[2];
    }
    solver.set_prescribed_displacements(std::move(targets));
  };
  // Nodes of the current interface the tip has reached (current z >= z_tip).
  auto join_reached_nodes = [&](double z_tip) {
    bool joined = false;
    if (current_layer >= n_layers) return false;
    for (const std::size_t n : tip_nodes[current_layer]) {
      if (contact.count(n)) continue;
      if (nodes[n].X[2] + u_of(nodes[n], 2) >= z_tip - tol) {
        contact[n] = {u_of(nodes[n], 0), u_of(nodes[n], 1)};
        joined = true;
      }
    }
    return Utilities::MPI::max(joined ? 1 : 0, comm) == 1;
  };
  auto needle_force = [&]() {
    std::vector<types::global_dof_index> dofs;
    for (const auto& [n, hold] : contact) dofs.push_back(nodes[n].dof[2]);
    // The z reaction is what the needle applies to the tissue; the tissue
    // pushes back on the needle with the opposite force (upward, > 0).
    const double force = -solver.sum_of_residual(dofs);
    return force == 0.0 ? 0.0 : force;  // no "-0" in the CSV
  };
  auto tip_stretch = [&](std::size_t layer) {
    return solver.max_principal_stretch([&](const FiniteStrainSolver::CellIterator& cell) {
      if (cell->material_id() != layer) return false;
      for (unsigned v = 0; v < 8; ++v) {
        const Point<3>& p = cell->vertex(v);
        if (std::abs(p[2] - interface_z[layer]) < tol &&
            std::hypot(p[0], p[1]) <= needle_radius * (1.0 + 1e-6))
          return true;
      }
      return false;
    });
  };

  std::ostringstream newton_log;
  bool solution_is_stale = true;  // the state differs from the last solved one
  // Solves at tip depth `depth`, joining reached nodes until none is left.
  // predictor_scale: start the first pass from u + scale x the last increment.
  auto solve_at = [&](double depth, NewtonReport& report, double predictor_scale) {
    const double z_tip = -depth;
    for (int pass = 0; pass < 8; ++pass) {
      const bool joined = join_reached_nodes(z_tip);
      if (!joined && !solution_is_stale && !any_contact()) return true;  // nothing to do
      apply_targets(z_tip);
      const auto t0 = std::chrono::steady_clock::now();
      report = solver.solve_step(pass == 0 && !joined ? predictor_scale : 0.0);
      summary.solve_time_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      summary.newton_iterations += report.iterations;
      summary.linear_iterations += report.linear_iterations;
      newton_log << "depth " << format_double(depth * 1e3, 6) << " mm, contact nodes " << contact.size()
                 << (solver.has_anchor_springs() ? ", spring-back stage" : "")
                 << (report.converged ? "" : ", FAILED: " + report.failure) << "\n";
      for (const auto& line : report.table) {
        newton_log << "  " << line << "\n";
        log("      " + line);
      }
      if (!report.converged) return false;
      solution_is_stale = false;
      bool more = false;
      if (current_layer < n_layers)
        for (const std::size_t n : tip_nodes[current_layer])
          if (!contact.count(n) && nodes[n].X[2] + u_of(nodes[n], 2) >= z_tip - tol) more = true;
      if (Utilities::MPI::max(more ? 1 : 0, comm) == 0) return true;
    }
    return true;
  };

  // ---- 3. Records ----------------------------------------------------------------
  std::vector<Row> rows;
  std::ostringstream profile_csv, recovery_csv;
  profile_csv << "step,depth_mm,r_mm,uz_mm,surface\n";
  recovery_csv << "layer,phase,depth_mm,r_mm,uz_mm\n";
  // u_z(r) of a layer's top interface, averaged over nodes at the same r (rank 0 gets it).
  auto surface_profile = [&](std::size_t layer) {
    std::vector<std::pair<double, double>> local;
    const IndexSet owned = solver.dof_handler().locally_owned_dofs();
    for (const std::size_t n : interface_nodes[layer])
      if (owned.is_element(nodes[n].dof[2])) local.emplace_back(nodes[n].r(), u_of(nodes[n], 2));
    const auto all = Utilities::MPI::gather(comm, local, 0);
    std::map<long long, std::pair<double, int>> by_r;
    std::map<long long, double> r_of;
    for (const auto& part : all)
      for (const auto& [r, uz] : part) {
        const long long key = std::llround(r / (1e-7 * thickness));
        auto& acc = by_r[key];
        acc.first += uz;
        acc.second += 1;
        r_of[key] = r;
      }
    std::vector<std::pair<double, double>> profile;
    for (const auto& [key, acc] : by_r) profile.emplace_back(r_of[key], acc.first / acc.second);
    return profile;
  };
  auto record_row = [&](double depth, double force, double stretch) {
    const double time = (depth + start_height) / speed;
    rows.push_back({time, depth, speed, force, stretch, states});
    summary.time_s.push_back(time);
    summary.depth_m.push_back(depth);
    summary.force_N.push_back(force);
    if (force > summary.peak_force_N) {
      summary.peak_force_N = force;
      summary.peak_force_depth_m = depth;
    }
  };

  std::unique_ptr<FieldOutputSeries> fields;
  if (options.write_files && options.write_vtu)
    fields = std::make_unique<FieldOutputSeries>(out_dir, "fem_fields", comm);
  const double load_step = scene.fem.load_step_m;
  // Puncture depths are located by bisection to within `resolution`: a step
  // after which the criterion holds is undone and halved until it is short.
  const double resolution =
      options.puncture_depth_resolution_m > 0.0 ? options.puncture_depth_resolution_m : load_step / 4.0;
  const int n_steps = std::max(1, int(std::ceil((final_depth + start_height) / load_step - 1e-9)));
  const int vtu_stride = std::max(1, n_steps / std::max(1, options.max_vtu_frames));
  auto write_frame = [&](double depth) {
    if (!fields) return;
    const auto names = fields->write_frame(solver, (depth + start_height) / speed);
    if (root) summary.files_written.insert(summary.files_written.end(), names.begin(), names.end());
  };

  auto write_outputs = [&](const std::string& status, const std::string& error) {
    if (!options.write_files) return;
    if (fields && root) summary.files_written.push_back(fields->write_collection());
    else if (fields) fields->write_collection();
    if (!root) return;
    std::ostringstream csv;
    csv << "time_s,depth_mm,velocity_mm_per_s,force_N,tip_stretch";
    for (const auto& layer : scene.layers) csv << "," << layer.name << "_state";
    csv << "\n";
    for (const auto& r : rows) {
      csv << format_double(r.time_s) << "," << format_double(r.depth_m * 1e3) << ","
          << format_double(r.velocity_m_per_s * 1e3) << "," << format_double(r.force_N) << ","
          << format_double(r.tip_stretch, 6);
      for (const auto s : r.states) csv << "," << to_string(s);
      csv << "\n";
    }
    write_file_atomically(out_dir / "fem_force_depth.csv", csv.str());
    write_file_atomically(out_dir / "fem_surface_profile.csv", profile_csv.str());
    write_file_atomically(out_dir / "fem_recovery_profile.csv", recovery_csv.str());
    write_file_atomically(out_dir / "fem_newton_log.txt", newton_log.str());
    for (const char* f : {"fem_force_depth.csv", "fem_surface_profile.csv", "fem_recovery_profile.csv",
                          "fem_newton_log.txt", "fem_summary.json"})
      summary.files_written.push_back(f);
    summary.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    nlohmann::json j;
    j["status"] = status;
    if (!error.empty()) j["error"] = error;
    j["scene"] = scene.name;
    j["n_dofs"] = summary.n_dofs;
    j["n_cells"] = summary.n_cells;
    j["n_ranks"] = summary.n_ranks;
    j["element_degree"] = degree;
    j["refinement"] = refinement;
    j["formulation"] = options.formulation;
    j["load_step_mm"] = load_step * 1e3;
    j["final_depth_mm"] = final_depth * 1e3;
    j["note"] = "quasi-static; the FEM stops at the target depth (no dwell, no withdrawal)";
    j["peak_force_N"] = summary.peak_force_N;
    j["peak_force_depth_mm"] = summary.peak_force_depth_m * 1e3;
    j["load_steps"] = summary.load_steps;
    j["step_cuts"] = summary.step_cuts;
    j["puncture_bisections"] = summary.bisections;
    j["spring_back_stages"] = summary.spring_back_stages;
    j["puncture_depth_resolution_mm"] = resolution * 1e3;
    j["newton_iterations"] = summary.newton_iterations;
    j["linear_iterations"] = summary.linear_iterations;
    j["wall_time_s"] = summary.wall_time_s;
    j["solve_time_s"] = summary.solve_time_s;
    j["punctures"] = nlohmann::json::array();
    for (const auto& e : summary.punctures)
      j["punctures"].push_back({{"layer", e.layer}, {"name", e.layer_name}, {"depth_mm", e.depth_m * 1e3},
                                {"force_N", e.force_N}, {"force_after_N", e.force_after_N},
                                {"max_stretch", e.max_stretch}, {"time_s", e.time_s}});
    j["files"] = summary.files_written;
    write_file_atomically(out_dir / "fem_summary.json", j.dump(2) + "\n");
  };

  // ---- 4. Load stepping ------------------------------------------------------------
  double depth = -start_height;
  record_row(depth, 0.0, 1.0);
  write_frame(depth);
  int record_index = 0;
  double last_advance = 0.0;     // depth change of the last converged step in contact
  bool predictor_valid = false;  // that step pressed the current layer like the next one will
  double crossing_upper = std::numeric_limits<double>::infinity();  // criterion known to hold here
  try {
    for (int step = 1; step <= n_steps; ++step) {
      const double step_target = std::min(-start_height + step * load_step, final_depth);
      double increment = step_target - depth;
      while (depth < step_target - 1e-12 * load_step) {
        double trial_depth = std::min(depth + increment, step_target);
        if (std::isfinite(crossing_upper)) {
          // Bisecting toward a known crossing (the last part is taken whole).
          const double remaining = crossing_upper - depth;
          trial_depth = std::min(trial_depth, remaining <= resolution * (1.0 + 1e-9)
                                                  ? crossing_upper
                                                  : depth + 0.5 * remaining);
        }
        const double advance = trial_depth - depth;
        const auto contact_before = contact;
        const auto states_before = states;
        const FiniteStrainSolver::Snapshot snapshot = solver.snapshot();
        const double predictor_scale =
            predictor_valid && last_advance > 0.0 ? std::min(2.0, advance / last_advance) : 0.0;
        NewtonReport report;
        if (!solve_at(trial_depth, report, predictor_scale)) {
          contact = contact_before;
          solution_is_stale = true;
          increment = 0.5 * advance;
          ++summary.step_cuts;
          log("  step cut at depth " + format_double(trial_depth * 1e3, 6) + " mm: " + report.failure);
          if (increment < load_step / 256.0)
            throw std::runtime_error("fem: cannot continue at depth " + format_double(depth * 1e3, 6) +
                                     " mm: " + report.failure + " even with load step " +
                                     format_double(increment * 1e3, 4) + " mm");
          continue;
        }
        const double depth_before = depth;
        const double last_advance_before = last_advance;
        const bool predictor_valid_before = predictor_valid;
        depth = trial_depth;
        ++summary.load_steps;
        increment = std::min(2.0 * advance, load_step);
        if (trial_depth == crossing_upper) crossing_upper = std::numeric_limits<double>::infinity();
        const bool in_contact = any_contact();
        if (current_layer < n_layers && in_contact) states[current_layer] = LayerState::pressed;
        predictor_valid = in_contact;
        last_advance = advance;

        // Puncture criterion of the pressed layer.
        if (current_layer < n_layers && in_contact) {
          const auto& crit = scene.layers[current_layer].puncture;
          const double force = needle_force();
          const double stretch = tip_stretch(current_layer);
          const bool breaks = crit.kind == PunctureCriterion::Kind::CriticalForce
                                  ? force >= crit.critical_force_N
                                  : stretch >= crit.critical_stretch;
          if (breaks && advance > resolution * (1.0 + 1e-9)) {
            // Undo the step and bisect toward the crossing.
            crossing_upper = depth;
            solver.restore(snapshot);
            contact = contact_before;
            states = states_before;
            depth = depth_before;
            last_advance = last_advance_before;
            predictor_valid = predictor_valid_before;
            solution_is_stale = false;
            ++summary.bisections;
            continue;
          }
          if (breaks) {
            crossing_upper = std::numeric_limits<double>::infinity();
            predictor_valid = false;
            const std::size_t layer = current_layer;
            PunctureEvent event;
            event.layer = int(layer);
            event.layer_name = scene.layers[layer].name;
            event.depth_m = depth;
            event.force_N = force;
            event.max_stretch = stretch;
            event.time_s = (depth + start_height) / speed;
            record_row(depth, force, stretch);
            for (const auto& [r, uz] : surface_profile(layer))
              recovery_csv << layer << ",before," << format_double(depth * 1e3) << ","
                           << format_double(r * 1e3) << "," << format_double(uz * 1e3) << "\n";
            // Remove the layer's material along the needle path, release the tip.
            // The spring-back is a homotopy in lambda = 1 -> 0 (see the header):
            // the removed cells' frozen load is lambda x its value and the
            // released contact nodes hang on anchor springs of lambda^2 x
            // 100x the contact patch stiffness per node.
            solver.remove_cells(
                [&](const FiniteStrainSolver::CellIterator& cell) {
                  const Point<3> c = cell->center();
                  return cell->material_id() == layer && std::hypot(c[0], c[1]) < needle_radius;
                },
                /*release_gradually=*/true);
            states[layer] = LayerState::punctured;
            const double indentation = std::max(depth - scene.layer_top_depth_m(layer), 1e-3 * needle_radius);
            const std::size_t n_released = Utilities::MPI::sum(contact.size(), comm);
            const double k0 = 100.0 * std::abs(force) / (indentation * std::max<std::size_t>(1, n_released));
            std::map<types::global_dof_index, double> springs;
            for (const auto& [n, hold] : contact)
              for (unsigned c = 0; c < 3; ++c) springs[nodes[n].dof[c]] = k0;
            contact.clear();
            current_layer = layer + 1;
            solver.set_anchor_springs(springs);
            double lambda = 1.0;  // last converged stage
            double d_lambda = 1.0 / options.spring_back_stages;
            while (lambda > 0.0) {
              const double next = lambda - d_lambda < 1e-3 ? 0.0 : lambda - d_lambda;
              solver.set_released_force_fraction(next);
              solver.set_anchor_spring_scale(next * next);
              const auto stage_snapshot = solver.snapshot();
              const auto stage_contact = contact;
              solution_is_stale = true;
              NewtonReport spring_back;
              const bool ok = solve_at(depth, spring_back, 0.0);
              ++summary.spring_back_stages;
              if (!ok) {
                solver.restore(stage_snapshot);
                contact = stage_contact;
                d_lambda *= 0.5;
                if (d_lambda < 1.0 / (64.0 * options.spring_back_stages))
                  throw std::runtime_error("fem: spring-back after the puncture of " + event.layer_name +
                                           " did not converge: " + spring_back.failure);
                continue;
              }
              lambda = next;
            }
            solver.set_anchor_springs({});
            const bool touching = any_contact();
            event.force_after_N = touching ? needle_force() : 0.0;
            if (current_layer < n_layers && touching) states[current_layer] = LayerState::pressed;
            for (const auto& [r, uz] : surface_profile(layer))
              recovery_csv << layer << ",after," << format_double(depth * 1e3) << ","
                           << format_double(r * 1e3) << "," << format_double(uz * 1e3) << "\n";
            summary.punctures.push_back(event);
            log("  PUNCTURE of " + event.layer_name + " at depth " + format_double(depth * 1e3, 5) +
                " mm, force " + format_double(force, 5) + " N -> " + format_double(event.force_after_N, 5) +
                " N");
            const double stretch_after =
                current_layer < n_layers && touching ? tip_stretch(current_layer) : 1.0;
            record_row(depth, event.force_after_N, stretch_after);
            write_frame(depth);
          }
        }
      }
      const bool touching = any_contact();
      const double force = touching ? needle_force() : 0.0;
      const double stretch = touching && current_layer < n_layers ? tip_stretch(current_layer) : 1.0;
      if (!std::isfinite(force)) throw std::runtime_error("fem: non-finite needle force");
      // (A puncture at the end of the step already recorded this depth.)
      if (!(rows.back().depth_m == depth && rows.back().force_N == force)) record_row(depth, force, stretch);
      ++record_index;
      if (current_layer < n_layers)
        for (const auto& [r, uz] : surface_profile(current_layer))
          profile_csv << record_index << "," << format_double(depth * 1e3) << "," << format_double(r * 1e3)
                      << "," << format_double(uz * 1e3) << "," << scene.layers[current_layer].name << "\n";
      if (step % vtu_stride == 0 || step == n_steps) write_frame(depth);
      std::ostringstream s;
      s << "  step " << std::setw(4) << step << "/" << n_steps << "  depth " << std::fixed << std::setprecision(3)
        << depth * 1e3 << " mm  force " << std::setprecision(5) << force << " N  tip stretch "
        << std::setprecision(4) << stretch << "  contact " << contact.size()
        << "  newton(total) " << summary.newton_iterations;
      log(s.str());
    }
  } catch (const std::exception& e) {
    write_outputs("failed", e.what());
    throw std::runtime_error(e.what());
  }
  write_outputs("completed", "");
  summary.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  log("fem: done in " + format_double(summary.wall_time_s, 4) + " s, " + std::to_string(summary.load_steps) +
      " load steps, " + std::to_string(summary.newton_iterations) + " Newton iterations, peak force " +
      format_double(summary.peak_force_N, 5) + " N");
  return summary;
}

}  // namespace

}  // namespace puncture::fem
