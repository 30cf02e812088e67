// mass_spring_identification.hpp: the volumetric mass-spring stiffnesses
// identified against the FEM reference by heuristic global search (seed
// paper 001: "simulated annealing and genetic algorithm were employed to
// extract the system parameters").
//
// Parameters: one factor per layer on the Van Gelder spring stiffnesses
// (ComparisonSettings::mass_spring_stiffness_scale), searched in log space in
// [start / bound_factor, start * bound_factor].
// Objective (dimensionless): (force RMSE / reference peak)^2 over the
// insertion + depth_weight * sum over layers of (puncture depth error /
// min(L, thickness))^2 (+ 1 for a layer broken by only one of the two).
// Model runs: the mass-spring model in quasi-static mode (equilibrium at every
// step, volumetric_model.hpp) along the insertion up to the reference's
// deepest sample, steps of `step_m` of needle travel: the FEM reference is
// quasi-static, and a dynamic run on the comparison mesh costs minutes. The
// identified factors are then checked with the full SUNDIALS run in the
// comparison table.
// Methods:
//   simulated_annealing  GSL gsl_siman (Metropolis, geometric cooling), steps
//                        of size `step` in log space;
//   isres                NLopt GN_ISRES (Runarsson & Yao's improved stochastic
//                        ranking evolution strategy), population `population`.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "puncture/meshing/tet_mesh.hpp"
#include "puncture/scene.hpp"
#include "puncture/validation/model_comparison.hpp"

namespace puncture::validation {

struct IdentificationOptions {
  std::string method = "simulated_annealing";  ///< or "isres"
  int max_evaluations = 40;
  double bound_factor = 30.0;
  double depth_weight = 0.1;
  double step_m = 0.25e-3;   ///< needle travel per quasi-static step
  int population = 10;       ///< ISRES
  unsigned seed = 1;
};

struct IdentificationEvaluation {
  std::vector<double> scale;
  double objective = 0.0;
  double force_rmse_relative = 0.0;
};

struct IdentificationResult {
  std::string method;
  std::vector<double> scale_before, scale_after;
  IdentificationEvaluation before, after;
  std::vector<LayerPunctureComparison> punctures_before, punctures_after;
  std::vector<IdentificationEvaluation> history;
  int evaluations = 0;
  double wall_time_s = 0.0;
  double seconds_per_evaluation = 0.0;
};

using IdentificationProgress = std::function<void(int evaluation, double objective, double best)>;

/// mesh: the comparison mesh of the scene. Throws std::invalid_argument for
/// an unknown method or bad options.
IdentificationResult identify_mass_spring_stiffness(const Scene& scene, std::shared_ptr<const meshing::TetMesh> mesh,
                                                    const ReferenceData& reference, const IdentificationOptions& options,
                                                    const IdentificationProgress& progress = {});

/// One quasi-static run of the mass-spring model with the given layer
/// factors, evaluated with the objective above (exposed for tests).
IdentificationEvaluation evaluate_mass_spring(const Scene& scene, std::shared_ptr<const meshing::TetMesh> mesh,
                                             const ReferenceData& reference, const std::vector<double>& scale,
                                             const IdentificationOptions& options,
                                             std::vector<LayerPunctureComparison>* punctures = nullptr);

}  // namespace puncture::validation
