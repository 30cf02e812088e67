// axisymmetric_solver.hpp: quasi-static finite-strain solver of the layered
// slab in the meridian (r-z) plane, with the needle's cutting crack, the rigid
// needle in frictional contact, and the flat punch (deal.II, serial, sparse
// direct solves).
//
// In:  an AxisymmetricSlabMesh (meshing/: vertices (R, Z) in m, cells with a
//      layer index, the crack line R = r_c whose vertices exist twice), one
//      LayerMaterial per layer, one cohesive law and one friction pair per
//      layer, the needle (RigidNeedle for a cutting tip, or a flat punch of
//      radius a), AxisymmetricSettings.
// Out: the displacement (u_R, u_Z) (m) of every node; the axial needle force
//      (N, > 0 when the tissue resists insertion) split into its normal and
//      friction parts; the cohesive energy dissipated (J); the damage along
//      the crack; per-cell fields; VTU files of the meridian plane.
//
// Kinematics (Holzapfel 2000, Sec. 2; components ordered R, Z, theta):
//   F = [[1 + u_R,R, u_R,Z, 0], [u_Z,R, 1 + u_Z,Z, 0], [0, 0, 1 + u_R/R]],
//   dV = 2 pi R dA, so nodal forces are those of the whole ring (N).
// Material: any LayerMaterial (hyperelastic_materials.hpp) in the three-field
// Hu-Washizu form of the 3D solver (Q1-P0 or Q2-P1, condensed per cell), so
// the nearly incompressible layers do not lock. A layer given a Prony series
// (set_viscoelasticity) is viscoelastic (viscoelastic_material.hpp): its
// LayerMaterial is then the long-term law, every quadrature point keeps its
// Prony history, read during a step's Newton iterations and committed with
// the converged step (time step: set_time_step).
// Boundary conditions: base Z = -H fixed, lateral R = R_s fixed (the sample
// held in a ring), axis u_R = 0, top free except where the needle touches it.
// Crack: every pair of crack nodes is joined by the layer's cohesive law
// (cohesive_law.hpp) with the lumped (Newton-Cotes) area of the node, or, for
// layers that break by the older force/stretch criteria, tied by a
// constraint until break_layer() releases them.
// Needle: a cutting tip is a RigidNeedle (needle_contact.hpp) pushing on the
// top-surface and crack-face nodes by penalty contact with Coulomb friction
// on the outer side; the penalty stiffness of a node is contact_penalty x the
// diagonal of the bulk tangent at that node (at the start of the step), so it
// follows the stiffening of the tissue. A blunt tip is a flat punch: the top
// nodes it reaches get u_Z prescribed, and u_R held (no slip) or free
// (frictionless); its force is the sum of their reactions.
// Newton with backtracking line search on the free residual; histories
// (damage, stick points) are committed only when a step converges; on failure
// the last converged state is restored (the caller cuts the step). Nothing
// non-finite is kept.
#pragma once

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>
#include <deal.II/base/types.h>
#include <deal.II/base/timer.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include <iostream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <puncture/fem/cohesive_law.hpp>
#include <puncture/fem/hyperelastic_materials.hpp>
#include <puncture/fem/needle_contact.hpp>
#include <puncture/fem/viscoelastic_material.hpp>
#include <puncture/meshing/axisymmetric_slab_mesh.hpp>

namespace puncture::fem {

/// Numerical settings of the axisymmetric solver.
struct AxisymmetricSettings {
  unsigned int degree = 1;        ///< displacement element degree: 1 (Q1-P0) or 2 (Q2-P1)
  int max_newton_iterations = 25;
  /// Converged when the free residual <= tolerance x force scale (largest of
  /// the needle force, the reactions and the largest free residual of the
  /// step) or below absolute_residual_floor_N.
  double newton_tolerance = 1e-6;
  double absolute_residual_floor_N = 1e-10;
  int max_line_search_halvings = 6;
  /// Trust region of a Newton iteration: the largest nodal displacement of
  /// its direction, in tip element sizes (the direction is scaled down to
  /// it; 0: no limit).
  double max_newton_displacement = 0.5;
  /// Stall detection: a step whose best free residual has not fallen below
  /// stall_factor x its best before the last stall_window iterations is given
  /// up (and cut by the driver) instead of cycling up to max_newton_iterations
  /// (Newton can cycle at the kinks of contact and full damage). Slow but
  /// steady progress (the damped iterations through the skin's snap) is not a
  /// stall. stall_window 0: off.
  int stall_window = 10;
  double stall_factor = 0.9;
  /// A stalled step whose free residual is already below this fraction of the
  /// force scale is accepted (and reported as such) rather than cut: Newton
  /// cycling at 1e-5 of the needle force is a kink, not a wrong equilibrium.
  /// (For comparison, Abaqus' default accepts 5e-3 of the average force.)
  double stall_acceptance_tolerance = 1e-4;
  /// Threads that compute the cells' stiffness and forces (the system is
  /// added up in cell order, so results do not depend on this number).
  unsigned int assembly_threads = 1;
  double contact_penalty = 1e2;   ///< k_n / (diagonal of the bulk tangent at the node)
  double friction_penalty = 0.5;  ///< k_t / k_n
  /// The least elastic slip over which the shaft friction builds up to mu N,
  /// in tip element sizes (k_t is capped at mu N / that; nodal_contact).
  double friction_min_slip = 0.005;
  double contact_rounding = 0.02; ///< eps of the C1 penalty, in tip element sizes
  double edge_rounding = 0.25;    ///< shoulder rounding radius and inner-wall ramp height, in tip element sizes
  /// Hold the crack line at r <= r_c below the edge too (the ring crack stands
  /// for a slit through the axis, whose material cannot drift away from the tip).
  bool hold_crack_line = true;
  bool blunt_tip_no_slip = true;  ///< flat punch: hold u_R of touching nodes (else frictionless)
  /// Viscous stabilisation time tau (s): a Kelvin-Voigt stress
  /// (tau/dt) 2 mu_0 sym(H - H_step_start) on the step's strain increment
  /// (mu_0: the layer's initial shear modulus; rigid motion costs nothing).
  /// It carries the solution through a snap (the skin slipping over the tip,
  /// a crack running) where the quasi-static path has a limit point; it is
  /// small at full steps (tau/dt = 0.01 at 0.1 mm steps at 10 mm/s, against
  /// tissue that has stiffened far beyond mu_0) and grows when a step is cut,
  /// so a cut step converges. Its dissipated energy is reported.
  double stabilization_time_s = 1e-4;
  /// Pseudo-transient continuation of a step plain Newton cannot solve
  /// (solve_step; 0 pseudo-steps: off, the step fails at once): a viscous
  /// stress ratio x 2 mu_0 sym(H - H_k) on each pseudo-step's change, the
  /// ratio from initial down by `decrease` per converged pseudo-step, up by
  /// `increase` per failed one (at most max_failures), until below final,
  /// where plain Newton finishes the step. A pseudo-step gets at most
  /// continuation_max_iterations iterations.
  int continuation_steps = 60;
  int continuation_max_iterations = 15;  ///< per pseudo-step (a harder one raises the ratio)
  double continuation_initial_ratio = 1.0;
  double continuation_final_ratio = 1e-4;
  double continuation_decrease = 4.0;
  double continuation_increase = 8.0;
  int continuation_max_failures = 8;
  /// A second, slower continuation where the first does not reach the
  /// step's equilibrium (0 steps: none): from the step's start again, the
  /// ratio down by 2 per converged pseudo-step and up by 4 per failed one, for
  /// up to 400 pseudo-steps and 80 failures. A snap whose equilibrium lies far
  /// from the step's start (a layer giving way under the tip just after the
  /// one above broke) is crossed in many small pseudo-steps, where the first
  /// policy's ratio oscillates between failing and converging and gives up.
  int continuation_retry_steps = 400;
  double continuation_retry_decrease = 2.0;
  double continuation_retry_increase = 4.0;
  int continuation_retry_max_failures = 80;
  bool verbose = false;
};

/// One layer's crack behaviour.
///
/// For a bevel needle the ring crack of radius r_c = 2a/pi stands for the
/// planar crack of width 2a that the bevel opens (same face perimeter, 4a):
///   * area: one unit of ring area carries area_scale = 2a / (2 pi r_c) = 1/2
///     units of slit area, so the ring dissipates G_c x 2a per unit depth;
///   * opening: the ring face opens radially from r_c to a while the slit's
///     faces open to the needle width 2a, so the law's normal separation is
///     opening_scale = 2a / (a - r_c) times the radial opening of the ring.
/// The nodal forces are area x area_scale x (opening_scale t_n, t_t) and the
/// law (sigma_c, G_c) is the tissue's own. For a hollow needle both scales
/// are 1 (the lumen edge cuts a real ring).
struct LayerCrack {
  enum class Kind { Cohesive, TiedUntilBroken };
  Kind kind = Kind::Cohesive;
  CohesiveLawParameters law;  ///< Cohesive: the law (the tissue's sigma_c, G_c)
  double area_scale = 1.0;
  double opening_scale = 1.0;
};

/// Convergence record of one step.
struct AxisymmetricNewtonReport {
  bool converged = false;
  /// Converged to stall_acceptance_tolerance only (Newton stalled below it).
  bool accepted_at_stall = false;
  int iterations = 0;
  /// 1 when plain Newton failed and pseudo-transient continuation took over.
  int continuation_steps = 0;
  double residual_N = 0.0;
  double force_scale_N = 0.0;
  std::string failure;
  std::vector<std::string> table;
};

/// Axial force on the needle (N, > 0 when the tissue pushes it back up).
struct NeedleForce {
  double total_N = 0.0;
  double normal_N = 0.0;    ///< from the normal contact pressure (tip flank, punch face)
  double friction_N = 0.0;  ///< from the tangential (friction) tractions
  int nodes_in_contact = 0;
};

/// The undeformed geometry of one cell at its quadrature points: what the
/// total-Lagrangian assembly reads of a cell's FEValues<2>, kept once per cell
/// (the reference configuration never moves). Shape data are indexed
/// [q * dofs_per_cell + i] for shape function i at quadrature point q.
struct AxisymmetricCellGeometry {
  std::vector<dealii::types::global_dof_index> dofs;  ///< the cell's dofs, in the element's order
  std::vector<double> R_m;                            ///< radius of each quadrature point (m)
  std::vector<double> JxW_m2;                         ///< quadrature weight x Jacobian determinant (m^2)
  std::vector<double> shape_value;                    ///< N_i at point q
  std::vector<dealii::Tensor<1, 2>> shape_grad;       ///< grad N_i at point q (1/m)
  const std::vector<dealii::Point<2>>* unit_points = nullptr;  ///< the quadrature's points on the unit cell
  unsigned n_q = 0, dofs_per_cell = 0;
  double value(unsigned i, unsigned q) const { return shape_value[q * dofs_per_cell + i]; }
  const dealii::Tensor<1, 2>& grad(unsigned i, unsigned q) const { return shape_grad[q * dofs_per_cell + i]; }
};

class AxisymmetricSolver {
 public:
  /// core_materials: optional, one per layer, used instead of `materials` for
  /// the cells inside the crack radius along the needle path (the bevel's
  /// stand-in core is a compliant filler; see LayerCrack).
  AxisymmetricSolver(const meshing::AxisymmetricSlabMesh& mesh, std::vector<LayerMaterial> materials,
                     std::vector<LayerCrack> cracks, std::vector<FrictionCoefficients> friction,
                     const AxisymmetricSettings& settings, std::vector<LayerMaterial> core_materials = {});

  /// Optional, before setup(): one Prony series per layer (empty: that layer
  /// is elastic). The layer's material given to the constructor is then its
  /// long-term (relaxed) law; the core filler cells stay elastic.
  void set_viscoelasticity(const std::vector<std::vector<PronyTerm>>& prony_per_layer);

  /// Distributes the dofs, finds the crack pairs and the contact nodes, u = 0.
  void setup(double sample_radius_m, double total_thickness_m);
  const AxisymmetricSettings& settings() const { return settings_; }

  std::size_t n_dofs() const { return dof_handler_.n_dofs(); }
  std::size_t n_cells() const { return triangulation_.n_active_cells(); }
  const dealii::DoFHandler<2>& dof_handler() const { return dof_handler_; }

  // --- the needle -----------------------------------------------------------
  /// Cutting tip (bevel / hollow): the rigid needle and its position.
  void set_cutting_needle(const RigidNeedle& needle);
  /// Flat punch of radius a whose face is at height z_face_m (blunt tip).
  void set_flat_punch(double radius_m, double z_face_m);
  /// Time step of the coming solve (s), for the cohesive viscosity and the
  /// viscoelastic layers.
  void set_time_step(double dt_s) { dt_s_ = dt_s; }
  /// When set (> 0), a stalled Newton solve is accepted below this force (N),
  /// or below stall_acceptance_tolerance x the current needle force if that
  /// is larger, instead of below the tolerance x the step's force scale (which
  /// also holds the reactions at ties and supports, at times a hundred times
  /// the needle force). The insertion sets it to 1e-3 x the largest needle
  /// force of the run so far: every accepted step is then exact to 0.1 % of
  /// the run's peak, and the steps where the needle force is millinewtons
  /// (the end of a withdrawal) are held to the run's scale, not their own.
  void set_stall_acceptance_floor(double force_N) { stall_acceptance_floor_N_ = force_N; }

  // --- solving ----------------------------------------------------------------
  /// Newton solve of the current step from u + predictor_scale x (last
  /// increment) when admissible. Commits the histories on success; restores
  /// the last converged state on failure.
  /// With `continue_if_stuck`, a step plain Newton cannot solve is handed to
  /// pseudo-transient continuation before it fails (the insertion does so
  /// once cutting the load step has not helped).
  AxisymmetricNewtonReport solve_step(double predictor_scale = 0.0, bool continue_if_stuck = true);

  struct Snapshot {
    dealii::Vector<double> solution, last_increment;
    std::vector<CohesiveHistory> cohesive;
    std::vector<FrictionHistory> friction;
    std::vector<char> punch_contact;
    std::vector<double> punch_lateral_hold;
    std::vector<char> broken_layers;
    double dissipated_J = 0.0;
    double stabilization_J = 0.0;
    std::vector<std::vector<ViscoelasticHistory>> viscous_history;
  };
  Snapshot snapshot() const;
  void restore(const Snapshot& s);

  /// Releases the ties of a TiedUntilBroken layer's crack at once (older
  /// criteria) and marks its cohesive points fully damaged.
  void break_layer(int layer);

  // --- results ----------------------------------------------------------------
  NeedleForce needle_force() const { return force_; }
  double cohesive_dissipation_J() const { return dissipated_J_; }
  /// Energy dissipated by the viscous stabilisation so far (J).
  double stabilization_dissipation_J() const { return stabilization_J_; }
  /// Deepest crack point (depth below the surface, m) of the given layer whose
  /// damage >= threshold (-1: none): the rate-independent damage its largest
  /// separation so far calls for (bilinear_damage), which the viscously
  /// regularised damage follows with a delay of the cohesive viscosity.
  double crack_front_depth_m(int layer, double damage_threshold = 0.999) const;
  /// Largest damage of the crack points of a layer.
  double max_damage(int layer) const;
  /// u_Z (m) along the horizontal line Z = z_line_m (nodes with both
  /// components), sorted by R: (R, u_Z). Both sides of the crack are listed.
  std::vector<std::pair<double, double>> vertical_displacement_along(double z_line_m) const;
  /// Maximum principal stretch over the quadrature points of the cells of a
  /// layer within radius r_max of the axis and depth range [z_lo, z_hi].
  double max_principal_stretch(int layer, double r_max_m, double z_lo_m, double z_hi_m) const;
  /// Displacement of the node nearest to (R, Z) (m).
  std::array<double, 2> displacement_at(double R_m, double Z_m) const;

  /// Writes the meridian plane (x = R, y = Z, m) with displacement, layer,
  /// J, von Mises stress (Pa), maximum principal stretch and crack damage.
  void write_vtu(const std::string& path) const;

  const dealii::Vector<double>& solution() const { return solution_; }

 private:
  struct ContactNode {
    unsigned dof_r, dof_z;
    double R, Z;           ///< reference position
    double area_m2;        ///< lumped boundary area (2 pi R x tributary length)
    bool core_side;
    int layer;
    bool on_top;           ///< on the top surface (flat punch candidates)
    int partner = -1;      ///< the other copy of a crack node at the same place (-1: none)
  };
  /// True if this contact node's z dof is tied to its partner's (unbroken tied layer).
  bool tied_slave(std::size_t node) const;
  struct CohesivePoint {
    bool to_plane = false;  ///< tied to the rigid crack plane R = r_c (open channel) instead of a core node
    unsigned core_r, core_z, outer_r, outer_z;
    double Z;
    double area_m2;
    int layer;
  };
  // --- setup(), in this order ------------------------------------------------
  /// Triangulation of the mesh, boundary ids of its faces, the core cells.
  void build_triangulation(double sample_radius_m, double total_thickness_m, double tol);
  /// Dofs, the cell list and its scratch, the homogeneous Dirichlet constraints.
  void distribute_dofs_and_constraints();
  /// Cohesive points: the crack dofs paired across the crack (or tied to its plane).
  void find_crack_pairs(const std::vector<dealii::Point<2>>& support, double tol);
  /// Open channel: the outer wall nodes of face f tied to the crack plane.
  void add_channel_wall_points(const dealii::DoFHandler<2>::active_cell_iterator& cell, unsigned f,
                               const std::vector<dealii::Point<2>>& support, double tol);
  /// The cohesive points joining core face f to its outer copy outer_f.
  void pair_crack_face(const dealii::DoFHandler<2>::active_cell_iterator& cell, unsigned f,
                       const dealii::DoFHandler<2>::active_cell_iterator& outer_cell, unsigned outer_f,
                       const std::vector<dealii::Point<2>>& support, double tol);
  /// Contact nodes of the top surface and crack faces, their areas and partners.
  void find_contact_nodes(const std::vector<dealii::Point<2>>& support, double tol);
  /// Sparsity of the cells and of every possible crack coupling.
  void make_sparsity();
  /// Matrices, vectors and the histories of the unloaded slab (u = 0).
  void allocate_state();

  // --- solve_step(), one Newton step in phases --------------------------------
  struct Step;     ///< what the phases of one step share (defined in the .cc)
  struct Iterate;  ///< one Newton iterate: residual, force scale, tests, log line (in the .cc)
  using Failure = std::optional<std::string>;  ///< why the step fails (nullopt: it goes on)
  /// Saves the start of the step, applies the predictor, lets the punch take in the nodes it reaches.
  void start_step(Step& step, double predictor_scale);
  /// Assembles at solution_: the free residual, the force scale, stall and convergence tests.
  Failure evaluate_iterate(Step& step, int it, Iterate& x);
  /// The free residual (N) at u (infinity where u is inverted or non-finite).
  double free_residual_at(const dealii::Vector<double>& u);
  /// Appends the free residual to the step's history; true if Newton stalls.
  bool check_stall(std::vector<double>& history, double free) const;
  /// The iterate's line of the Newton log (residual, scale, force, contact and crack counts).
  void write_iterate_line(int it, Iterate& x) const;
  /// Flat punch: frees the nodes the face would pull (tensile reaction); true if any.
  bool release_pulled_punch_nodes(std::vector<char>& released_in_step, double scale);
  /// Flat punch: the top nodes within its radius that the face has reached join; true if any.
  bool update_punch_contact(const std::vector<char>& released_in_step);
  /// Too many iterations or a stall: why the step is given up (nullopt: go on).
  Failure give_up_reason(int it, const Iterate& x, int max_iterations) const;
  /// Newton direction: K du = -R with the increment constraints condensed in.
  Failure newton_direction(Step& step, Iterate& x);
  /// Backtracking line search along du from solution_: the step length alpha and step.trial.
  Failure line_search(Step& step, const Iterate& x, double& alpha);
  /// Pseudo-steps from the step's start under one policy of the ratio; true
  /// if the ratio fell below continuation_final_ratio (the state is then
  /// near the step's equilibrium).
  bool pseudo_transient(Step& step, int steps, int max_failures, double decrease, double increase);
  /// Diagnostic (PUNCTURE_FEM_CHECK_TANGENT set): the assembled tangent along
  /// the Newton direction against central differences of the residual, on
  /// the free dofs, split into contact-node, cohesive and other dofs; one
  /// line for the Newton log. Leaves the state as it found it (reassembles).
  std::string tangent_check(const Step& step, const dealii::Vector<double>& direction);
  /// At most max_iterations Newton iterations from solution_ to convergence
  /// (nullopt) or to why they fail.
  Failure newton(Step& step, int max_iterations);
  /// Pseudo-transient continuation from the step's start after plain Newton failed.
  Failure continue_step(Step& step, const std::string& plain_failure);
  /// The state at the start of the step (solution, punch contact, trial histories).
  void restore_step_start(Step& step);
  /// A converged step: the last increment, the histories committed.
  AxisymmetricNewtonReport accept_step(Step& step);
  /// A failed step: the state at its start restored, the reason reported.
  AxisymmetricNewtonReport fail_step(Step& step, const std::string& why);

  // --- assemble(): residual_ and (with_matrix) tangent_ at u -----------------
  /// Cells, cohesive crack, needle; the trial histories and needle force; false
  /// on an inverted or non-finite state.
  bool assemble(const dealii::Vector<double>& u, bool with_matrix);
  /// Every cell's stiffness and forces into cell_work_, on assembly_threads threads.
  bool compute_cell_contributions(const dealii::Vector<double>& u, bool with_matrix);
  /// Adds cell_work_ to the system in cell order (and the bulk diagonal, the stabilisation energy).
  void add_cell_contributions(bool with_matrix);
  /// The cohesive tractions of the crack points (trial histories, dissipation); false if non-finite.
  bool add_cohesive_forces(const dealii::Vector<double>& u, bool with_matrix);
  /// Cutting tip: penalty contact with Coulomb friction at the contact nodes, the needle force.
  void add_needle_contact(const dealii::Vector<double>& u, bool with_matrix);
  /// Flat punch: its force from the reactions of the nodes it holds.
  void add_punch_reactions();

  /// The Newton increment's constraints at u: Dirichlet, unbroken ties, the flat punch.
  void make_constraints(const dealii::Vector<double>& u, dealii::AffineConstraints<double>& c) const;
  /// Norm of residual_ over the dofs c leaves free (constrained dofs hand theirs to their masters).
  double free_residual_norm(const dealii::AffineConstraints<double>& c) const;
  /// Contact penalties from the bulk diagonal of the last assembly.
  void update_penalties();
  /// Makes the trial histories, dissipation and needle force the committed ones.
  void commit();

  const meshing::AxisymmetricSlabMesh& mesh_;
  std::vector<LayerMaterial> materials_, core_materials_;
  std::vector<char> core_cell_;  ///< per active cell: inside the crack radius on the needle path
  const LayerMaterial& material_of(const dealii::DoFHandler<2>::active_cell_iterator& cell) const;
  /// Per layer: its viscoelastic law (absent: elastic).
  std::vector<std::optional<ViscoelasticMaterial<LayerMaterial>>> viscoelastic_;
  /// Per active cell: the Prony history of its quadrature points at the last
  /// converged step (empty for elastic cells).
  std::vector<std::vector<ViscoelasticHistory>> viscous_history_;
  /// The viscoelastic law of a cell (nullptr: elastic).
  const ViscoelasticMaterial<LayerMaterial>* viscoelastic_of(
      const dealii::DoFHandler<2>::active_cell_iterator& cell) const;
  /// Advances every viscoelastic point's history to the converged solution_.
  void commit_viscous_history();
  std::vector<LayerCrack> cracks_;
  std::vector<FrictionCoefficients> friction_;
  AxisymmetricSettings settings_;
  dealii::Triangulation<2> triangulation_;
  dealii::FESystem<2> fe_;
  dealii::DoFHandler<2> dof_handler_;
  dealii::AffineConstraints<double> dirichlet_;  ///< homogeneous: base, lateral, axis
  dealii::SparsityPattern sparsity_;
  dealii::SparseMatrix<double> tangent_, system_matrix_;
  dealii::Vector<double> residual_, rhs_, solution_, last_increment_, bulk_diagonal_;
  /// One cell's stiffness, forces and stabilisation energy of an assembly.
  struct CellContribution {
    dealii::FullMatrix<double> Ke;
    dealii::Vector<double> Re;
    double stabilization_J = 0.0;
  };
  std::vector<dealii::DoFHandler<2>::active_cell_iterator> cells_;
  std::vector<CellContribution> cell_work_;
  /// Per cell of cells_: its undeformed geometry (made once with the dofs), and
  /// the quadrature's unit points it refers to.
  std::vector<AxisymmetricCellGeometry> geometry_;
  std::vector<dealii::Point<2>> unit_points_;
  std::vector<unsigned> shape_component_;  ///< per shape function: 0 (u_R) or 1 (u_Z)
  /// Cells [begin, end) of cells_ into cell_work_; false on an inverted or
  /// non-finite state.
  bool assemble_cells(std::size_t begin, std::size_t end, const dealii::Vector<double>& u, bool with_matrix);

  std::vector<ContactNode> contact_nodes_;
  std::vector<CohesivePoint> cohesive_points_;
  std::vector<CohesiveHistory> cohesive_committed_, cohesive_trial_;
  std::vector<FrictionHistory> friction_committed_, friction_trial_;
  /// The branch each cohesive point (bit 0: loading, bit 1: opening) and each
  /// contact node (bit 0: in contact) is on at the last assembly, and at the
  /// iterate before: the Newton log counts the switches between iterates (a
  /// Newton that cycles at a kink of the laws shows them).
  std::vector<unsigned char> cohesive_branch_, contact_branch_;
  mutable std::vector<unsigned char> cohesive_branch_logged_, contact_branch_logged_;
  std::vector<double> penalty_;  ///< k_n per contact node (N/m)
  std::vector<char> broken_layers_;
  double dissipated_J_ = 0.0, dissipated_trial_J_ = 0.0;
  double stabilization_J_ = 0.0, stabilization_trial_J_ = 0.0;
  dealii::Vector<double> step_start_;  ///< u at the start of the step (viscous stabilisation)
  /// Pseudo-transient continuation: the viscous ratio (0: off) and the state
  /// of the last pseudo-step it acts on.
  double continuation_ratio_ = 0.0;
  double stall_acceptance_floor_N_ = 0.0;
  dealii::Vector<double> continuation_reference_;

  // needle
  bool cutting_ = true;
  RigidNeedle needle_;
  double punch_radius_m_ = 0.0, punch_z_m_ = 0.0;
  std::vector<char> punch_contact_;         ///< per contact node: touching the punch face
  std::vector<double> punch_lateral_hold_;  ///< u_R held while touching (no slip)
  double dt_s_ = 0.0;
  NeedleForce force_, force_trial_;
  bool debug_contacts_ = false;
  /// Wall time by section ("assemble", "linear solve"); the Newton log's
  /// per-iteration times are differences of its totals. Never printed by itself.
  dealii::TimerOutput timer_{std::cout, dealii::TimerOutput::never, dealii::TimerOutput::wall_times};
};

}  // namespace puncture::fem
