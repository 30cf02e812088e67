// slab_insertion_run.hpp (internal to puncture_fem): the 3D reference's insertion run
// (SlabInsertionRun, slab_insertion_run.cc: the algorithm; slab_insertion_output.cc: what it
// records and writes), with the node sets and rows it keeps.
#pragma once

#include <puncture/fem/needle_insertion.hpp>
#include <deal.II/distributed/tria.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
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
#include <puncture/meshing/inclined_path_mesh.hpp>
#include "insertion_common.hpp"

namespace puncture::fem::slab_insertion {

using namespace dealii;
using insertion::format_double;
using insertion::LayerState;
using Tria = parallel::distributed::Triangulation<3>;

/// The boundary ids build_slab_triangulation gives the slab's faces (needle_insertion.hpp).
constexpr types::boundary_id kTop = 0, kBase = 1, kLateral = 2;

/// A node (support point) with its three displacement dofs.
struct Node {
  Point<3> X;
  types::global_dof_index dof[3] = {0, 0, 0};
  double r() const { return std::hypot(X[0], X[1]); }
};

/// The needle's straight path through the entry point (the origin) at the
/// scene's angle a and azimuth b (meshing::inclined_path_of, the path the
/// mesh follows): its unit direction d into the tissue
/// (meshing::path_direction) and two unit vectors across it, e1 in the
/// plane of d and the sample axis, e2 horizontal. Along the sample axis
/// d = (0, 0, -1), e1 = (1, 0, 0), e2 = (0, 1, 0), so that every quantity
/// below is computed with the same floating-point operations as the axial
/// punch's (z, x, y).
struct NeedlePath {
  Tensor<1, 3> d, e1, e2;
  double axis_cosine = 1.0;  ///< cos a: a vertical depth is axis_cosine x the length along d
  explicit NeedlePath(const meshing::InclinedPath& path);
  /// Distance (m) of point p from the path line.
  double distance(const Point<3>& p) const { return std::hypot(p * e1, p * e2); }
};

struct Row {
  double time_s, depth_m, velocity_m_per_s, force_N;
  double tip_stretch;  ///< max principal stretch at the tip in the pressed layer (1: no contact)
  std::vector<LayerState> states;
  double lateral_force_N = 0.0;  ///< |force on the needle across its axis| (inclined needle)
};

/// The tissue's force on the needle: along the needle (> 0 resisting the
/// insertion) and across it.
struct NeedleForce {
  double axial_N = 0.0;
  double lateral_N = 0.0;
};

/// Element degree and global refinements of the 3D reference.
struct SlabDiscretisation {
  int degree;
  int refinement;
};

/// What a sub-step started from: restored when it is undone to bisect toward
/// a puncture (the contact set also when its solve fails).
struct SubStepStart {
  double depth_m;
  double last_advance_m;
  bool predictor_valid;
  std::map<std::size_t, Tensor<1, 3>> contact;
  std::vector<LayerState> states;
  FiniteStrainSolver::Snapshot snapshot;
};

/// The pressed layer's puncture criterion after a sub-step.
struct PunctureCheck {
  double force_N;
  double stretch;
  bool breaks;
};

/// The 3D insertion (flat punch moving along the needle's path, at an angle
/// on a mesh whose needle column follows the path; removal of a layer column
/// at puncture): the
/// slab and the solver, the contact set and the layer states, what is
/// recorded, and the steps of the algorithm. Every rank runs it.
class SlabInsertionRun {
 public:
  /// Checks the scene, creates the output directory, builds the slab, the
  /// solver, the boundary conditions and the node sets.
  SlabInsertionRun(const Scene& scene, const FemRunOptions& options, MPI_Comm comm);
  /// Runs the insertion and writes the outputs (also when it fails).
  FemRunSummary run();

 private:
  void advance_to(double step_target);
  double next_trial_depth(double step_target, double increment) const;
  SubStepStart sub_step_start() const;
  double cut_sub_step(const SubStepStart& start, double trial_depth, double advance, const NewtonReport& report);
  bool accept_sub_step(double trial_depth, double advance);
  PunctureCheck check_puncture();
  void undo_for_bisection(const SubStepStart& start);
  void puncture_current_layer(double force, double stretch);
  PunctureEvent record_before_puncture(std::size_t layer, double force, double stretch);
  void open_hole(std::size_t layer);
  void release_needle(std::size_t layer, double force);
  void spring_back(const std::string& layer_name);
  void record_after_puncture(std::size_t layer, PunctureEvent event);
  void record_load_step(int step);
  bool solve_at(double depth, NewtonReport& report, double predictor_scale);
  void find_node_sets();
  void describe_model();
  double u_of(const Node& n, unsigned c) const { return solver_.displacement(n.dof[c]); }
  bool any_contact() const;
  double along_path(const Node& n) const;
  void apply_targets(double path_tip);
  bool join_reached_nodes(double path_tip);
  NeedleForce needle_force_vector() const;
  double needle_force() const { return needle_force_vector().axial_N; }
  double tip_stretch(std::size_t layer) const;
  insertion::SurfaceProfile surface_profile(std::size_t layer) const;
  void record_row(double depth, double force, double stretch, double lateral_force);
  void write_frame(double depth);
  void write_outputs(const std::string& status, const std::string& error);
  std::string force_depth_csv() const;
  nlohmann::json summary_json(const std::string& status, const std::string& error) const;
  void log(const std::string& s) const {
    if (root_ && options_.verbose) std::cout << s << std::endl;
  }

  // What the scene asks for.
  const dealii::Timer wall_timer_;  ///< runs from the run's construction
  const Scene& scene_;
  const FemRunOptions& options_;
  const MPI_Comm comm_;
  const bool root_;
  const SlabDiscretisation disc_;
  const std::size_t n_layers_;
  const double needle_radius_;
  const NeedlePath path_;
  const double thickness_;
  const double tol_;  // position tolerance (m)
  const double speed_;
  const double start_height_;
  const double final_depth_;
  const std::filesystem::path out_dir_;
  // Slab and solver.
  const std::unique_ptr<Tria> tria_;
  const SolverSettings settings_;
  FiniteStrainSolver solver_;
  FemRunSummary summary_;
  // Boundary conditions and node sets.
  std::map<types::global_dof_index, double> fixed_;
  std::vector<Node> nodes_;
  std::vector<double> interface_z_;
  // Per layer: every node of its top interface (profiles) and those under the needle.
  std::vector<std::vector<std::size_t>> interface_nodes_, tip_nodes_;
  // Contact and layer state.
  std::map<std::size_t, Tensor<1, 3>> contact_;  // joined node -> its displacement across the needle, held
  std::vector<LayerState> states_;
  std::size_t current_layer_ = 0;  // first layer not punctured
  bool solution_is_stale_ = true;  // the state differs from the last solved one
  // Records.
  insertion::InsertionRecords records_;
  std::vector<Row> rows_;
  std::unique_ptr<FieldOutputSeries> fields_;
  // Load stepping.
  const double load_step_;
  // Puncture depths are located by bisection to within `resolution_`: a step
  // after which the criterion holds is undone and halved until it is short.
  const double resolution_;
  const int n_steps_;
  const int vtu_stride_;
  double depth_;
  int record_index_ = 0;
  double last_advance_ = 0.0;     // depth change of the last converged step in contact
  bool predictor_valid_ = false;  // that step pressed the current layer like the next one will
  double crossing_upper_ = std::numeric_limits<double>::infinity();  // criterion known to hold here
};

}  // namespace puncture::fem::slab_insertion
