// axisymmetric_insertion_run.hpp (internal to puncture_fem): the axisymmetric insertion
// run (AxisymmetricInsertionRun; axisymmetric_insertion.cc: the algorithm,
// axisymmetric_insertion_output.cc: what it records and writes) and what it keeps.
#pragma once

#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <sched.h>
#include <unistd.h>
#include <puncture/fem/axisymmetric_solver.hpp>
#include <puncture/fem/field_output.hpp>
#include <puncture/fem/needle_insertion.hpp>
#include <puncture/io/pvd.hpp>
#include <puncture/meshing/axisymmetric_slab_mesh.hpp>
#include "insertion_common.hpp"

namespace puncture::fem::axisymmetric_insertion {

using insertion::format_double;
using insertion::LayerState;

/// One point of the needle's trajectory: time, tip depth (m below the skin
/// surface; negative above it) and phase.
struct TrajectoryPoint {
  double time_s;
  double depth_m;
  const char* phase;
};

/// Per-layer materials (the long-term laws of viscoelastic layers), Prony
/// series (empty: elastic), crack laws and friction from the scene.
struct LayerLaws {
  std::vector<LayerMaterial> materials;
  std::vector<std::vector<PronyTerm>> prony;
  std::vector<LayerCrack> cracks;
  std::vector<FrictionCoefficients> friction;
};

/// One row of fem_force_depth.csv.
struct Row {
  double time_s, depth_m, velocity_m_per_s, force_N, tip_N, cutting_N, friction_N, tip_stretch;
  std::string phase;
  std::vector<LayerState> states;
};

/// A converged step of the needle: where it started in time, how far the tip
/// went (m, > 0 inward) and the cutting force over it (N).
struct StepAdvance {
  double t0_s;
  double advance_m;
  double cutting_N;
  int newton_iterations;
};

/// The axisymmetric insertion on rank 0: the mesh and the solver, the state of
/// the layers along the way, what is recorded, and the steps of the algorithm.
class AxisymmetricInsertionRun {
 public:
  /// Checks the scene, builds the mesh and the solver, fills the model part of
  /// `summary` and creates the output directory.
  AxisymmetricInsertionRun(const Scene& scene, const FemRunOptions& options, MPI_Comm comm, FemRunSummary& summary);
  /// Walks the needle along the whole trajectory, step by step.
  void walk_trajectory();
  /// Writes the CSV files, the Newton log, the PVD collection and the summary
  /// ("status": "ok", or "failed" with `failure` as its "error" and the rows
  /// recorded before it).
  void write_outputs(const std::string& failure = "");

 private:
  std::optional<StepAdvance> advance_needle(std::size_t k);
  void cut_step(const AxisymmetricNewtonReport& report, const std::string& phase, double d0, double d1);
  void detect_punctures();
  bool tip_reached_top(std::size_t i) const;
  bool layer_breaks(std::size_t i, double force_N, bool first_intact) const;
  void open_crack(std::size_t i);
  void record_puncture(std::size_t i, double force_after_N);
  void record_step(const std::string& phase, const StepAdvance& step);
  void check_intact_friction() const;
  void check_force_drops() const;
  void record(const std::string& phase, double velocity, double cutting_N);
  double cutting_force_N(double advance_m, double crack_J);
  void add_energy_totals();
  void describe_model(MPI_Comm comm);
  void place_needle(double depth);
  int pressed_layer() const;
  bool crack_through_top(std::size_t i) const;
  insertion::SurfaceProfile layer_top_profile(std::size_t layer) const;
  void write_frame(double time);
  std::string force_depth_csv() const;
  void write_pvd() const;
  nlohmann::json summary_json(const std::string& failure) const;
  void log(const std::string& s) const {
    if (options_.verbose) std::cout << s << std::endl;
  }

  // What the scene asks for.
  const Scene& scene_;
  const FemRunOptions& options_;
  FemRunSummary& summary_;
  const dealii::Timer wall_timer_;  ///< runs from the run's construction
  const int degree_;
  const int refinement_;
  const bool cutting_;  // a bevel or hollow tip (else a flat punch)
  const std::size_t n_layers_;
  const double a_;  // needle radius (m)
  // Mesh and solver.
  const meshing::AxisymmetricSlabMesh mesh_;
  const LayerLaws laws_;
  AxisymmetricSolver solver_;
  // Outputs being collected.
  const std::filesystem::path out_dir_;
  const std::vector<TrajectoryPoint> plan_;
  const int frame_every_;
  std::vector<Row> rows_;
  insertion::InsertionRecords records_;
  std::vector<std::pair<double, std::string>> frames_;  // (time, file name)
  // State of the layers.
  std::vector<LayerState> states_;
  std::vector<double> peak_force_, peak_depth_, peak_time_;
  std::vector<insertion::SurfaceProfile> peak_profile_;
  // State of the walk.
  double depth_, time_ = 0.0;
  double fraction_ = 1.0;  // of the planned step, grows back after cuts
  bool last_resort_ = false;  // the step is retried at 1/256 with the larger stall floor
  int step_index_ = 0;
  double last_advance_ = 0.0;  // depth change of the last converged step (for the predictor)
};

}  // namespace puncture::fem::axisymmetric_insertion
