// axisymmetric_solver.cc: see axisymmetric_solver.hpp for the formulation.
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
#include <chrono>
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
using axisymmetric_cell::CellState;
using axisymmetric_cell::DisplacementGradients;
using axisymmetric_cell::ViscousCell;
using axisymmetric_cell::evaluate_cell;
using axisymmetric_cell::kTwoPi;
using axisymmetric_cell::n_pressure_modes;

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

/// Viscous stabilisation at one quadrature point: the stress two_mu_v sym(dH)
/// (dH the step's increment of the displacement gradient) against the test
/// gradients gradN: adds its forces to Re and, with_matrix, its stiffness to
/// the lower triangle of Ke. Returns its energy two_mu_v |sym(dH)|^2 dV (J).
double add_stabilization(double two_mu_v, const Tensor<2, 3>& dH, const std::vector<Tensor<2, 3>>& gradN,
                         double dV, bool with_matrix, FullMatrix<double>& Ke, Vector<double>& Re) {
  const Tensor<2, 3> eps = 0.5 * (dH + transpose(dH));
  for (unsigned i = 0; i < gradN.size(); ++i) {
    const Tensor<2, 3> ei = 0.5 * (gradN[i] + transpose(gradN[i]));
    Re(i) += two_mu_v * scalar_product(ei, eps) * dV;
    if (with_matrix)
      for (unsigned j = 0; j <= i; ++j) Ke(i, j) += two_mu_v * scalar_product(ei, gradN[j]) * dV;
  }
  return two_mu_v * scalar_product(eps, eps) * dV;
}

/// Adds the condensed pressure stiffness B^T (M^-1 K_JJ M^-1) B of the
/// three-field form (B: the cell's dJ couplings, np x dofs) to the lower
/// triangle of Ke, then mirrors the lower triangle into the upper one.
void add_condensed_pressure_stiffness(const CellState& st, const FullMatrix<double>& B, FullMatrix<double>& Ke) {
  const unsigned np = B.m(), dpc = B.n();
  FullMatrix<double> tmp(np, np), G(np, np), GB(np, dpc);
  st.M_inv.mmult(tmp, st.K_JJ);
  tmp.mmult(G, st.M_inv);
  G.mmult(GB, B);
  for (unsigned i = 0; i < dpc; ++i)
    for (unsigned j = 0; j <= i; ++j) {
      double s = 0.0;
      for (unsigned a = 0; a < np; ++a) s += B(a, i) * GB(a, j);
      Ke(i, j) += s;
    }
  for (unsigned i = 0; i < dpc; ++i)
    for (unsigned j = i + 1; j < dpc; ++j) Ke(i, j) = Ke(j, i);
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

void AxisymmetricSolver::set_viscoelasticity(const std::vector<std::vector<PronyTerm>>& prony_per_layer) {
  if (prony_per_layer.size() != materials_.size())
    throw std::invalid_argument("AxisymmetricSolver: one Prony series (possibly empty) per layer");
  viscoelastic_.assign(materials_.size(), std::nullopt);
  for (std::size_t l = 0; l < materials_.size(); ++l)
    if (!prony_per_layer[l].empty()) viscoelastic_[l] = make_viscoelastic_layer(materials_[l], prony_per_layer[l]);
}

const ViscoelasticMaterial<LayerMaterial>* AxisymmetricSolver::viscoelastic_of(
    const DoFHandler<2>::active_cell_iterator& cell) const {
  if (viscoelastic_.empty() || core_cell_[cell->active_cell_index()]) return nullptr;
  const auto& law = viscoelastic_[cell->material_id()];
  return law ? &*law : nullptr;
}

void AxisymmetricSolver::commit_viscous_history() {
  const QGauss<2> quadrature(settings_.degree + 1);
  FEValues<2> fev(fe_, quadrature, update_values | update_gradients | update_quadrature_points);
  const unsigned nq = quadrature.size();
  DisplacementGradients gradients(nq);
  std::vector<Tensor<2, 3>> H(nq);
  for (const auto& cell : cells_) {
    const ViscoelasticMaterial<LayerMaterial>* law = viscoelastic_of(cell);
    if (!law) continue;
    fev.reinit(cell);
    gradients.compute(fev, solution_, H);
    std::vector<ViscoelasticHistory>& history = viscous_history_[cell->active_cell_index()];
    for (unsigned q = 0; q < nq; ++q) {
      const Tensor<2, 3> F = Tensor<2, 3>(unit_symmetric_tensor<3>()) + H[q];
      law->commit(right_cauchy_green(F), dt_s_, history[q]);
    }
  }
}

const LayerMaterial& AxisymmetricSolver::material_of(const DoFHandler<2>::active_cell_iterator& cell) const {
  return core_cell_[cell->active_cell_index()] ? core_materials_[cell->material_id()] : materials_[cell->material_id()];
}

void AxisymmetricSolver::set_cutting_needle(const RigidNeedle& needle) {
  needle.check();
  cutting_ = true;
  needle_ = needle;
}

void AxisymmetricSolver::set_flat_punch(double radius_m, double z_face_m) {
  if (!(radius_m > 0.0) || !std::isfinite(z_face_m))
    throw std::invalid_argument("AxisymmetricSolver: flat punch needs a positive radius and a finite face height");
  cutting_ = false;
  punch_radius_m_ = radius_m;
  punch_z_m_ = z_face_m;
}

void AxisymmetricSolver::break_layer(int layer) {
  if (layer < 0 || layer >= static_cast<int>(materials_.size())) throw std::out_of_range("break_layer: no such layer");
  broken_layers_[layer] = 1;
  for (std::size_t i = 0; i < cohesive_points_.size(); ++i)
    if (cohesive_points_[i].layer == layer) cohesive_committed_[i].damage = 1.0;
  cohesive_trial_ = cohesive_committed_;
}

bool AxisymmetricSolver::tied_slave(std::size_t node) const {
  const ContactNode& nd = contact_nodes_[node];
  if (nd.partner < 0 || nd.core_side) return false;
  for (const CohesivePoint& cp : cohesive_points_)
    if (cp.outer_z == nd.dof_z)
      return cracks_[cp.layer].kind == LayerCrack::Kind::TiedUntilBroken && !broken_layers_[cp.layer];
  return false;
}

void AxisymmetricSolver::make_constraints(const Vector<double>& u, AffineConstraints<double>& c) const {
  // Newton-increment constraints: Dirichlet (homogeneous), ties of unbroken
  // tied layers, and the flat punch (du = target - u).
  c.clear();
  for (const CohesivePoint& cp : cohesive_points_)
    if (!cp.to_plane && cracks_[cp.layer].kind == LayerCrack::Kind::TiedUntilBroken && !broken_layers_[cp.layer]) {
      c.add_line(cp.outer_r);
      c.add_entry(cp.outer_r, cp.core_r, 1.0);
      c.set_inhomogeneity(cp.outer_r, u[cp.core_r] - u[cp.outer_r]);
      c.add_line(cp.outer_z);
      c.add_entry(cp.outer_z, cp.core_z, 1.0);
      c.set_inhomogeneity(cp.outer_z, u[cp.core_z] - u[cp.outer_z]);
    }
  if (!cutting_)
    for (std::size_t i = 0; i < contact_nodes_.size(); ++i) {
      if (!punch_contact_[i]) continue;
      const ContactNode& nd = contact_nodes_[i];
      if (c.is_constrained(nd.dof_z) || dirichlet_.is_constrained(nd.dof_z)) continue;
      c.add_line(nd.dof_z);
      c.set_inhomogeneity(nd.dof_z, (punch_z_m_ - nd.Z) - u[nd.dof_z]);
      if (settings_.blunt_tip_no_slip && !dirichlet_.is_constrained(nd.dof_r) && !c.is_constrained(nd.dof_r)) {
        c.add_line(nd.dof_r);
        c.set_inhomogeneity(nd.dof_r, punch_lateral_hold_[i] - u[nd.dof_r]);
      }
    }
  c.merge(dirichlet_, AffineConstraints<double>::MergeConflictBehavior::left_object_wins);
  c.close();
}

bool AxisymmetricSolver::assemble_cells(std::size_t begin, std::size_t end, const Vector<double>& u, bool with_matrix) {
  const unsigned degree = settings_.degree;
  const QGauss<2> quadrature(degree + 1);
  FEValues<2> fev(fe_, quadrature, update_values | update_gradients | update_JxW_values | update_quadrature_points);
  const unsigned dpc = fe_.n_dofs_per_cell(), nq = quadrature.size(), np = n_pressure_modes(degree);
  FullMatrix<double> B(np, dpc);
  std::vector<Tensor<2, 3>> H(nq), H0(nq), gradN(dpc);
  std::vector<SymTensor2> dE(dpc), CC_dE(dpc);
  std::vector<unsigned> comp(dpc);
  for (unsigned i = 0; i < dpc; ++i) comp[i] = fe_.system_to_component_index(i).first;
  DisplacementGradients gradients(nq);
  CellState st;
  // Viscous stabilisation (Kelvin-Voigt on the step's strain increment):
  // sigma_v = (tau / dt) 2 mu_0 sym(H - H_step_start), mu_0 the layer's
  // initial shear modulus.
  const bool stabilize = settings_.stabilization_time_s > 0.0 && dt_s_ > 0.0 && step_start_.size() == u.size();
  const double stab_ratio = stabilize ? settings_.stabilization_time_s / dt_s_ : 0.0;

  for (std::size_t k = begin; k < end; ++k) {
    const auto& cell = cells_[k];
    CellContribution& out = cell_work_[k];
    FullMatrix<double>& Ke = out.Ke;
    Vector<double>& Re = out.Re;
    out.stabilization_J = 0.0;
    fev.reinit(cell);
    gradients.compute(fev, u, H);
    const ViscousCell viscous{viscoelastic_of(cell), &viscous_history_[cell->active_cell_index()], dt_s_};
    if (!evaluate_cell(material_of(cell), degree, fev, H, st, with_matrix, viscous)) return false;
    Ke = 0.0;
    Re = 0.0;
    B = 0.0;
    double two_mu_v = 0.0;
    if (stabilize) {
      gradients.compute(fev, step_start_, H0);
      const LayerMaterial& m = material_of(cell);
      two_mu_v = stab_ratio * m.youngs_modulus_Pa() / (1.0 + m.poisson_ratio());
    }
    for (unsigned q = 0; q < nq; ++q) {
      const double R = fev.quadrature_point(q)[0];
      for (unsigned i = 0; i < dpc; ++i) {
        gradN[i] = axisymmetric_shape_gradient(comp[i], fev.shape_value(i, q), fev.shape_grad(i, q), R);
        dE[i] = strain_variation(st.F[q], gradN[i]);
        Re(i) += scalar_product(st.S[q], dE[i]) * st.dV[q];
      }
      if (stabilize)
        out.stabilization_J += add_stabilization(two_mu_v, H[q] - H0[q], gradN, st.dV[q], with_matrix, Ke, Re);
      if (!with_matrix) continue;
      const Tensor<2, 3> S_full(st.S[q]);
      const Tensor<2, 3> F_inv_T = transpose(invert(st.F[q]));
      for (unsigned i = 0; i < dpc; ++i) {
        CC_dE[i] = st.CC[q] * dE[i];
        const Tensor<2, 3> gNi_S = gradN[i] * S_full;
        for (unsigned j = 0; j <= i; ++j)
          Ke(i, j) += (scalar_product(CC_dE[i], dE[j]) + scalar_product(gNi_S, gradN[j])) * st.dV[q];
        const double dJ_i = st.J[q] * scalar_product(gradN[i], F_inv_T);
        for (unsigned a = 0; a < np; ++a) B(a, i) += st.Np[q][a] * dJ_i * st.dV[q];
      }
    }
    if (with_matrix) add_condensed_pressure_stiffness(st, B, Ke);
  }
  return true;
}

bool AxisymmetricSolver::assemble(const Vector<double>& u, bool with_matrix) {
  if (!compute_cell_contributions(u, with_matrix)) return false;
  add_cell_contributions(with_matrix);
  if (!add_cohesive_forces(u, with_matrix)) return false;
  // Needle: penalty contact with friction (cutting tip) or flat punch reactions.
  force_trial_ = NeedleForce{};
  if (cutting_)
    add_needle_contact(u, with_matrix);
  else
    add_punch_reactions();
  force_trial_.total_N = force_trial_.normal_N + force_trial_.friction_N;
  for (std::size_t i = 0; i < residual_.size(); ++i)
    if (!std::isfinite(residual_(i))) return false;
  return true;
}

bool AxisymmetricSolver::compute_cell_contributions(const Vector<double>& u, bool with_matrix) {
  // Cells: computed in parallel (each thread its own range and scratch), added
  // to the global system in cell order, so the result does not depend on the
  // number of threads.
  const std::size_t n_cells = cells_.size();
  const std::size_t n_threads = std::max<std::size_t>(1, std::min<std::size_t>(settings_.assembly_threads, n_cells));
  std::vector<char> ok(n_threads, 1);
  std::vector<std::exception_ptr> errors(n_threads);
  auto run_range = [&](std::size_t t) {
    try {
      ok[t] = assemble_cells(t * n_cells / n_threads, (t + 1) * n_cells / n_threads, u, with_matrix) ? 1 : 0;
    } catch (...) {
      errors[t] = std::current_exception();
    }
  };
  {
    std::vector<std::thread> pool;
    for (std::size_t t = 1; t < n_threads; ++t) pool.emplace_back(run_range, t);
    run_range(0);
    for (auto& th : pool) th.join();
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
  for (const char o : ok)
    if (!o) return false;
  return true;
}

void AxisymmetricSolver::add_cell_contributions(bool with_matrix) {
  stabilization_trial_J_ = stabilization_J_;
  if (with_matrix) {
    tangent_ = 0.0;
    bulk_diagonal_ = 0.0;
  }
  residual_ = 0.0;
  std::vector<types::global_dof_index> dofs(fe_.n_dofs_per_cell());
  for (std::size_t k = 0; k < cells_.size(); ++k) {
    const CellContribution& c = cell_work_[k];
    cells_[k]->get_dof_indices(dofs);
    stabilization_trial_J_ += c.stabilization_J;
    for (unsigned i = 0; i < dofs.size(); ++i) {
      residual_(dofs[i]) += c.Re(i);
      if (with_matrix) bulk_diagonal_(dofs[i]) += c.Ke(i, i);
    }
    if (with_matrix) tangent_.add(dofs, c.Ke, false);
  }
}

bool AxisymmetricSolver::add_cohesive_forces(const Vector<double>& u, bool with_matrix) {
  // Cohesive points: R_outer += A t, R_core -= A t.
  dissipated_trial_J_ = dissipated_J_;
  for (std::size_t k = 0; k < cohesive_points_.size(); ++k) {
    const CohesivePoint& cp = cohesive_points_[k];
    const LayerCrack& crack = cracks_[cp.layer];
    if (crack.kind == LayerCrack::Kind::TiedUntilBroken) {
      // Tied by constraints until broken; afterwards only the faces'
      // no-interpenetration penalty of a fully damaged law remains.
      if (!broken_layers_[cp.layer]) continue;
    }
    CohesiveLawParameters law = crack.law;
    double area_scale = crack.area_scale, kn = crack.opening_scale;
    if (crack.kind == LayerCrack::Kind::TiedUntilBroken) {
      // A broken tied layer keeps a stiff closure penalty only (D = 1).
      law.strength_Pa = 1e3 * materials_[cp.layer].youngs_modulus_Pa();
      law.toughness_J_per_m2 = 1e-3 * law.strength_Pa;
      area_scale = kn = 1.0;
    }
    // Law in the slit's separation (kn x radial opening, sliding); forces on
    // the ring nodes A area_scale (kn t_n, t_t) (see LayerCrack).
    // A wall tied to the crack plane opens by its radial displacement and
    // does not slide on it (the plane is one of symmetry of the cut).
    const double dn = cp.to_plane ? u[cp.outer_r] : u[cp.outer_r] - u[cp.core_r];
    const double dt = cp.to_plane ? 0.0 : u[cp.outer_z] - u[cp.core_z];
    const CohesiveResponse r = cohesive_response(law, cohesive_committed_[k], kn * dn, dt, dt_s_);
    if (!std::isfinite(r.traction[0]) || !std::isfinite(r.traction[1])) return false;
    cohesive_trial_[k] = r.history;
    const double A = cp.area_m2 * area_scale;
    dissipated_trial_J_ += A * (r.history.dissipated_J_per_m2 - cohesive_committed_[k].dissipated_J_per_m2);
    if (cp.to_plane) {
      residual_(cp.outer_r) += A * kn * r.traction[0];
      if (with_matrix) tangent_.add(cp.outer_r, cp.outer_r, A * kn * kn * r.tangent[0][0]);
      continue;
    }
    const double scale[2] = {kn, 1.0};
    const unsigned d[4] = {cp.core_r, cp.core_z, cp.outer_r, cp.outer_z};
    const double sgn[4] = {-1.0, -1.0, 1.0, 1.0};
    for (unsigned i = 0; i < 4; ++i) residual_(d[i]) += sgn[i] * A * scale[i % 2] * r.traction[i % 2];
    if (with_matrix)
      for (unsigned i = 0; i < 4; ++i)
        for (unsigned j = 0; j < 4; ++j)
          tangent_.add(d[i], d[j], sgn[i] * sgn[j] * A * scale[i % 2] * scale[j % 2] * r.tangent[i % 2][j % 2]);
  }
  return true;
}

void AxisymmetricSolver::add_needle_contact(const Vector<double>& u, bool with_matrix) {
  // Cutting tip: penalty contact with Coulomb friction at every contact node.
  const Vec2 edge{needle_.edge_radius_m, needle_.z_tip_m};
  for (std::size_t i = 0; i < contact_nodes_.size(); ++i) {
    const ContactNode& nd = contact_nodes_[i];
    const Vec2 x{nd.R + u[nd.dof_r], nd.Z + u[nd.dof_z]};
    const ContactPenalty penalty{penalty_[i], settings_.contact_rounding * mesh_.tip_element_size_m};
    NodalContactResponse resp;
    ContactPoint c;
    if (nd.core_side) {
      resp = core_wall_contact(needle_, x, penalty,
                               settings_.hold_crack_line ? -1.0 : settings_.edge_rounding * mesh_.tip_element_size_m);
      c.penetration_m = std::max(x[0] - needle_.edge_radius_m, 0.0);
    } else {
      c = outer_contact(needle_, x, settings_.edge_rounding * mesh_.tip_element_size_m);
      resp = nodal_contact(c, x, edge, friction_committed_[i], friction_[nd.layer], penalty,
                           settings_.friction_penalty * penalty_[i]);
    }
    friction_trial_[i] = resp.history;
    if (!resp.history.in_contact) continue;
    if (debug_contacts_)
      std::cout << "        node R " << nd.R * 1e3 << " Z " << nd.Z * 1e3 << (nd.core_side ? " core" : " outer")
                << " x (" << x[0] * 1e3 << ", " << x[1] * 1e3 << ") pen " << c.penetration_m * 1e6 << " um n ("
                << c.normal[0] << "," << c.normal[1] << ") k " << penalty_[i] << " f " << resp.normal_force[0] << ","
                << resp.normal_force[1] << " ft " << resp.friction_force[1] << std::endl;
    const unsigned d[2] = {nd.dof_r, nd.dof_z};
    for (unsigned a = 0; a < 2; ++a) {
      residual_(d[a]) -= resp.normal_force[a] + resp.friction_force[a];
      if (with_matrix)
        for (unsigned b = 0; b < 2; ++b) tangent_.add(d[a], d[b], -resp.dforce_dx[a][b]);
    }
    force_trial_.normal_N -= resp.normal_force[1];
    force_trial_.friction_N -= resp.friction_force[1];
    ++force_trial_.nodes_in_contact;
  }
}

void AxisymmetricSolver::add_punch_reactions() {
  for (std::size_t i = 0; i < contact_nodes_.size(); ++i)
    if (punch_contact_[i]) {
      force_trial_.normal_N -= residual_(contact_nodes_[i].dof_z);  // R_z < 0 where the punch presses
      ++force_trial_.nodes_in_contact;
    }
}

double AxisymmetricSolver::free_residual_norm(const AffineConstraints<double>& c) const {
  // Residual of the unknowns left free by the constraints: a constrained dof
  // hands its residual to its masters (a tied crack node to its partner).
  Vector<double> r(residual_);
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (!c.is_constrained(i)) continue;
    if (const auto* entries = c.get_constraint_entries(i))
      for (const auto& [j, w] : *entries) r(j) += w * residual_(i);
  }
  double s = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i)
    if (!c.is_constrained(i)) s += r(i) * r(i);
  return std::sqrt(s);
}

void AxisymmetricSolver::update_penalties() {
  // k_n = contact_penalty x the bulk stiffness at the node (mean of its two
  // diagonal entries; the bulk tangent of the last converged state).
  for (std::size_t i = 0; i < contact_nodes_.size(); ++i) {
    const ContactNode& nd = contact_nodes_[i];
    const double k = 0.5 * (bulk_diagonal_(nd.dof_r) + bulk_diagonal_(nd.dof_z));
    penalty_[i] = settings_.contact_penalty * std::max(k, 1e-12);
  }
}

void AxisymmetricSolver::commit() {
  commit_viscous_history();
  cohesive_committed_ = cohesive_trial_;
  friction_committed_ = friction_trial_;
  dissipated_J_ = dissipated_trial_J_;
  stabilization_J_ = stabilization_trial_J_;
  force_ = force_trial_;
}

AxisymmetricSolver::Snapshot AxisymmetricSolver::snapshot() const {
  return {solution_,          last_increment_,     cohesive_committed_, friction_committed_,
          punch_contact_,     punch_lateral_hold_, broken_layers_,      dissipated_J_,
          stabilization_J_,   viscous_history_};
}

void AxisymmetricSolver::restore(const Snapshot& s) {
  solution_ = s.solution;
  last_increment_ = s.last_increment;
  cohesive_committed_ = cohesive_trial_ = s.cohesive;
  friction_committed_ = friction_trial_ = s.friction;
  punch_contact_ = s.punch_contact;
  punch_lateral_hold_ = s.punch_lateral_hold;
  broken_layers_ = s.broken_layers;
  dissipated_J_ = dissipated_trial_J_ = s.dissipated_J;
  stabilization_J_ = stabilization_trial_J_ = s.stabilization_J;
  viscous_history_ = s.viscous_history;
  step_start_ = solution_;
  const double dt_s = dt_s_;  // the restored state itself: no step, no viscous advance
  dt_s_ = 0.0;
  assemble(solution_, true);
  dt_s_ = dt_s;
  force_ = force_trial_;
  update_penalties();
}

/// What the phases of one solve_step share.
struct AxisymmetricSolver::Step {
  AxisymmetricNewtonReport report;
  Vector<double> u_start;                 ///< the last converged solution (restored on failure)
  std::vector<char> punch_contact_start;  ///< the flat punch's contact set at the start
  std::vector<double> punch_hold_start;   ///< and its held u_R
  std::vector<char> released_in_step;     ///< punch nodes released for a tensile reaction (free for the step)
  AffineConstraints<double> constraints;  ///< the Newton increment's constraints at solution_
  SparseDirectUMFPACK direct;
  Vector<double> du, trial;               ///< Newton direction; the line search's state
  double max_free = 0.0;                  ///< largest free residual of the step so far (N)
  int contact_changes = 0;                ///< changes of the punch contact set so far
  std::vector<double> history;            ///< free residual per iteration (stall detection)
};

/// One Newton iterate (the state solution_).
struct AxisymmetricSolver::Iterate {
  double free = 0.0;   ///< free residual (N)
  double gap = 0.0;    ///< largest prescribed punch displacement not yet reached (m)
  double scale = 0.0;  ///< force scale of the convergence test (N)
  bool stalled = false, strict = false, converged = false;
  double assemble_s = 0.0, solve_s = 0.0;
  std::ostringstream line;  ///< the iterate's line of the Newton log
};

AxisymmetricNewtonReport AxisymmetricSolver::solve_step(double predictor_scale) {
  Step step;
  start_step(step, predictor_scale);
  for (int it = 0;; ++it) {
    Iterate x;
    if (const Failure why = evaluate_iterate(step, it, x)) return fail_step(step, *why);
    if (x.converged) {
      // Flat punch: release nodes pulled by the face (tensile reaction) and
      // take in the nodes it reaches; if the contact set changed, go on.
      const bool released = release_pulled_punch_nodes(step.released_in_step, x.scale);
      const bool joined = update_punch_contact(step.released_in_step);
      if (!released && !joined) return accept_step(step, x, it);
      if (++step.contact_changes > 50) return fail_step(step, "flat punch contact set does not settle");
      x.line << "  (punch contact set changed)";
      step.report.table.push_back(x.line.str());
      continue;
    }
    if (const Failure why = give_up_reason(it, x)) {
      step.report.table.push_back(x.line.str());
      step.report.iterations = it;
      return fail_step(step, *why);
    }
    if (const Failure why = newton_direction(step, x)) return fail_step(step, *why);
    double alpha = 0.0;
    if (const Failure why = line_search(step, x, alpha)) return fail_step(step, *why);
    x.line << "  alpha " << std::defaultfloat << alpha << "  t_assemble " << std::setprecision(3) << x.assemble_s
           << " s  t_solve " << x.solve_s << " s";
    step.report.table.push_back(x.line.str());
    if (settings_.verbose) std::cout << "      " << step.report.table.back() << std::endl;
    solution_ = step.trial;
  }
}

void AxisymmetricSolver::start_step(Step& step, double predictor_scale) {
  step.u_start = solution_;
  step_start_ = step.u_start;
  step.punch_contact_start = punch_contact_;
  step.punch_hold_start = punch_lateral_hold_;
  if (predictor_scale > 0.0 && last_increment_.linfty_norm() > 0.0) {
    solution_.add(predictor_scale, last_increment_);
    if (!assemble(solution_, false)) solution_ = step.u_start;
  }
  step.released_in_step.assign(contact_nodes_.size(), 0);
  update_punch_contact(step.released_in_step);
  step.du.reinit(solution_.size());
  step.trial.reinit(solution_.size());
}

AxisymmetricSolver::Failure AxisymmetricSolver::evaluate_iterate(Step& step, int it, Iterate& x) {
  debug_contacts_ = settings_.verbose && std::getenv("PUNCTURE_FEM_DEBUG_CONTACT") != nullptr;
  make_constraints(solution_, step.constraints);
  const auto t_assemble = std::chrono::steady_clock::now();
  if (!assemble(solution_, true)) return "inverted or non-finite state";
  debug_contacts_ = false;
  x.assemble_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_assemble).count();
  const AffineConstraints<double>& constraints = step.constraints;
  x.free = free_residual_norm(constraints);
  for (std::size_t i = 0; i < solution_.size(); ++i)
    if (constraints.is_inhomogeneously_constrained(i))
      x.gap = std::max(x.gap, std::abs(constraints.get_inhomogeneity(i)));
  step.max_free = std::max(step.max_free, x.free);
  double reaction = std::abs(force_trial_.total_N);
  for (std::size_t i = 0; i < solution_.size(); ++i)
    if (constraints.is_constrained(i)) reaction = std::max(reaction, std::abs(residual_(i)));
  x.scale = std::max({reaction, step.max_free, 1e-300});
  step.report.residual_N = x.free;
  step.report.force_scale_N = x.scale;
  if (!std::isfinite(x.free)) return "non-finite residual";
  x.stalled = check_stall(step.history, x.free);
  const bool gap_closed = x.gap <= 1e-12 * std::max(1e-3, punch_radius_m_);
  x.strict = x.free <= settings_.newton_tolerance * x.scale || x.free <= settings_.absolute_residual_floor_N;
  const bool loose = x.stalled && x.free <= settings_.stall_acceptance_tolerance * x.scale;
  x.converged = gap_closed && (x.strict || loose);
  write_iterate_line(it, x);
  return std::nullopt;
}

bool AxisymmetricSolver::check_stall(std::vector<double>& history, double free) const {
  // Stall: the best residual of the last stall_window iterations is not
  // below stall_factor x the best before them.
  history.push_back(free);
  const int window = settings_.stall_window;
  if (window <= 0 || static_cast<int>(history.size()) <= window) return false;
  const double before = *std::min_element(history.begin(), history.end() - window);
  const double recent = *std::min_element(history.end() - window, history.end());
  return recent > settings_.stall_factor * before;
}

void AxisymmetricSolver::write_iterate_line(int it, Iterate& x) const {
  int sliding = 0, damaged = 0, broken = 0, closed = 0;
  for (const auto& h : friction_trial_) sliding += h.sliding ? 1 : 0;
  for (std::size_t k = 0; k < cohesive_points_.size(); ++k) {
    damaged += cohesive_trial_[k].damage > 0.0 ? 1 : 0;
    broken += cohesive_trial_[k].damage >= 1.0 ? 1 : 0;
    closed += (cohesive_trial_[k].damage > 0.0 &&
               solution_(cohesive_points_[k].outer_r) < solution_(cohesive_points_[k].core_r)) ? 1 : 0;
  }
  x.line << std::setw(4) << it << "  |R_free| " << std::scientific << std::setprecision(3) << x.free << " N  scale "
         << x.scale << " N  F_needle " << force_trial_.total_N << " N  contact " << force_trial_.nodes_in_contact
         << " sliding " << sliding << " damaged " << damaged << " broken " << broken << " closed " << closed;
}

bool AxisymmetricSolver::release_pulled_punch_nodes(std::vector<char>& released_in_step, double scale) {
  bool released = false;
  if (cutting_) return released;
  for (std::size_t i = 0; i < contact_nodes_.size(); ++i) {
    if (!punch_contact_[i] || tied_slave(i)) continue;
    // A tied pair of crack nodes carries its reaction together.
    const int p = contact_nodes_[i].partner;
    double reaction = residual_(contact_nodes_[i].dof_z);
    if (p >= 0 && tied_slave(static_cast<std::size_t>(p))) reaction += residual_(contact_nodes_[p].dof_z);
    if (reaction > 1e-6 * scale) {  // R_z > 0: the face would pull the node
      if (settings_.verbose)
        std::cout << "      punch releases node R=" << contact_nodes_[i].R << " reaction " << reaction << std::endl;
      punch_contact_[i] = 0;
      released_in_step[i] = 1;
      if (p >= 0 && tied_slave(static_cast<std::size_t>(p))) punch_contact_[p] = 0;
      released = true;
    }
  }
  return released;
}

bool AxisymmetricSolver::update_punch_contact(const std::vector<char>& released_in_step) {
  // Flat punch: top nodes within the punch radius that the face has reached
  // join; a node released for a tensile reaction stays free for this step.
  bool changed = false;
  if (cutting_) return changed;
  for (std::size_t i = 0; i < contact_nodes_.size(); ++i) {
    const ContactNode& nd = contact_nodes_[i];
    if (punch_contact_[i] || released_in_step[i] || !nd.on_top || nd.R > punch_radius_m_ * (1 + 1e-9) ||
        tied_slave(i))
      continue;
    if (nd.Z + solution_(nd.dof_z) >= punch_z_m_) {
      punch_contact_[i] = 1;
      punch_lateral_hold_[i] = solution_(nd.dof_r);
      if (nd.partner >= 0 && tied_slave(static_cast<std::size_t>(nd.partner))) punch_contact_[nd.partner] = 1;
      changed = true;
    }
  }
  return changed;
}

AxisymmetricSolver::Failure AxisymmetricSolver::give_up_reason(int it, const Iterate& x) const {
  if (it >= settings_.max_newton_iterations) return "no convergence in " + std::to_string(it) + " Newton iterations";
  if (!x.stalled) return std::nullopt;
  std::ostringstream why;
  why << "Newton stalls: |R_free| " << std::scientific << std::setprecision(3) << x.free << " N did not fall by "
      << std::defaultfloat << 100.0 * (1.0 - settings_.stall_factor) << " % in " << settings_.stall_window
      << " iterations";
  return why.str();
}

AxisymmetricSolver::Failure AxisymmetricSolver::newton_direction(Step& step, Iterate& x) {
  // Linear system K du = -R with the increment constraints condensed in
  // (UMFPACK takes the nonsymmetric tangent of sliding friction).
  rhs_ = residual_;
  rhs_ *= -1.0;
  const auto t_solve = std::chrono::steady_clock::now();
  system_matrix_.copy_from(tangent_);
  step.constraints.condense(system_matrix_, rhs_);
  try {
    step.direct.initialize(system_matrix_);
    step.direct.vmult(step.du, rhs_);
  } catch (const std::exception& e) {
    return std::string("sparse direct solve failed: ") + e.what();
  }
  x.solve_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_solve).count();
  step.constraints.distribute(step.du);
  if (!std::isfinite(step.du.l2_norm())) return "non-finite Newton update";
  return std::nullopt;
}

AxisymmetricSolver::Failure AxisymmetricSolver::line_search(Step& step, const Iterate& x, double& alpha) {
  // Backtracking: the first of alpha = 1, 1/2, 1/4, ... whose free residual
  // falls enough (any admissible one while the punch gap closes), else the
  // best admissible one.
  double best_alpha = -1.0, best_free = std::numeric_limits<double>::infinity();
  alpha = 1.0;
  for (int h = 0; h <= settings_.max_line_search_halvings; ++h, alpha *= 0.5) {
    step.trial = solution_;
    step.trial.add(alpha, step.du);
    if (!assemble(step.trial, false)) continue;
    AffineConstraints<double> tc;
    make_constraints(step.trial, tc);
    const double trial_free = free_residual_norm(tc);
    if (!std::isfinite(trial_free)) continue;
    if (x.gap > 0.0 || trial_free < (1.0 - 1e-4 * alpha) * x.free || trial_free <= settings_.absolute_residual_floor_N)
      return std::nullopt;
    if (trial_free < best_free) {
      best_free = trial_free;
      best_alpha = alpha;
    }
  }
  if (best_alpha < 0.0) return "line search: every trial state is inverted or non-finite";
  alpha = best_alpha;
  step.trial = solution_;
  step.trial.add(alpha, step.du);
  return std::nullopt;
}

AxisymmetricNewtonReport AxisymmetricSolver::accept_step(Step& step, const Iterate& x, int it) {
  AxisymmetricNewtonReport& report = step.report;
  report.accepted_at_stall = !x.strict;
  report.table.push_back(x.line.str() +
                         (x.strict ? "  converged" : "  converged (stalled below the acceptance tolerance)"));
  if (settings_.verbose) std::cout << "      " << report.table.back() << std::endl;
  report.converged = true;
  report.iterations = it;
  last_increment_ = solution_;
  last_increment_ -= step.u_start;
  commit();
  update_penalties();
  return report;
}

AxisymmetricNewtonReport AxisymmetricSolver::fail_step(Step& step, const std::string& why) {
  solution_ = step.u_start;
  punch_contact_ = step.punch_contact_start;
  punch_lateral_hold_ = step.punch_hold_start;
  cohesive_trial_ = cohesive_committed_;
  friction_trial_ = friction_committed_;
  assemble(solution_, true);
  step.report.converged = false;
  step.report.failure = why;
  if (settings_.verbose) std::cout << "      newton failed: " << why << std::endl;
  return step.report;
}

}  // namespace puncture::fem
