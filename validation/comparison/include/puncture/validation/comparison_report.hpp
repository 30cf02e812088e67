// comparison_report.hpp: the report of `puncture compare` as one library call:
// every comparison model and the real-time model on the identical insertion
// (same scene: slab, needle, trajectory), measured against one FEM reference,
// graded by the seed paper's Sec. 3.3 method and written to a directory.
//
// write_model_comparison(scene, weights, fem, options, out, err):
//   In:  the scene (SI units: m, s, N), the Delphi weights of the grading,
//        the FEM reference's result directory as obtain_fem_reference left it
//        (fem_force_depth.csv, fem_surface_profile.csv, fem_summary.json) with
//        its cache key, and ComparisonReportOptions (model keys, mass-spring
//        identification methods, ParaView frames, output directory, the
//        command line recorded as provenance).
//   Out: in options.output_dir, staged and renamed only on success:
//        comparison.csv (one row per model: dofs, memory MB, force RMSE in N
//        and relative to the FEM peak, peak forces N, puncture depths mm,
//        skin deflection RMSE mm, step times ms, build and run wall time s),
//        ranking.csv, curves/<model>.csv (every haptic step: time s, depth mm,
//        velocity mm/s, forces N, step wall time us, layer states),
//        fem_curve.csv, deflection_profiles.csv (depth, r, deflection in mm,
//        > 0 into the tissue), comparison_summary.json (provenance, FEM
//        reference, mesh, integrators, identification, wall time s); with
//        write_vtk also mesh.vtu, frames/<model>/*.vtp|*.vtu and
//        comparison.pvd (coordinates in m, each model shifted along x); then
//        the plots of scripts/plot_comparison.py and comparison.md.
//        Returns the metrics and grading, one entry per compared model (the
//        FEM row last when "fem" is among the models).
//   Progress lines "[compare] ..." go to `out` unless options.quiet; a model
//   that fails is reported on `err` and kept in the tables.
//   Throws what the readers and writers throw (bad FEM result files, an
//   output that cannot be written); the files staged so far are then removed.
#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "puncture/scene.hpp"
#include "puncture/validation/comparison_grading.hpp"
#include "puncture/validation/model_comparison.hpp"
#include "puncture/validation/validation_cases.hpp"

namespace puncture::validation {

/// The FEM reference of the scene: where its result files are and its cache entry.
struct ComparisonFemReference {
  std::filesystem::path dir;  ///< directory with fem_force_depth.csv, fem_summary.json, ...
  std::string hash;           ///< cache key (shown in the report)
  bool from_cache = false;    ///< taken from the cache (else computed for this run)
  double wall_time_s = 0.0;   ///< spent obtaining it in this command (reading the cache or solving), s
};

/// A case on which every model, identified once on the scene's trajectory, is
/// judged without retuning: the case (validation_cases.hpp) and the FEM
/// reference of the scene with the case's overrides.
struct ComparisonCase {
  ValidationCase validation_case;
  ComparisonFemReference fem;
};

struct ComparisonReportOptions {
  /// Model keys in table order: comparison::comparison_model_names() and/or
  /// "fem" (the FEM's own row, last). Checked by the caller.
  std::vector<std::string> models;
  /// Mass-spring identification methods ("simulated_annealing", "isres"),
  /// each giving an extra row msm_sa / msm_isres.
  std::vector<std::string> identify;
  int identify_evaluations = 40;  ///< model runs per identification
  /// Every model but the real-time one (calibrated by `puncture calibrate`)
  /// gets its layers' stiffness factors (identify_stiffness) and critical
  /// contact forces identified against the FEM on the scene's trajectory
  /// (model_identification.hpp); false: the scene's values and rules.
  bool identify_models = true;
  bool identify_stiffness = true;
  /// Held-out cases (empty: none): every model is run on each and measured
  /// against the case's FEM; heldout.csv, ranking_heldout.csv, and the
  /// ranking of comparison.md reads the held-out metrics.
  std::vector<ComparisonCase> cases;
  std::string cases_file;  ///< recorded in the summary
  int frames = 20;                ///< ParaView frames per model over the trajectory (0: none)
  bool write_vtk = true;          ///< mesh.vtu, frames, comparison.pvd
  bool quiet = false;             ///< no progress lines on `out`
  /// Called every 5 % of each model run and after every run of an
  /// identification; may throw to stop the comparison (nothing is written).
  /// The Python module's Ctrl-C.
  std::function<void()> check_interrupt;
  std::filesystem::path output_dir;
  std::filesystem::path weights_path;  ///< recorded in comparison_summary.json
  std::string command_line;            ///< provenance of every file and comparison.md
  /// Start of the whole command (wall time in the summary and comparison.md).
  std::chrono::steady_clock::time_point wall_start = std::chrono::steady_clock::now();
};

struct ComparisonOutcome {
  std::vector<ModelMetrics> metrics;  ///< one per row of comparison.csv
  ComparisonGrade grade;              ///< scores and ranks in the same order
  /// With held-out cases: one row per model over them (aggregate) and their grade.
  std::vector<ModelMetrics> heldout_metrics;
  ComparisonGrade heldout_grade;
  bool has_shaft_forces = false;      ///< the total force was compared (else the contact force)
};

ComparisonOutcome write_model_comparison(const Scene& scene, const DelphiWeights& weights,
                                         const ComparisonFemReference& fem, const ComparisonReportOptions& options,
                                         std::ostream& out, std::ostream& err);

}  // namespace puncture::validation
