// internal_forces.hpp: the internal (elastic and visco-elastic) nodal forces
// of the volumetric comparison models on a tetrahedral mesh (seed paper 001).
//
// Every law maps node positions x (3N, m), velocities v (3N, m/s) and, for the
// visco-elastic law, internal variables q to nodal forces f (3N, N: the force
// the tissue exerts on each node) and dq/dt. The dynamics M x'' = f - Y x'
// (Y = alpha M) is integrated by volumetric_model.hpp.
//
//   MassSpringLaw       conventional volumetric mass-spring model: one spring
//                       per tetrahedron edge. Seed 001's form (SpringKind::
//                       Linear, the default): M x'' = -K (x - x0) - Y x' with
//                       K constant, each spring's k n0 n0^T about its rest
//                       direction n0, f = k (n0 . (u_b - u_a)) n0; or
//                       geometrically exact springs (SpringKind::Nonlinear),
//                       f = k (|l| - l0) l/|l|, whose compressed springs buckle
//                       sideways under the tip. Spring
//                       stiffness by Van Gelder's rule (A. Van Gelder 1998,
//                       "Approximate simulation of elastic membranes by
//                       triangulated spring meshes", J. Graphics Tools 3(2),
//                       its volumetric form): k_e = E sum_{T containing e} V_T / l_e^2
//                       times a per-layer factor (identification, section 4
//                       of the comparison). A central-force lattice cannot
//                       represent an arbitrary Poisson ratio (Cauchy
//                       relations): nu is not used.
//   LinearTensorMass    Cotin, Delingette, Ayache (2000): linear elasticity on
//                       P1 tetrahedra with the stiffness stored as 3 x 3
//                       tensors per vertex (K_aa) and per edge (K_ab);
//                       f_a = -(K_aa u_a + sum_b K_ab u_b), u = x - X.
//   StvkTensorMass      Picinbono, Delingette, Ayache (2003): St Venant-Kirchhoff
//                       energy on P1 tetrahedra (large displacements, rotation
//                       invariant); f = -dW/dx (tet_elements.hpp). The force is
//                       evaluated per tetrahedron from the precomputed shape
//                       gradients, the factored form of Picinbono's vertex,
//                       edge, triangle and tetrahedron tensors (same energy).
//   ViscoelasticTensorMass  StVK with a Prony series (quasi-linear
//                       visco-elasticity, the extension of Schwartz, Denninger,
//                       Rancourt, Moisan, Laurendeau 2005 of Picinbono's model):
//                       S = S_e(E) + sum_k Q_k with dQ_k/dt = g_k dS_e/dt - Q_k / tau_k,
//                       one symmetric Q_k per tetrahedron and term (6 numbers),
//                       so a step response relaxes as S_e (1 + sum g_k exp(-t/tau_k)):
//                       the scene's modulus is the long-term one. The internal
//                       variables are part of the integrated state: no history
//                       is stored (the cost the seed paper warns of).
//
// Puncture removes tetrahedra (the needle column of a broken layer):
// set_removed(mask) drops their contributions (springs of edges with no
// remaining tetrahedron vanish).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "puncture/comparison/block_sparse.hpp"
#include "puncture/comparison/tet_elements.hpp"
#include "puncture/meshing/tet_mesh.hpp"

namespace puncture::comparison {

using meshing::TetMesh;  // the comparison models work on meshing's tetrahedral slab

using VectorRef = Eigen::Ref<const Eigen::VectorXd>;
using MutableVectorRef = Eigen::Ref<Eigen::VectorXd>;

/// Small-strain moduli and density of one layer (index = TetMesh::layer).
struct LayerElasticity {
  double youngs_modulus_Pa = 0.0;
  double poisson_ratio = 0.0;
  double density_kg_per_m3 = 0.0;
};

class InternalForceLaw {
 public:
  virtual ~InternalForceLaw() = default;
  virtual std::string name() const = 0;
  /// Number of internal variables integrated with the state (0 for elastic laws).
  virtual int extra_state_size() const { return 0; }
  /// f += internal forces at (x, v, q); qdot = dq/dt (size extra_state_size()).
  virtual void add_forces(VectorRef x, VectorRef v, const double* q, MutableVectorRef f,
                          double* qdot) const = 0;
  /// K += tangent stiffness -df/dx at x (symmetric). `gamma` is the implicit
  /// integrator's step scale (laws with internal variables fold their
  /// short-time stiffening into K with it); gamma = 0 asks for the exact
  /// elastic tangent of a static solve (the mass-spring law otherwise drops
  /// the negative stiffness of compressed springs).
  virtual void add_tangent(VectorRef x, double gamma, NodeBlockMatrix& K) const = 0;
  /// True if add_tangent is the exact derivative of add_forces (not for the
  /// visco-elastic law), so a Jacobian-vector product may use it.
  virtual bool tangent_is_exact() const { return true; }
  /// True if the forces are f = -K0 (x - X) with K0 the tangent at rest
  /// (constant), so a few nodes' forces are a few columns of K0.
  virtual bool is_linear() const { return false; }
  /// Elastic energy (J) at x (the long-term part for the visco-elastic law).
  virtual double energy_J(VectorRef x) const = 0;
  /// Tetrahedra flagged 1 no longer contribute.
  virtual void set_removed(const std::vector<std::uint8_t>& removed) = 0;
  virtual std::size_t memory_bytes() const = 0;
  /// Absolute tolerance of the internal variables (their unit) and the decay
  /// rates 1/tau of each (for the preconditioner).
  virtual double extra_state_abs_tolerance() const { return 1.0; }
  virtual void extra_state_decay_rates(std::vector<double>& rates) const { rates.clear(); }
  /// For the implicit preconditioner of laws with internal variables (q' =
  /// h(v) - q / tau, forces linear in q): f += the nodal forces of the
  /// internal variables r_q / (1 + gamma / tau) at positions x.
  virtual void add_internal_variable_forces(VectorRef x, const double* r_q, double gamma, MutableVectorRef f) const {
    (void)x, (void)r_q, (void)gamma, (void)f;
  }
  /// z_q = (r_q + gamma h(b)) / (1 + gamma / tau): the internal variables' part
  /// of the Newton correction once the velocity part b is known.
  virtual void internal_variable_correction(VectorRef x, VectorRef b, const double* r_q, double gamma,
                                            double* z_q) const {
    (void)x, (void)b, (void)r_q, (void)gamma, (void)z_q;
  }
};

/// Node pairs coupled by the mesh's tetrahedra (for NodeBlockMatrix).
std::vector<std::pair<int, int>> tet_node_pairs(const TetMesh& mesh);
/// Unique edges (a < b) of the mesh's tetrahedra, sorted.
std::vector<std::pair<int, int>> tet_edges(const TetMesh& mesh);

/// How a spring's force depends on its end points: linearised about the rest
/// direction (seed 001's constant K) or geometrically exact.
enum class SpringKind { Linear, Nonlinear };
SpringKind parse_spring_kind(const std::string& name);  ///< "linear", "nonlinear"; throws otherwise
const char* to_string(SpringKind kind);

class MassSpringLaw final : public InternalForceLaw {
 public:
  /// layer_scale: one factor per layer on the Van Gelder stiffness (empty: 1).
  MassSpringLaw(const TetMesh& mesh, const std::vector<LayerElasticity>& layers, std::vector<double> layer_scale = {},
                SpringKind kind = SpringKind::Linear);
  std::string name() const override { return "msm"; }
  SpringKind spring_kind() const { return kind_; }
  bool is_linear() const override { return kind_ == SpringKind::Linear; }
  void add_forces(VectorRef x, VectorRef v, const double* q, MutableVectorRef f,
                  double* qdot) const override;
  void add_tangent(VectorRef x, double gamma, NodeBlockMatrix& K) const override;
  double energy_J(VectorRef x) const override;
  void set_removed(const std::vector<std::uint8_t>& removed) override;
  std::size_t memory_bytes() const override;

  const std::vector<std::pair<int, int>>& edges() const { return edges_; }
  const std::vector<double>& stiffness_N_per_m() const { return stiffness_; }
  const std::vector<double>& rest_length_m() const { return rest_length_; }

 private:
  void compute_stiffness(const std::vector<std::uint8_t>& removed);

  const TetMesh* mesh_;
  std::vector<LayerElasticity> layers_;
  std::vector<double> layer_scale_;
  std::vector<std::pair<int, int>> edges_;
  std::vector<double> rest_length_;
  std::vector<Eigen::Vector3d> rest_direction_;  ///< n0 of each edge, from its first to its second node
  std::vector<double> stiffness_;
  SpringKind kind_;
};

class LinearTensorMass final : public InternalForceLaw {
 public:
  LinearTensorMass(const TetMesh& mesh, const std::vector<LayerElasticity>& layers);
  std::string name() const override { return "mass_tensor"; }
  bool is_linear() const override { return true; }
  void add_forces(VectorRef x, VectorRef v, const double* q, MutableVectorRef f,
                  double* qdot) const override;
  void add_tangent(VectorRef x, double gamma, NodeBlockMatrix& K) const override;
  double energy_J(VectorRef x) const override;
  void set_removed(const std::vector<std::uint8_t>& removed) override;
  std::size_t memory_bytes() const override;

  const std::vector<Eigen::Matrix3d>& vertex_tensors() const { return vertex_; }
  const std::vector<std::pair<int, int>>& edges() const { return edges_; }
  const std::vector<Eigen::Matrix3d>& edge_tensors() const { return edge_; }  ///< K_ab for edge (a < b)

 private:
  void compute_tensors(const std::vector<std::uint8_t>& removed);

  const TetMesh* mesh_;
  std::vector<LayerElasticity> layers_;
  Eigen::VectorXd rest_;
  std::vector<std::pair<int, int>> edges_;
  std::vector<Eigen::Matrix3d> vertex_;
  std::vector<Eigen::Matrix3d> edge_;
};

class StvkTensorMass : public InternalForceLaw {
 public:
  StvkTensorMass(const TetMesh& mesh, const std::vector<LayerElasticity>& layers);
  std::string name() const override { return "nonlinear_mass_tensor"; }
  void add_forces(VectorRef x, VectorRef v, const double* q, MutableVectorRef f,
                  double* qdot) const override;
  void add_tangent(VectorRef x, double gamma, NodeBlockMatrix& K) const override;
  double energy_J(VectorRef x) const override;
  void set_removed(const std::vector<std::uint8_t>& removed) override;
  std::size_t memory_bytes() const override;

 protected:
  Matrix34d element_positions(VectorRef x, int t) const;
  const TetMesh* mesh_;
  std::vector<TetShape> shape_;
  std::vector<LameParameters> lame_;
  std::vector<std::uint8_t> removed_;
};

struct PronySeries {
  std::vector<double> g;      ///< relative moduli g_k >= 0
  std::vector<double> tau_s;  ///< relaxation times tau_k > 0
};

class ViscoelasticTensorMass final : public StvkTensorMass {
 public:
  ViscoelasticTensorMass(const TetMesh& mesh, const std::vector<LayerElasticity>& layers, PronySeries prony);
  std::string name() const override { return "viscoelastic_mass_tensor"; }
  int extra_state_size() const override { return 6 * static_cast<int>(prony_.g.size()) * mesh_->tet_count(); }
  void add_forces(VectorRef x, VectorRef v, const double* q, MutableVectorRef f,
                  double* qdot) const override;
  /// Elastic tangent scaled by 1 + sum_k g_k tau_k / (tau_k + gamma): the
  /// stiffening of the internal stresses over one implicit step of scale gamma.
  void add_tangent(VectorRef x, double gamma, NodeBlockMatrix& K) const override;
  bool tangent_is_exact() const override { return false; }
  std::size_t memory_bytes() const override;
  double extra_state_abs_tolerance() const override { return abs_tol_Pa_; }
  void extra_state_decay_rates(std::vector<double>& rates) const override;
  void add_internal_variable_forces(VectorRef x, const double* r_q, double gamma, MutableVectorRef f) const override;
  void internal_variable_correction(VectorRef x, VectorRef b, const double* r_q, double gamma,
                                    double* z_q) const override;
  const PronySeries& prony() const { return prony_; }

 private:
  PronySeries prony_;
  double abs_tol_Pa_ = 1.0;
};

}  // namespace puncture::comparison
