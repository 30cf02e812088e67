// needle_insertion.hpp: the FEM reference of a needle insertion into the
// layered slab of a Scene (the one function the command-line program calls).
//
// In:  a Scene (SI units; geometry convention of scene.hpp: sample axis = z,
//      skin top at z = 0, needle along -z on the axis, depth = -z_tip),
//      FemRunOptions, an MPI communicator.
// Out: FemRunSummary, and in options.output_dir (created if missing; every
//      file written under a temporary name and renamed when complete):
//        fem_force_depth.csv      time_s, depth_mm, velocity_mm_per_s, force_N,
//                                 tip_stretch (max principal stretch at the tip
//                                 in the pressed layer; 1 without contact),
//                                 <layer>_state (untouched|pressed|punctured)...
//        fem_surface_profile.csv  step, depth_mm, r_mm, uz_mm, surface: u_z(r) of
//                                 the top surface of the layer the needle
//                                 currently presses (the intact layer)
//        fem_recovery_profile.csv layer, phase (before|after breakthrough),
//                                 depth_mm, r_mm, uz_mm: spring-back of the
//                                 punctured surface (reference for resumption)
//        fem_newton_log.txt       the Newton convergence table of every step
//        fem_summary.json         events, peak force, counts, timings, files
//        fem_fields_*.vtu/.pvtu, fem_fields.pvd (if write_vtu)
//
// Model: bonded layers; base fixed (u = 0); lateral surface r = D/2 fixed
// (u = 0: sample held in a rigid ring). The needle tip is a rigid flat
// cylinder of the scene's radius: a node of the current top interface with
// r <= needle radius joins the contact set when the tip reaches it (its
// current z >= z_tip); from then on u_z = z_tip - Z and its lateral
// displacement is held (no slip under the flat tip). Needle force (N, > 0
// resisting the insertion) = -(sum of the z reactions on the contact dofs),
// each dof counted by its owning rank, then MPI-summed. When the layer's
// puncture criterion is met (critical force, or critical maximum principal
// stretch in the cells touching the contact patch) its cells with centre
// inside the needle radius become void (linear material with
// void_stiffness_fraction x E; see finite_strain_solver.hpp), the contact set
// is released and the same depth is re-solved (spring-back, recorded) and the
// tip goes on to the next interface. The spring-back is a homotopy in
// lambda = 1 -> 0 over spring_back_stages stages: the internal force the
// removed cells exerted is kept as a frozen load scaled by lambda (force
// release, as in excavation analysis), and the released contact nodes hang
// on anchor springs of lambda^2 x 100x the contact patch stiffness per node;
// a stage that fails is retried from the last converged one with half the
// lambda step. Quasi-static load steps of scene.fem.load_step_m
// from the start height to the target depth; each step starts from the
// previous step's increment, extrapolated. A step after which the puncture
// criterion holds is undone and bisected until the crossing is located to
// puncture_depth_resolution_m. A step that fails (no convergence, a stalled
// line search, inverted elements) is halved, down to 1/256 of the load step,
// then the run stops with an error. The FEM stops at the target depth: dwell
// and withdrawal are not simulated.
#pragma once

#include <mpi.h>

#include <functional>
#include <string>
#include <vector>

#include <deal.II/distributed/tria.h>

#include <puncture/meshing/layered_cylinder_mesh.hpp>
#include <puncture/scene.hpp>

namespace puncture::fem {

struct FemRunOptions {
  std::string output_dir;        ///< created if missing
  int refinement_override = -1;  ///< >= 0 replaces scene.fem.refinement
  int degree_override = -1;      ///< 1 or 2 replaces scene.fem.element_degree
  bool write_vtu = true;
  // Beyond the command line (tests, studies):
  meshing::SlabMeshOptions mesh;      ///< coarse hex mesh resolution
  std::string formulation = "three_field";  ///< "three_field" (locking-free) or "one_field"
  /// "auto" (sparse direct MUMPS up to direct_solver_max_dofs, else CG + AMG
  /// with the rigid-body modes; measured on the default scene: CG + AMG is
  /// faster from about 10k dofs on), "direct" or "iterative".
  std::string linear_solver = "auto";
  std::size_t direct_solver_max_dofs = 5000;
  double stop_depth_m = -1.0;         ///< > 0: stop at this depth (before the target)
  /// Puncture depths are located to within this (m) by bisection; <= 0: a
  /// quarter of the scene's load step.
  double puncture_depth_resolution_m = -1.0;
  /// Spring-back homotopy: stages from lambda = 1 to 0 (a failed stage is
  /// retried from the last converged one with half the lambda step).
  int spring_back_stages = 4;
  int max_vtu_frames = 40;            ///< at most about this many VTU frames (plus events)
  bool verbose = true;                ///< progress and Newton tables on rank 0's stdout
  bool write_files = true;            ///< false: no files at all (tests)
  /// Called after every converged load (sub)step with the tip depth (m) and
  /// the share of the trajectory done (0..1, by time; by depth in 3D). It may
  /// throw to stop the run: the run writes its outputs with "status":
  /// "failed" and rethrows (as std::runtime_error with the same message).
  /// The Python module checks Ctrl-C here. Axisymmetric geometry: called on
  /// rank 0, which solves alone; 3D: on every rank, and it must throw on all
  /// of them or on none.
  std::function<void(double depth_m, double fraction_done)> on_step;
};

struct PunctureEvent {
  int layer = -1;
  std::string layer_name;
  double depth_m = 0.0;     ///< tip depth when the criterion was met
  double force_N = 0.0;     ///< needle force just before breakthrough
  double force_after_N = 0.0;  ///< needle force after the spring-back
  double max_stretch = 1.0; ///< max principal stretch at the tip before breakthrough
  double time_s = 0.0;
};

struct FemRunSummary {
  std::vector<PunctureEvent> punctures;
  double peak_force_N = 0.0;
  double peak_force_depth_m = 0.0;
  int load_steps = 0;         ///< converged (sub)steps solved
  int step_cuts = 0;          ///< halvings of the load step after a failed solve
  /// Axisymmetric: steps accepted at a Newton stall below the acceptance
  /// tolerance (AxisymmetricSettings::stall_acceptance_tolerance) rather than
  /// at the Newton tolerance.
  int steps_accepted_at_stall = 0;
  /// Steps accepted only by the last resort (a stall below 0.5 % of the peak
  /// force at 1/256 of the load step; axisymmetric reference).
  int steps_accepted_last_resort = 0;
  double largest_accepted_residual_N = 0.0;  ///< largest |R_free| of a step accepted at a stall (N)
  /// Steps plain Newton could not solve and pseudo-transient continuation did
  /// (axisymmetric reference).
  int steps_continued = 0;
  int bisections = 0;         ///< steps undone to locate a puncture depth
  int spring_back_stages = 0; ///< solves of the spring-back homotopies
  int newton_iterations = 0;  ///< total
  int linear_iterations = 0;  ///< total
  double wall_time_s = 0.0;
  double solve_time_s = 0.0;  ///< time inside Newton solves
  std::size_t n_dofs = 0;
  std::size_t n_cells = 0;
  int n_ranks = 1;
  int assembly_threads = 1;  ///< axisymmetric: threads of rank 0's cell loop
  int degree = 1;
  int refinement = 0;
  std::vector<double> time_s, depth_m, force_N;  ///< the rows of the force-depth CSV
  /// Parts of force_N per row (axisymmetric geometry; 0 in 3D): friction on
  /// the shaft and flank, cutting (cohesive energy dissipated per unit tip
  /// advance, at most force_N - friction: see crack_energy_released_J), tip
  /// (the rest: pressing and spreading the tissue).
  std::vector<double> tip_force_N, cutting_force_N, friction_force_N;
  std::vector<std::string> phase;  ///< per row: approach|insertion|dwell|withdrawal
  /// Per row, each layer's state: untouched|pressed|punctured (axisymmetric geometry).
  std::vector<std::vector<std::string>> layer_states;
  std::string geometry = "3d";
  double cohesive_dissipation_J = 0.0;  ///< energy dissipated by the crack (J)
  /// The part of the crack's dissipation in insertion steps that exceeded the
  /// needle's work beyond friction in the step (J): energy stored in the
  /// tissue and released by a crack run (the cut jumping ahead at a
  /// puncture), not counted in the cutting part.
  double crack_energy_released_J = 0.0;
  /// Energy dissipated by the numerical (Kelvin-Voigt) stabilisation (J); to
  /// be compared with the needle's work, of which it should be a small share.
  double stabilization_dissipation_J = 0.0;
  double needle_work_J = 0.0;  ///< work of the needle force over the insertion phase (J)
  double tip_element_size_m = 0.0;
  std::vector<int> elements_through_layer;
  std::vector<std::string> warnings;   ///< e.g. a mesh too coarse for the accuracy target
  std::vector<std::string> files_written;
};

/// Builds the distributed triangulation of the scene's slab: hex mesh from
/// meshing::build_layered_cylinder_mesh, material id = layer index, boundary
/// ids 0 = top (z = 0), 1 = base, 2 = lateral; `refinement` global
/// refinements (lateral faces follow the cylinder).
void build_slab_triangulation(const Scene& scene, const meshing::SlabMeshOptions& options,
                              int refinement, dealii::parallel::distributed::Triangulation<3>& tria);

/// The axisymmetric reference (scene.fem.geometry == "axisymmetric"; see
/// reference_fem/README.md): the same outputs, the whole trajectory
/// (insertion, dwell, withdrawal), fracture-energy puncture by a cohesive
/// crack that advances with the tip, shaft friction. Runs on rank 0 (a 2D
/// problem); the other ranks wait and receive the summary.
FemRunSummary run_axisymmetric_insertion(const Scene& scene, const FemRunOptions& options, MPI_Comm comm);

/// The reference a scene runs with: scene.fem.geometry, or for "auto" "3d"
/// with a blunt tip and "axisymmetric" with a cutting one.
std::string resolved_geometry(const Scene& scene);

/// Runs the insertion (see the file comment) on resolved_geometry(scene).
/// Throws std::runtime_error with a clear message if the solver cannot
/// continue (after writing the rows computed so far, with "status": "failed"
/// in the summary), and std::invalid_argument for scenes it cannot model
/// (e.g. an inclined needle in the axisymmetric reference).
FemRunSummary run_needle_insertion(const Scene& scene, const FemRunOptions& options, MPI_Comm comm);

}  // namespace puncture::fem
