// axisymmetric_solver_output.cc: the results of the axisymmetric solver read
// from its converged state (crack front, damage, displacements, stretches)
// and its VTU files; see axisymmetric_solver.hpp.
#include <puncture/fem/axisymmetric_solver.hpp>
#include <puncture/fem/kinematics.hpp>

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/numerics/data_out.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <stdexcept>

#include "axisymmetric_cell.hpp"

namespace puncture::fem {

using namespace dealii;
using axisymmetric_cell::CellState;
using axisymmetric_cell::DisplacementGradients;
using axisymmetric_cell::ViscousCell;
using axisymmetric_cell::evaluate_cell;

double AxisymmetricSolver::crack_front_depth_m(int layer, double damage_threshold) const {
  double depth = -1.0;
  for (std::size_t k = 0; k < cohesive_points_.size(); ++k) {
    if (cohesive_points_[k].layer != layer) continue;
    // The damage the separation reached calls for (without the viscous lag).
    const CohesiveHistory& h = cohesive_committed_[k];
    const double damage = std::max(h.damage, bilinear_damage(cracks_[layer].law, h.max_separation_m));
    if (damage >= damage_threshold) depth = std::max(depth, -cohesive_points_[k].Z);
  }
  return depth;
}

double AxisymmetricSolver::max_damage(int layer) const {
  double d = 0.0;
  for (std::size_t k = 0; k < cohesive_points_.size(); ++k)
    if (cohesive_points_[k].layer == layer) d = std::max(d, cohesive_committed_[k].damage);
  return d;
}

std::vector<std::pair<double, double>> AxisymmetricSolver::vertical_displacement_along(double z_line_m) const {
  std::vector<Point<2>> support(dof_handler_.n_dofs());
  DoFTools::map_dofs_to_support_points(MappingQ1<2>(), dof_handler_, support);
  std::vector<std::pair<double, double>> out;
  const double tol = 1e-9;
  std::vector<types::global_dof_index> dofs(fe_.n_dofs_per_cell());
  std::vector<char> seen(dof_handler_.n_dofs(), 0);
  for (const auto& cell : dof_handler_.active_cell_iterators()) {
    cell->get_dof_indices(dofs);
    for (unsigned i = 0; i < dofs.size(); ++i) {
      if (fe_.system_to_component_index(i).first != 1 || seen[dofs[i]]) continue;
      seen[dofs[i]] = 1;
      if (std::abs(support[dofs[i]][1] - z_line_m) < tol) out.emplace_back(support[dofs[i]][0], solution_(dofs[i]));
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

double AxisymmetricSolver::max_principal_stretch(int layer, double r_max_m, double z_lo_m, double z_hi_m) const {
  const unsigned nq = unit_points_.size();
  std::vector<Tensor<2, 3>> H(nq);
  DisplacementGradients gradients(nq, shape_component_);
  double stretch = 1.0;
  for (std::size_t k = 0; k < cells_.size(); ++k) {
    const auto& cell = cells_[k];
    if (static_cast<int>(cell->material_id()) != layer) continue;
    const Point<2> c = cell->center();
    if (c[0] > r_max_m || c[1] < z_lo_m || c[1] > z_hi_m) continue;
    gradients.compute(geometry_[k], solution_, H);
    for (unsigned q = 0; q < nq; ++q) {
      const Tensor<2, 3> F = Tensor<2, 3>(unit_symmetric_tensor<3>()) + H[q];
      const auto ev = eigenvalues(right_cauchy_green(F));
      stretch = std::max(stretch, std::sqrt(std::max(ev[0], 0.0)));
    }
  }
  return stretch;
}

std::array<double, 2> AxisymmetricSolver::displacement_at(double R_m, double Z_m) const {
  std::vector<Point<2>> support(dof_handler_.n_dofs());
  DoFTools::map_dofs_to_support_points(MappingQ1<2>(), dof_handler_, support);
  const Point<2> p(R_m, Z_m);
  double best[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  std::array<double, 2> u{0.0, 0.0};
  std::vector<types::global_dof_index> dofs(fe_.n_dofs_per_cell());
  for (const auto& cell : dof_handler_.active_cell_iterators()) {
    cell->get_dof_indices(dofs);
    for (unsigned i = 0; i < dofs.size(); ++i) {
      const unsigned c = fe_.system_to_component_index(i).first;
      const double d = support[dofs[i]].distance(p);
      if (d < best[c]) {
        best[c] = d;
        u[c] = solution_(dofs[i]);
      }
    }
  }
  return u;
}

void AxisymmetricSolver::write_vtu(const std::string& path) const {
  const unsigned n = triangulation_.n_active_cells();
  Vector<double> layer(n), J(n), von_mises(n), stretch(n), damage(n);
  const unsigned nq = unit_points_.size();
  DisplacementGradients gradients(nq, shape_component_);
  std::vector<Tensor<2, 3>> H(nq);
  CellState st;
  for (std::size_t k = 0; k < cells_.size(); ++k) {
    const auto& cell = cells_[k];
    const unsigned c = cell->active_cell_index();
    gradients.compute(geometry_[k], solution_, H);
    layer(c) = cell->material_id();
    // dt = 0 with the committed history: the committed (converged) stress.
    const ViscousCell viscous{viscoelastic_of(cell), &viscous_history_[c], 0.0};
    const bool ok = evaluate_cell(material_of(cell), settings_.degree, geometry_[k], H, st, true, viscous);
    double j_sum = 0.0, vm_sum = 0.0, s_max = 1.0;
    for (unsigned q = 0; q < nq; ++q) {
      const Tensor<2, 3> F = Tensor<2, 3>(unit_symmetric_tensor<3>()) + H[q];
      const double Jq = determinant(F);
      j_sum += Jq;
      const auto ev = eigenvalues(right_cauchy_green(F));
      s_max = std::max(s_max, std::sqrt(std::max(ev[0], 0.0)));
      if (ok) {
        const Tensor<2, 3> sigma = (1.0 / Jq) * F * Tensor<2, 3>(st.S[q]) * transpose(F);
        const SymTensor2 s = deviator(symmetrize(sigma));
        vm_sum += std::sqrt(1.5 * scalar_product(s, s));
      }
    }
    J(c) = j_sum / nq;
    von_mises(c) = vm_sum / nq;
    stretch(c) = s_max;
  }
  // Crack damage on the cells along the crack (largest of their points).
  std::map<unsigned, double> damage_of_dof;
  for (std::size_t k = 0; k < cohesive_points_.size(); ++k) {
    const CohesivePoint& cp = cohesive_points_[k];
    damage_of_dof[cp.core_r] = std::max(damage_of_dof[cp.core_r], cohesive_committed_[k].damage);
    damage_of_dof[cp.outer_r] = std::max(damage_of_dof[cp.outer_r], cohesive_committed_[k].damage);
  }
  std::vector<types::global_dof_index> dofs(fe_.n_dofs_per_cell());
  for (const auto& cell : dof_handler_.active_cell_iterators()) {
    cell->get_dof_indices(dofs);
    double d = 0.0;
    for (auto dof : dofs) {
      const auto it = damage_of_dof.find(dof);
      if (it != damage_of_dof.end()) d = std::max(d, it->second);
    }
    damage(cell->active_cell_index()) = d;
  }
  DataOut<2> out;
  out.attach_dof_handler(dof_handler_);
  std::vector<std::string> names{"displacement_m", "displacement_m"};
  std::vector<DataComponentInterpretation::DataComponentInterpretation> interp(
      2, DataComponentInterpretation::component_is_part_of_vector);
  out.add_data_vector(solution_, names, DataOut<2>::type_dof_data, interp);
  out.add_data_vector(layer, "layer_id");
  out.add_data_vector(J, "J");
  out.add_data_vector(von_mises, "von_mises_Pa");
  out.add_data_vector(stretch, "max_principal_stretch");
  out.add_data_vector(damage, "crack_damage");
  out.build_patches(settings_.degree);
  std::ofstream file(path);
  if (!file) throw std::runtime_error("cannot write " + path);
  out.write_vtu(file);
  if (!file) throw std::runtime_error("error while writing " + path);
}

}  // namespace puncture::fem
