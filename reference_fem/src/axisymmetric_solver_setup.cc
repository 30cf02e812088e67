// axisymmetric_solver_setup.cc: the AxisymmetricSolver's mesh, boundary ids, degrees of
// freedom, crack pairs, contact nodes, sparsity and state (axisymmetric_solver.hpp).
#include <puncture/fem/axisymmetric_solver.hpp>
#include <puncture/fem/kinematics.hpp>

#include <deal.II/base/function.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <iomanip>
#include <exception>
#include <iostream>
#include <thread>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "axisymmetric_cell.hpp"

namespace puncture::fem {
using namespace dealii;
using namespace axisymmetric_cell;

namespace {

enum BoundaryId : types::boundary_id {
  kTop = 0, kBase = 1, kLateral = 2, kAxis = 3, kCrackCore = 4, kCrackOuter = 5, kChannelFloor = 6
};

/// Lumped (Newton-Cotes) weight of the face node at p on a face of the given
/// length from its vertex v0: 1/2 (Q1); 1/6, 4/6, 1/6 (Q2).
double newton_cotes_weight(unsigned degree, const Point<2>& p, const Point<2>& v0, double length) {
  const double s = (p - v0).norm() / length;
  if (degree == 1) return 0.5;
  return (s < 0.25 || s > 0.75) ? 1.0 / 6.0 : 4.0 / 6.0;
}

/// A face by its centre (rounded to 1e3 x tol), to find the other side of a crack face.
std::pair<long, long> face_key(const Point<2>& p, double tol) {
  return std::make_pair(std::lround(p[0] / tol * 1e-3), std::lround(p[1] / tol * 1e-3));
}

/// The face's Z dof at the support point p (the last such dof; 0 if none).
unsigned z_dof_at(const FiniteElement<2>& fe, const std::vector<types::global_dof_index>& face_dofs,
                  const std::vector<Point<2>>& support, const Point<2>& p, double tol) {
  unsigned dz = 0;
  for (unsigned j = 0; j < face_dofs.size(); ++j)
    if (fe.face_system_to_component_index(j).first == 1 && support[face_dofs[j]].distance(p) < tol)
      dz = face_dofs[j];
  return dz;
}

}  // namespace

AxisymmetricSolver::AxisymmetricSolver(const meshing::AxisymmetricSlabMesh& mesh,
                                       std::vector<LayerMaterial> materials, std::vector<LayerCrack> cracks,
                                       std::vector<FrictionCoefficients> friction,
                                       const AxisymmetricSettings& settings,
                                       std::vector<LayerMaterial> core_materials)
    : mesh_(mesh),
      materials_(std::move(materials)),
      core_materials_(std::move(core_materials)),
      cracks_(std::move(cracks)),
      friction_(std::move(friction)),
      settings_(settings),
      fe_(FE_Q<2>(settings.degree), 2),
      dof_handler_(triangulation_) {
  if (settings_.degree != 1 && settings_.degree != 2)
    throw std::invalid_argument("AxisymmetricSolver: element degree must be 1 or 2");
  if (materials_.empty() || cracks_.size() != materials_.size() || friction_.size() != materials_.size())
    throw std::invalid_argument("AxisymmetricSolver: one material, crack law and friction pair per layer");
  if (!core_materials_.empty() && core_materials_.size() != materials_.size())
    throw std::invalid_argument("AxisymmetricSolver: core materials must be given for every layer or none");
  for (const LayerCrack& c : cracks_)
    if (!(c.area_scale > 0.0) || !(c.opening_scale > 0.0))
      throw std::invalid_argument("AxisymmetricSolver: crack area and opening scales must be > 0");
  for (const LayerCrack& c : cracks_)
    if (c.kind == LayerCrack::Kind::Cohesive) c.law.check();
  if (!(settings_.contact_penalty > 0.0) || !(settings_.friction_penalty > 0.0))
    throw std::invalid_argument("AxisymmetricSolver: penalty factors must be > 0");
}

void AxisymmetricSolver::setup(double sample_radius_m, double total_thickness_m) {
  const double tol = 1e-9 * sample_radius_m;  // geometric tolerance (m)
  build_triangulation(sample_radius_m, total_thickness_m, tol);
  distribute_dofs_and_constraints();
  std::vector<Point<2>> support(dof_handler_.n_dofs());
  DoFTools::map_dofs_to_support_points(MappingQ1<2>(), dof_handler_, support);
  find_crack_pairs(support, tol);
  find_contact_nodes(support, tol);
  make_sparsity();
  allocate_state();
  assemble(solution_, true);  // the unloaded tangent gives the first contact penalties
  update_penalties();
}

void AxisymmetricSolver::build_triangulation(double sample_radius_m, double total_thickness_m, double tol) {
  // Triangulation from the plain mesh (crack vertices duplicated: the two
  // sides share no face and their faces are boundary faces).
  std::vector<Point<2>> vertices;
  vertices.reserve(mesh_.vertices.size());
  for (const auto& v : mesh_.vertices) vertices.emplace_back(v[0], v[1]);
  std::vector<CellData<2>> cells(mesh_.cells.size());
  for (std::size_t c = 0; c < mesh_.cells.size(); ++c) {
    for (unsigned i = 0; i < 4; ++i) cells[c].vertices[i] = mesh_.cells[c][i];
    cells[c].material_id = static_cast<types::material_id>(mesh_.material_id[c]);
    if (mesh_.material_id[c] < 0 || static_cast<std::size_t>(mesh_.material_id[c]) >= materials_.size())
      throw std::invalid_argument("AxisymmetricSolver: cell layer index without a material");
  }
  triangulation_.clear();
  triangulation_.create_triangulation(vertices, cells, SubCellData());
  const double r_c = mesh_.crack_radius_m;
  for (const auto& cell : triangulation_.active_cell_iterators())
    for (const unsigned f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary()) continue;
      const Point<2> p = cell->face(f)->center();
      types::boundary_id id = kTop;
      if (std::abs(p[1]) < tol)
        id = kTop;
      else if (std::abs(p[1] + total_thickness_m) < tol)
        id = kBase;
      else if (std::abs(p[0] - sample_radius_m) < tol)
        id = kLateral;
      else if (std::abs(p[0]) < tol)
        id = kAxis;
      else if (std::abs(p[0] - r_c) < tol)
        id = cell->center()[0] < r_c ? kCrackCore : kCrackOuter;
      else if (mesh_.open_channel && std::abs(p[1] + mesh_.path_depth_m) < tol && p[0] < r_c)
        id = kChannelFloor;
      else
        throw std::logic_error("AxisymmetricSolver: unexpected boundary face");
      cell->face(f)->set_boundary_id(id);
    }

  core_cell_.assign(triangulation_.n_active_cells(), 0);
  if (!core_materials_.empty())
    for (const auto& cell : triangulation_.active_cell_iterators())
      core_cell_[cell->active_cell_index()] =
          cell->center()[0] < r_c && cell->center()[1] > -mesh_.path_depth_m ? 1 : 0;
}

void AxisymmetricSolver::distribute_dofs_and_constraints() {
  dof_handler_.distribute_dofs(fe_);
  cells_.clear();
  for (const auto& cell : dof_handler_.active_cell_iterators()) cells_.push_back(cell);
  cell_work_.assign(cells_.size(), CellContribution{FullMatrix<double>(fe_.n_dofs_per_cell(), fe_.n_dofs_per_cell()),
                                                    Vector<double>(fe_.n_dofs_per_cell()), 0.0});
  // The cells' undeformed geometry, once: every assembly reads it.
  const QGauss<2> quadrature(settings_.degree + 1);
  unit_points_ = quadrature.get_points();
  shape_component_.resize(fe_.n_dofs_per_cell());
  for (unsigned i = 0; i < fe_.n_dofs_per_cell(); ++i) shape_component_[i] = fe_.system_to_component_index(i).first;
  FEValues<2> fev(fe_, quadrature, update_values | update_gradients | update_JxW_values | update_quadrature_points);
  std::vector<types::global_dof_index> dofs(fe_.n_dofs_per_cell());
  geometry_.clear();
  geometry_.reserve(cells_.size());
  for (const auto& cell : cells_) {
    fev.reinit(cell);
    cell->get_dof_indices(dofs);
    geometry_.push_back(cell_geometry(fev, dofs, unit_points_));
  }
  // Homogeneous Dirichlet conditions.
  dirichlet_.clear();
  VectorTools::interpolate_boundary_values(dof_handler_, kBase, Functions::ZeroFunction<2>(2), dirichlet_);
  VectorTools::interpolate_boundary_values(dof_handler_, kLateral, Functions::ZeroFunction<2>(2), dirichlet_);
  VectorTools::interpolate_boundary_values(dof_handler_, kAxis, Functions::ZeroFunction<2>(2), dirichlet_,
                                           fe_.component_mask(FEValuesExtractors::Scalar(0)));
  dirichlet_.close();
}

void AxisymmetricSolver::find_crack_pairs(const std::vector<Point<2>>& support, double tol) {
  // Cohesive points, in the order of the cells and their faces: the outer
  // wall nodes of an open channel tied to the crack plane, and the crack
  // nodes of the core side paired with their copies on the outer side.
  cohesive_points_.clear();
  // Crack faces of the outer side by the centre of the face, to pair with the core side.
  std::map<std::pair<long, long>, std::pair<DoFHandler<2>::active_cell_iterator, unsigned>> outer_faces;
  for (const auto& cell : dof_handler_.active_cell_iterators())
    for (const unsigned f : cell->face_indices())
      if (cell->face(f)->at_boundary() && cell->face(f)->boundary_id() == kCrackOuter)
        outer_faces[face_key(cell->face(f)->center(), tol)] = {cell, f};

  for (const auto& cell : dof_handler_.active_cell_iterators())
    for (const unsigned f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary()) continue;
      const auto id = cell->face(f)->boundary_id();
      if (id == kCrackOuter && mesh_.open_channel) {
        add_channel_wall_points(cell, f, support, tol);
      } else if (id == kCrackCore) {
        const auto match = outer_faces.find(face_key(cell->face(f)->center(), tol));
        if (match == outer_faces.end()) throw std::logic_error("AxisymmetricSolver: unmatched crack face");
        pair_crack_face(cell, f, match->second.first, match->second.second, support, tol);
      }
    }
}

void AxisymmetricSolver::add_channel_wall_points(const DoFHandler<2>::active_cell_iterator& cell, unsigned f,
                                                 const std::vector<Point<2>>& support, double tol) {
  // Open channel: each wall node is tied to the rigid crack plane.
  const auto face = cell->face(f);
  std::vector<types::global_dof_index> face_dofs(fe_.n_dofs_per_face());
  face->get_dof_indices(face_dofs);
  const double length = face->measure();
  for (unsigned i = 0; i < face_dofs.size(); ++i) {
    if (fe_.face_system_to_component_index(i).first != 0) continue;
    const Point<2> p = support[face_dofs[i]];
    CohesivePoint cp{};
    cp.to_plane = true;
    cp.outer_r = cp.core_r = face_dofs[i];
    cp.outer_z = cp.core_z = z_dof_at(fe_, face_dofs, support, p, tol);
    cp.Z = p[1];
    cp.area_m2 = kTwoPi * mesh_.crack_radius_m * newton_cotes_weight(settings_.degree, p, face->vertex(0), length) *
                 length;
    cp.layer = static_cast<int>(cell->material_id());
    cohesive_points_.push_back(cp);
  }
}

void AxisymmetricSolver::pair_crack_face(const DoFHandler<2>::active_cell_iterator& cell, unsigned f,
                                         const DoFHandler<2>::active_cell_iterator& outer_cell, unsigned outer_f,
                                         const std::vector<Point<2>>& support, double tol) {
  // Cohesive points: pair the core face's dofs with the outer face's.
  const auto face = cell->face(f);
  const unsigned dpf = fe_.n_dofs_per_face();
  std::vector<types::global_dof_index> face_dofs(dpf), outer_dofs(dpf);
  face->get_dof_indices(face_dofs);
  outer_cell->face(outer_f)->get_dof_indices(outer_dofs);
  const double length = face->measure();
  for (unsigned i = 0; i < dpf; ++i) {
    if (fe_.face_system_to_component_index(i).first != 0) continue;
    const Point<2> p = support[face_dofs[i]];
    CohesivePoint cp{};
    cp.core_r = face_dofs[i];
    cp.core_z = z_dof_at(fe_, face_dofs, support, p, tol);
    bool found_r = false, found_z = false;
    for (unsigned j = 0; j < dpf; ++j) {
      if (support[outer_dofs[j]].distance(p) >= tol) continue;
      if (fe_.face_system_to_component_index(j).first == 0) {
        cp.outer_r = outer_dofs[j];
        found_r = true;
      } else {
        cp.outer_z = outer_dofs[j];
        found_z = true;
      }
    }
    if (!found_r || !found_z) throw std::logic_error("AxisymmetricSolver: crack dofs do not pair up");
    if (cp.outer_r == cp.core_r) continue;  // shared node at the path depth
    cp.Z = p[1];
    cp.area_m2 = kTwoPi * mesh_.crack_radius_m * newton_cotes_weight(settings_.degree, p, face->vertex(0), length) *
                 length;
    cp.layer = static_cast<int>(cell->material_id());
    cohesive_points_.push_back(cp);
  }
}

void AxisymmetricSolver::find_contact_nodes(const std::vector<Point<2>>& support, double tol) {
  // One node per R-dof of the top surface and of the crack faces; its lumped
  // area adds up over the faces that hold it.
  contact_nodes_.clear();
  std::map<unsigned, std::size_t> node_of_rdof;  // R-dof -> contact node
  const double r_c = mesh_.crack_radius_m;
  const unsigned dpf = fe_.n_dofs_per_face();
  std::vector<types::global_dof_index> face_dofs(dpf);
  for (const auto& cell : dof_handler_.active_cell_iterators())
    for (const unsigned f : cell->face_indices()) {
      const auto face = cell->face(f);
      if (!face->at_boundary()) continue;
      const auto id = face->boundary_id();
      if (id != kTop && id != kCrackCore && id != kCrackOuter) continue;
      face->get_dof_indices(face_dofs);
      const double length = face->measure();
      const Point<2> v0 = face->vertex(0);
      const bool core = id == kCrackCore || (id == kTop && cell->center()[0] < r_c);
      const int layer = static_cast<int>(cell->material_id());
      for (unsigned i = 0; i < dpf; ++i) {
        if (fe_.face_system_to_component_index(i).first != 0) continue;
        const unsigned dr = face_dofs[i];
        const unsigned dz = z_dof_at(fe_, face_dofs, support, support[dr], tol);
        const Point<2> p = support[dr];
        const double area =
            kTwoPi * std::max(p[0], 0.0) * newton_cotes_weight(settings_.degree, p, v0, length) * length;
        auto it = node_of_rdof.find(dr);
        if (it == node_of_rdof.end()) {
          node_of_rdof[dr] = contact_nodes_.size();
          contact_nodes_.push_back({dr, dz, p[0], p[1], area, core, layer, id == kTop});
        } else {
          ContactNode& node = contact_nodes_[it->second];
          node.area_m2 += area;
          node.on_top = node.on_top || id == kTop;
        }
      }
    }

  // Partners: the two copies of a crack node.
  for (std::size_t i = 0; i < contact_nodes_.size(); ++i)
    for (std::size_t j = i + 1; j < contact_nodes_.size(); ++j)
      if (std::abs(contact_nodes_[i].R - contact_nodes_[j].R) < tol &&
          std::abs(contact_nodes_[i].Z - contact_nodes_[j].Z) < tol) {
        contact_nodes_[i].partner = static_cast<int>(j);
        contact_nodes_[j].partner = static_cast<int>(i);
      }
}

void AxisymmetricSolver::make_sparsity() {
  // Sparsity: cells, plus the couplings of each cohesive point.
  // (condensed with every possible crack tie, so that any set of tie
  // constraints can be condensed into the matrix later).
  AffineConstraints<double> all_ties;
  for (const CohesivePoint& cp : cohesive_points_) {
    if (cp.to_plane) continue;
    for (const auto& [slave, master] : {std::make_pair(cp.outer_r, cp.core_r), std::make_pair(cp.outer_z, cp.core_z)})
      if (!all_ties.is_constrained(slave)) {
        all_ties.add_line(slave);
        all_ties.add_entry(slave, master, 1.0);
      }
  }
  all_ties.close();
  const unsigned n = dof_handler_.n_dofs();
  DynamicSparsityPattern dsp(n, n);
  DoFTools::make_sparsity_pattern(dof_handler_, dsp, all_ties, true);
  for (const CohesivePoint& cp : cohesive_points_) {
    if (cp.to_plane) continue;
    const unsigned d[4] = {cp.core_r, cp.core_z, cp.outer_r, cp.outer_z};
    for (unsigned a : d)
      for (unsigned b : d) dsp.add(a, b);
  }
  sparsity_.copy_from(dsp);
}

void AxisymmetricSolver::allocate_state() {
  // Matrices, vectors, and the state of the unloaded slab: u = 0, no damage,
  // no contact, no dissipation, the viscoelastic points at rest.
  const unsigned n = dof_handler_.n_dofs();
  tangent_.reinit(sparsity_);
  system_matrix_.reinit(sparsity_);
  residual_.reinit(n);
  rhs_.reinit(n);
  solution_.reinit(n);
  last_increment_.reinit(n);
  bulk_diagonal_.reinit(n);
  cohesive_committed_.assign(cohesive_points_.size(), CohesiveHistory{});
  cohesive_trial_ = cohesive_committed_;
  friction_committed_.assign(contact_nodes_.size(), FrictionHistory{});
  friction_trial_ = friction_committed_;
  cohesive_branch_.assign(cohesive_points_.size(), 0);
  contact_branch_.assign(contact_nodes_.size(), 0);
  punch_contact_.assign(contact_nodes_.size(), 0);
  punch_lateral_hold_.assign(contact_nodes_.size(), 0.0);
  penalty_.assign(contact_nodes_.size(), 0.0);
  broken_layers_.assign(materials_.size(), 0);
  dissipated_J_ = dissipated_trial_J_ = 0.0;
  stabilization_J_ = stabilization_trial_J_ = 0.0;
  const unsigned n_points = (settings_.degree + 1) * (settings_.degree + 1);
  viscous_history_.assign(triangulation_.n_active_cells(), {});
  for (const auto& cell : dof_handler_.active_cell_iterators())
    if (const ViscoelasticMaterial<LayerMaterial>* law = viscoelastic_of(cell))
      viscous_history_[cell->active_cell_index()].assign(n_points, law->initial_history());
}

}  // namespace puncture::fem
