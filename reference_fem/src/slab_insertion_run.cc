// slab_insertion_run.cc: the 3D reference's insertion run (SlabInsertionRun,
// slab_insertion_run.hpp), read top-down as the algorithm: build the slab and
// the solver, then for every load step advance the tip (cutting a sub-step
// that fails, bisecting toward a puncture), detect the puncture, open the hole
// and release the needle (spring-back), record; then write (what it records
// and writes: slab_insertion_output.cc). Only the 3D branch of
// run_needle_insertion (needle_insertion.cc) runs it.

#include <deal.II/base/mpi.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/manifold_lib.h>
#include <deal.II/grid/tria.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include <puncture/fem/field_output.hpp>
#include <puncture/fem/finite_strain_solver.hpp>

#include "insertion_common.hpp"
#include "slab_insertion_run.hpp"

namespace puncture::fem {

using namespace dealii;

namespace {

using insertion::format_double;
using insertion::LayerState;
using slab_insertion::Node;
using slab_insertion::SlabDiscretisation;
using slab_insertion::Tria;
using slab_insertion::kBase;
using slab_insertion::kLateral;

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

}  // namespace

namespace {

/// The scene checks of the 3D reference; returns its discretisation.
SlabDiscretisation checked_discretisation(const Scene& scene, const FemRunOptions& options) {
  if (scene.needle.tip != "blunt")
    throw std::invalid_argument("fem: the 3d reference models a flat (blunt) punch only; needle tip '" +
                                scene.needle.tip + "' needs geometry axisymmetric");
  for (const Layer& l : scene.layers)
    if (l.puncture.kind == PunctureCriterion::Kind::FractureEnergy)
      throw std::invalid_argument("fem: the 3d reference has no fracture_energy criterion (layer '" + l.name +
                                  "'); use geometry axisymmetric");
  insertion::check_insertion(scene);
  if (!(scene.fem.load_step_m > 0.0)) throw std::invalid_argument("fem: load_step_m must be > 0");
  if (options.spring_back_stages < 1) throw std::invalid_argument("fem: spring_back_stages must be >= 1");
  const SlabDiscretisation d{insertion::element_degree(scene, options), insertion::refinement_level(scene, options)};
  if (d.degree != 1 && d.degree != 2) throw std::invalid_argument("fem: element degree must be 1 or 2");
  if (d.refinement < 0 || d.refinement > 4) throw std::invalid_argument("fem: refinement must lie in 0..4");
  return d;
}

/// The deepest tip position: the target depth, within the slab, or the option's stop depth.
double final_tip_depth(const Scene& scene, const FemRunOptions& options) {
  double final_depth = std::min(scene.insertion.target_depth_m, scene.total_thickness_m());
  if (options.stop_depth_m > 0.0) final_depth = std::min(final_depth, options.stop_depth_m);
  return final_depth;
}

/// The output directory, created (by rank 0) if files are to be written.
std::filesystem::path prepared_output_dir(const FemRunOptions& options, bool root, MPI_Comm comm) {
  const std::filesystem::path out_dir(options.output_dir);
  if (options.write_files) {
    if (options.output_dir.empty()) throw std::invalid_argument("fem: output_dir is empty");
    if (root) std::filesystem::create_directories(out_dir);
    MPI_Barrier(comm);
  }
  return out_dir;
}

/// The scene's slab, distributed over `comm`.
std::unique_ptr<Tria> slab_triangulation(const Scene& scene, const FemRunOptions& options, int refinement,
                                         MPI_Comm comm) {
  auto tria = std::make_unique<Tria>(comm);
  build_slab_triangulation(scene, options.mesh, refinement, *tria);
  return tria;
}

/// Per layer its (long-term) law: a viscoelastic layer's modulus relaxed by g_inf when the
/// scene gives the instantaneous one (insertion_common.hpp).
std::vector<LayerMaterial> layer_materials(const Scene& scene) {
  std::vector<LayerMaterial> materials;
  for (const auto& layer : scene.layers) materials.push_back(insertion::long_term_material(layer.material));
  return materials;
}

/// Per layer its Prony series (empty: elastic), on the law layer_materials gives.
std::vector<std::vector<PronyTerm>> layer_prony_terms(const Scene& scene) {
  std::vector<std::vector<PronyTerm>> terms;
  for (const auto& layer : scene.layers) terms.push_back(insertion::prony_terms(layer.material.viscoelastic));
  return terms;
}

/// Solver settings from the options: formulation, Newton, linear solver
/// (sparse direct up to direct_solver_max_dofs with "auto").
SolverSettings solver_settings(const Scene& scene, const FemRunOptions& options, int degree, const Tria& tria) {
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
  return settings;
}

}  // namespace

namespace slab_insertion {

NeedlePath::NeedlePath(const meshing::InclinedPath& path) {
  const Eigen::Vector3d direction = meshing::path_direction(path);
  for (unsigned c = 0; c < 3; ++c) d[c] = direction[c];
  const double a = path.angle_rad, b = path.azimuth_rad;
  axis_cosine = std::cos(a);
  const double sin_a = std::sin(a), cos_b = std::cos(b), sin_b = std::sin(b);
  e1[0] = axis_cosine * cos_b, e1[1] = axis_cosine * sin_b, e1[2] = sin_a;
  e2[0] = -sin_b, e2[1] = cos_b, e2[2] = 0.0;
}

SlabInsertionRun::SlabInsertionRun(const Scene& scene, const FemRunOptions& options, MPI_Comm comm)
    : scene_(scene),
      options_(options),
      comm_(comm),
      root_(Utilities::MPI::this_mpi_process(comm) == 0),
      disc_(checked_discretisation(scene, options)),
      n_layers_(scene.layers.size()),
      needle_radius_(scene.needle.radius_m),
      path_(meshing::inclined_path_of(scene)),
      thickness_(scene.total_thickness_m()),
      tol_(1e-9 * std::max(thickness_, scene.sample.diameter_m)),
      speed_(scene.insertion.speed_m_per_s),
      start_height_(scene.insertion.start_height_m),
      final_depth_(final_tip_depth(scene, options)),
      out_dir_(prepared_output_dir(options, root_, comm)),
      tria_(slab_triangulation(scene, options, disc_.refinement, comm)),
      settings_(solver_settings(scene, options, disc_.degree, *tria_)),
      solver_(*tria_, layer_materials(scene), settings_),
      states_(n_layers_, LayerState::Untouched),
      load_step_(scene.fem.load_step_m),
      resolution_(options.puncture_depth_resolution_m > 0.0 ? options.puncture_depth_resolution_m
                                                             : load_step_ / 4.0),
      n_steps_(std::max(1, int(std::ceil((final_depth_ + start_height_) / load_step_ - 1e-9)))),
      vtu_stride_(std::max(1, n_steps_ / std::max(1, options.max_vtu_frames))),
      depth_(-start_height_) {
  solver_.set_viscoelastic_layers(layer_prony_terms(scene));
  solver_.setup();
  describe_model();
  find_node_sets();
  if (options.write_files && options.write_vtu)
    fields_ = std::make_unique<FieldOutputSeries>(out_dir_, "fem_fields", comm);
}

// Fills the model part of the summary and logs it.
void SlabInsertionRun::describe_model() {
  summary_.n_dofs = solver_.n_dofs();
  summary_.n_cells = tria_->n_global_active_cells();
  summary_.n_ranks = Utilities::MPI::n_mpi_processes(comm_);
  summary_.degree = disc_.degree;
  summary_.refinement = disc_.refinement;
  // The mesh study of this model (results/fem_mesh_convergence.md): on the
  // default slab with a flat punch, Q1 without refinement gives an indentation
  // force 9.7 % above one uniform refinement (which matches an independent
  // quadratic-element solution within 0.1 %); more sectors alone do not cure it.
  if (disc_.degree == 1 && disc_.refinement == 0)
    summary_.warnings.push_back(
        "mesh: the 3D reference with Q1 elements and no refinement is about 10 % too stiff at small indentation "
        "(results/fem_mesh_convergence.md); run with --refinement 1 (about 8 times the unknowns) for a force within "
        "about 1 % of the converged value");
  std::ostringstream s;
  s << "fem: scene '" << scene_.name << "', " << summary_.n_cells << " cells, Q" << disc_.degree << " ("
    << options_.formulation << "), " << summary_.n_dofs << " dofs, "
    << (settings_.direct_linear_solver ? "MUMPS" : "CG+AMG") << ", " << summary_.n_ranks << " rank(s)";
  log(s.str());
  if (root_)
    for (const auto& w : summary_.warnings) std::cerr << "warning: " << w << std::endl;
}

// Base and lateral surface held (u = 0); the nodes of each layer's top
// interface, and those of them under the needle.
void SlabInsertionRun::find_node_sets() {
  VectorTools::interpolate_boundary_values(solver_.dof_handler(), kBase, Functions::ZeroFunction<3>(3), fixed_);
  VectorTools::interpolate_boundary_values(solver_.dof_handler(), kLateral, Functions::ZeroFunction<3>(3), fixed_);
  nodes_ = group_nodes(solver_.locally_relevant_dof_points(), thickness_);
  interface_z_.resize(n_layers_);
  for (std::size_t i = 0; i < n_layers_; ++i) interface_z_[i] = -scene_.layer_top_depth_m(i);
  interface_nodes_.resize(n_layers_);
  tip_nodes_.resize(n_layers_);
  for (std::size_t n = 0; n < nodes_.size(); ++n)
    for (std::size_t i = 0; i < n_layers_; ++i)
      if (std::abs(nodes_[n].X[2] - interface_z_[i]) < tol_) {
        interface_nodes_[i].push_back(n);
        if (path_.distance(nodes_[n].X) <= needle_radius_ * (1.0 + 1e-6)) tip_nodes_[i].push_back(n);
      }
}

// The algorithm: from the start height to the final depth, load step by load
// step, advance the tip (with punctures on the way), then record the step.
// The outputs are written also when the run fails.
FemRunSummary SlabInsertionRun::run() {
  record_row(depth_, 0.0, 1.0, 0.0);
  write_frame(depth_);
  try {
    for (int step = 1; step <= n_steps_; ++step) {
      advance_to(std::min(-start_height_ + step * load_step_, final_depth_));
      record_load_step(step);
      if (options_.on_step) options_.on_step(depth_, static_cast<double>(step) / n_steps_);
    }
  } catch (const std::exception& e) {
    write_outputs("failed", e.what());
    throw std::runtime_error(e.what());
  }
  write_outputs("completed", "");
  summary_.wall_time_s = wall_timer_.wall_time();
  log("fem: done in " + format_double(summary_.wall_time_s, 4) + " s, " + std::to_string(summary_.load_steps) +
      " load steps, " + std::to_string(summary_.newton_iterations) + " Newton iterations, peak force " +
      format_double(summary_.peak_force_N, 5) + " N");
  return summary_;
}

// Advances the tip to `step_target` in sub-steps: a sub-step whose solve
// fails is halved; one after which the pressed layer's criterion holds is
// undone and bisected until the crossing is within the resolution; there the
// layer is punctured.
void SlabInsertionRun::advance_to(double step_target) {
  double increment = step_target - depth_;
  while (depth_ < step_target - 1e-12 * load_step_) {
    const double trial_depth = next_trial_depth(step_target, increment);
    const double advance = trial_depth - depth_;
    const SubStepStart start = sub_step_start();
    const double predictor_scale =
        predictor_valid_ && last_advance_ > 0.0 ? std::min(2.0, advance / last_advance_) : 0.0;
    NewtonReport report;
    if (!solve_at(trial_depth, report, predictor_scale)) {
      increment = cut_sub_step(start, trial_depth, advance, report);
      continue;
    }
    increment = std::min(2.0 * advance, load_step_);
    const bool in_contact = accept_sub_step(trial_depth, advance);
    if (current_layer_ >= n_layers_ || !in_contact) continue;
    const PunctureCheck check = check_puncture();
    if (!check.breaks) continue;
    if (advance > resolution_ * (1.0 + 1e-9)) {
      undo_for_bisection(start);
      continue;
    }
    puncture_current_layer(check.force_N, check.stretch);
  }
}

// The next sub-step's depth: `increment` further (at most to the step's
// target), or half-way toward a known crossing (the last part taken whole).
double SlabInsertionRun::next_trial_depth(double step_target, double increment) const {
  double trial_depth = std::min(depth_ + increment, step_target);
  if (std::isfinite(crossing_upper_)) {
    const double remaining = crossing_upper_ - depth_;
    trial_depth = std::min(trial_depth, remaining <= resolution_ * (1.0 + 1e-9) ? crossing_upper_
                                                                                : depth_ + 0.5 * remaining);
  }
  return trial_depth;
}

// The state a sub-step starts from.
SubStepStart SlabInsertionRun::sub_step_start() const {
  return {depth_, last_advance_, predictor_valid_, contact_, states_, solver_.snapshot()};
}

// A failed solve: back to the contact set before it, half the sub-step
// (returned); stops with an error below 1/256 of the load step.
double SlabInsertionRun::cut_sub_step(const SubStepStart& start, double trial_depth, double advance,
                                      const NewtonReport& report) {
  contact_ = start.contact;
  solution_is_stale_ = true;
  const double increment = 0.5 * advance;
  ++summary_.step_cuts;
  log("  step cut at depth " + format_double(trial_depth * 1e3, 6) + " mm: " + report.failure);
  if (increment < load_step_ / 256.0)
    throw std::runtime_error("fem: cannot continue at depth " + format_double(depth_ * 1e3, 6) + " mm: " +
                             report.failure + " even with load step " + format_double(increment * 1e3, 4) + " mm");
  return increment;
}

// A converged sub-step: the tip is at `trial_depth` (the viscoelastic layers'
// history committed there); the layer it touches is pressed. Returns whether the needle touches the tissue.
bool SlabInsertionRun::accept_sub_step(double trial_depth, double advance) {
  solver_.commit_time_step();
  depth_ = trial_depth;
  ++summary_.load_steps;
  if (trial_depth == crossing_upper_) crossing_upper_ = std::numeric_limits<double>::infinity();
  const bool in_contact = any_contact();
  if (current_layer_ < n_layers_ && in_contact) states_[current_layer_] = LayerState::Pressed;
  predictor_valid_ = in_contact;
  last_advance_ = advance;
  return in_contact;
}

// The pressed layer's puncture criterion: critical needle force or critical
// maximum principal stretch at the tip.
PunctureCheck SlabInsertionRun::check_puncture() {
  const auto& crit = scene_.layers[current_layer_].puncture;
  const double force = needle_force();
  const double stretch = tip_stretch(current_layer_);
  const bool breaks = crit.kind == PunctureCriterion::Kind::CriticalForce ? force >= crit.critical_force_N
                                                                           : stretch >= crit.critical_stretch;
  return {force, stretch, breaks};
}

// The criterion holds after a sub-step longer than the resolution: undo it
// and bisect toward the crossing.
void SlabInsertionRun::undo_for_bisection(const SubStepStart& start) {
  crossing_upper_ = depth_;
  solver_.restore(start.snapshot);
  contact_ = start.contact;
  states_ = start.states;
  depth_ = start.depth_m;
  last_advance_ = start.last_advance_m;
  predictor_valid_ = start.predictor_valid;
  solution_is_stale_ = false;
  ++summary_.bisections;
}

// Punctures the current layer at this depth: record the state before, open
// the hole along the needle path, release the needle and let the tissue
// spring back, record the state after.
void SlabInsertionRun::puncture_current_layer(double force, double stretch) {
  crossing_upper_ = std::numeric_limits<double>::infinity();
  predictor_valid_ = false;
  const std::size_t layer = current_layer_;
  PunctureEvent event = record_before_puncture(layer, force, stretch);
  open_hole(layer);
  release_needle(layer, force);
  spring_back(event.layer_name);
  record_after_puncture(layer, std::move(event));
}

// Removes the layer's material along the needle path (cells with centre
// inside the needle radius become void; their internal force is kept as a
// frozen load for the spring-back homotopy).
void SlabInsertionRun::open_hole(std::size_t layer) {
  solver_.remove_cells(
      [&](const FiniteStrainSolver::CellIterator& cell) {
        const Point<3> c = cell->center();
        return cell->material_id() == layer && path_.distance(c) < needle_radius_;
      },
      /*release_gradually=*/true);
  states_[layer] = LayerState::Punctured;
}

// Releases the contact set: its nodes hang on anchor springs of 100x the
// contact patch stiffness per node; the tip goes on to the next layer.
void SlabInsertionRun::release_needle(std::size_t layer, double force) {
  const double indentation = std::max(depth_ - scene_.layer_top_depth_m(layer), 1e-3 * needle_radius_);
  const std::size_t n_released = Utilities::MPI::sum(contact_.size(), comm_);
  const double k0 = 100.0 * std::abs(force) / (indentation * std::max<std::size_t>(1, n_released));
  std::map<types::global_dof_index, double> springs;
  for (const auto& [n, hold] : contact_)
    for (unsigned c = 0; c < 3; ++c) springs[nodes_[n].dof[c]] = k0;
  contact_.clear();
  current_layer_ = layer + 1;
  solver_.set_anchor_springs(springs);
}

// The spring-back as a homotopy in lambda = 1 -> 0 (see the header): the
// removed cells' frozen load is lambda x its value, the anchor springs
// lambda^2 x theirs; a failed stage is retried with half the lambda step.
void SlabInsertionRun::spring_back(const std::string& layer_name) {
  double lambda = 1.0;  // last converged stage
  double d_lambda = 1.0 / options_.spring_back_stages;
  while (lambda > 0.0) {
    const double next = lambda - d_lambda < 1e-3 ? 0.0 : lambda - d_lambda;
    solver_.set_released_force_fraction(next);
    solver_.set_anchor_spring_scale(next * next);
    const auto stage_snapshot = solver_.snapshot();
    const auto stage_contact = contact_;
    solution_is_stale_ = true;
    NewtonReport report;
    const bool ok = solve_at(depth_, report, 0.0);
    ++summary_.spring_back_stages;
    if (!ok) {
      solver_.restore(stage_snapshot);
      contact_ = stage_contact;
      d_lambda *= 0.5;
      if (d_lambda < 1.0 / (64.0 * options_.spring_back_stages))
        throw std::runtime_error("fem: spring-back after the puncture of " + layer_name +
                                 " did not converge: " + report.failure);
      continue;
    }
    solver_.commit_time_step();  // the stage's state (same instant) is the viscoelastic layers' history
    lambda = next;
  }
  solver_.set_anchor_springs({});
}

// Solves at (vertical) tip depth `depth`, joining reached nodes until none
// is left. predictor_scale: start the first pass from u + scale x the last increment.
bool SlabInsertionRun::solve_at(double depth, NewtonReport& report, double predictor_scale) {
  const double path_tip = depth / path_.axis_cosine;  // the tip's coordinate along the path
  // The time this solve advances the viscoelastic layers: the vertical depth moves at v cos a
  // (0 for a spring-back stage, at the same depth).
  solver_.set_time_step((depth - depth_) / (speed_ * path_.axis_cosine));
  for (int pass = 0; pass < 8; ++pass) {
    const bool joined = join_reached_nodes(path_tip);
    // Nothing to do, unless viscoelastic layers relax while the tip moves.
    if (!joined && !solution_is_stale_ && !any_contact() && !solver_.has_viscoelastic_layers()) return true;
    apply_targets(path_tip);
    const Timer solve_timer;
    report = solver_.solve_step(pass == 0 && !joined ? predictor_scale : 0.0);
    summary_.solve_time_s += solve_timer.wall_time();
    summary_.newton_iterations += report.iterations;
    summary_.linear_iterations += report.linear_iterations;
    records_.newton_log << "depth " << format_double(depth * 1e3, 6) << " mm, contact nodes " << contact_.size()
                        << (solver_.has_anchor_springs() ? ", spring-back stage" : "")
                        << (report.converged ? "" : ", FAILED: " + report.failure) << "\n";
    for (const auto& line : report.table) {
      records_.newton_log << "  " << line << "\n";
      log("      " + line);
    }
    if (!report.converged) return false;
    solution_is_stale_ = false;
    bool more = false;
    if (current_layer_ < n_layers_)
      for (const std::size_t n : tip_nodes_[current_layer_])
        if (!contact_.count(n) && along_path(nodes_[n]) <= path_tip + tol_) more = true;
    if (Utilities::MPI::max(more ? 1 : 0, comm_) == 0) return true;
  }
  return true;
}

// Collective: does any rank hold contact nodes? (A rank may own none of them.)
bool SlabInsertionRun::any_contact() const { return Utilities::MPI::max(contact_.empty() ? 0 : 1, comm_) == 1; }

// A node's current position along the path (m; the tip is at path_tip).
double SlabInsertionRun::along_path(const Node& n) const {
  Tensor<1, 3> x;
  for (unsigned c = 0; c < 3; ++c) x[c] = n.X[c] + u_of(n, c);
  return x * path_.d;
}

// Prescribes the held boundary and the contact nodes: on the punch face
// (their coordinate along the path that of the tip), held across the needle.
void SlabInsertionRun::apply_targets(double path_tip) {
  std::map<types::global_dof_index, double> targets = fixed_;
  for (const auto& [n, hold] : contact_) {
    const Tensor<1, 3> u = hold + (path_tip - Tensor<1, 3>(nodes_[n].X) * path_.d) * path_.d;
    for (unsigned c = 0; c < 3; ++c) targets[nodes_[n].dof[c]] = u[c];
  }
  solver_.set_prescribed_displacements(std::move(targets));
}

// Nodes of the current interface the tip has reached (their coordinate
// along the path <= the tip's) join the contact set; collective: did any join?
bool SlabInsertionRun::join_reached_nodes(double path_tip) {
  bool joined = false;
  if (current_layer_ >= n_layers_) return false;
  for (const std::size_t n : tip_nodes_[current_layer_]) {
    if (contact_.count(n)) continue;
    if (along_path(nodes_[n]) <= path_tip + tol_) {
      Tensor<1, 3> u;
      for (unsigned c = 0; c < 3; ++c) u[c] = u_of(nodes_[n], c);
      contact_[n] = u - (u * path_.d) * path_.d;
      joined = true;
    }
  }
  return Utilities::MPI::max(joined ? 1 : 0, comm_) == 1;
}

// The tissue's force on the needle: the reactions at the contact nodes are
// what the needle applies to the tissue; the tissue pushes back with the
// opposite force, whose part along -d resists the insertion (> 0).
NeedleForce SlabInsertionRun::needle_force_vector() const {
  Tensor<1, 3> reaction;
  for (unsigned c = 0; c < 3; ++c) {
    std::vector<types::global_dof_index> dofs;
    for (const auto& [n, hold] : contact_) dofs.push_back(nodes_[n].dof[c]);
    reaction[c] = solver_.sum_of_residual(dofs);
  }
  const double axial = reaction * path_.d;
  const Tensor<1, 3> across = reaction - (reaction * path_.d) * path_.d;
  return {axial == 0.0 ? 0.0 : axial, across.norm()};  // no "-0" in the CSV
}

// Maximum principal stretch in the layer's cells touching the needle's patch of its top.
double SlabInsertionRun::tip_stretch(std::size_t layer) const {
  return solver_.max_principal_stretch([&](const FiniteStrainSolver::CellIterator& cell) {
    if (cell->material_id() != layer) return false;
    for (unsigned v = 0; v < 8; ++v) {
      const Point<3>& p = cell->vertex(v);
      if (std::abs(p[2] - interface_z_[layer]) < tol_ && path_.distance(p) <= needle_radius_ * (1.0 + 1e-6))
        return true;
    }
    return false;
  });
}

}  // namespace slab_insertion

}  // namespace puncture::fem
