// comparison_runs.hpp (internal to the comparison report): the steps of
// write_model_comparison before the tables are written.
//
// read_comparison_reference(scene, fem_dir): the FEM's result files, the
//   reference of the metrics (curve, the skin's u_z(r) profiles; whether the
//   curve has cutting/friction columns, then totals are compared) and the
//   depths (m, > 0) and radii (m) at which every model records the skin.
// build_comparison_mesh: the tetrahedral mesh of the slab (scene.comparison.mesh.kind) when a
//   volumetric model or an identification needs it (else an empty mesh);
//   mesh.vtu with write_vtk.
// ComparisonRunner: identifies a model's stiffness factors and critical forces (identify_model),
//   builds and runs each model along the scripted insertion
//   (one haptic step at a time), writes curves/<key>.csv and, with frames,
//   frames/<key>/... and their .pvd entries (each model shifted along x by
//   1.25 sample diameters per model); identify() runs one mass-spring
//   identification and then the identified model as row msm_<sa|isres>,
//   returning the identification's record for the summary (factors,
//   objectives, puncture depths in mm, evaluations, wall time s).
// comparison_rows: the rows of comparison.csv (metrics against the
//   reference, the FEM's own row last when asked for).
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "comparison_frames.hpp"
#include "puncture/meshing/tet_mesh.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/io/pvd.hpp"
#include "puncture/meshing/comparison_tet_slab_mesh.hpp"
#include "puncture/validation/comparison_report.hpp"
#include "puncture/validation/fem_comparison.hpp"
#include "puncture/validation/model_comparison.hpp"

namespace puncture::validation::comparison_report_detail {

struct ComparisonReference {
  FemResultFiles fem;
  ReferenceData data;
  std::vector<double> profile_depths_m;  ///< depths of the FEM's skin profiles (> 0), m
  std::vector<double> profile_radii_m;   ///< radii of its first profile, m
};
ComparisonReference read_comparison_reference(const Scene& scene, const std::filesystem::path& fem_dir);

struct ComparisonMesh {
  std::shared_ptr<const meshing::TetMesh> mesh;  ///< null: no model needs one
  meshing::ComparisonTetMeshReport report;
};
ComparisonMesh build_comparison_mesh(const Scene& scene, const ComparisonReportOptions& options,
                                     io::OutputSession& session, std::ostream& out);

class ComparisonRunner {
 public:
  ComparisonRunner(const Scene& scene, const ComparisonReportOptions& options, const ComparisonReference& reference,
                   std::shared_ptr<const meshing::TetMesh> mesh, io::OutputSession& session, std::ostream& out,
                   std::ostream& err);
  /// Builds the model `factory_name` on model_scene and runs it as row `key`.
  void run(const std::string& key, const Scene& model_scene, const std::string& factory_name);
  /// run() in two steps, so that runs can go side by side: add_slot books
  /// row `key` (its place among the rows and the .pvd parts, its scene in
  /// model_scenes()) and returns its index; run_in_slot (from any thread)
  /// fills it.
  std::size_t add_slot(const std::string& key, const Scene& model_scene, const std::string& factory_name);
  void run_in_slot(std::size_t slot, const std::string& key, const Scene& model_scene,
                   const std::string& factory_name);
  /// One identification (method: simulated_annealing or isres) and the run of its result.
  nlohmann::json identify(const std::string& method);
  /// The scene of model `key` with its layers' stiffness factors and
  /// critical forces identified against the reference
  /// (model_identification.hpp), also written to identified/<key>.json; the
  /// record goes to identification_records().
  Scene identify_model(const std::string& key);
  /// identify_model of each of `keys`, two models at a time (each
  /// identification's optimiser runs its own model runs two at a time too:
  /// side by side they keep both cores busy while one optimiser waits for
  /// its slower run). Returns key -> identified scene; wall_time_s gets the
  /// phase's wall time. The identified values do not depend on the order.
  std::map<std::string, Scene> identify_models(const std::vector<std::string>& keys, double& wall_time_s);
  const nlohmann::json& identification_records() const { return identification_records_; }
  /// The scene each run model was built on (key -> scene).
  const std::map<std::string, Scene>& model_scenes() const { return model_scenes_; }

  std::vector<std::unique_ptr<ModelRun>>& runs() { return runs_; }
  const std::vector<io::PvdEntry>& pvd() const { return pvd_; }

 private:
  ModelRunOptions run_options(const std::string& key, std::size_t slot, int& last_tenth);

  struct Slot {
    int first_part = 0;  ///< .pvd part index of the row's first dataset
  };

  const Scene& scene_;
  const ComparisonReportOptions& options_;
  const ComparisonReference& reference_;
  std::shared_ptr<const meshing::TetMesh> mesh_;
  io::OutputSession& session_;
  std::ostream& out_;
  std::ostream& err_;
  DiscFrames discs_;
  double frame_interval_s_ = 0.0;
  int next_part_ = 0;  ///< .pvd part index of the next model's first dataset
  std::vector<io::PvdEntry> pvd_;
  std::vector<Slot> slots_;
  std::vector<std::unique_ptr<ModelRun>> runs_;  ///< one per slot (null until its run is done)
  nlohmann::json identification_records_ = nlohmann::json::object();
  std::map<std::string, Scene> model_scenes_;
  std::mutex mutex_;  ///< out_, session_ and the records while identifications run side by side
};

/// Haptic steps of the scene's whole scripted trajectory (the denominator of
/// ModelMetrics::completed_fraction).
std::size_t trajectory_steps(const Scene& scene);

/// The rows of comparison.csv, ranking.csv and the tables of comparison.md.
struct ComparisonRows {
  std::vector<ModelMetrics> metrics;
  std::vector<const ModelRun*> runs;  ///< null for the FEM's row
  std::vector<std::string> descriptions;
};
ComparisonRows comparison_rows(const Scene& scene, const std::vector<std::unique_ptr<ModelRun>>& runs,
                               const ComparisonReference& reference, bool with_fem_row);

}  // namespace puncture::validation::comparison_report_detail
