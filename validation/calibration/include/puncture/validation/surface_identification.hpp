// surface_identification.hpp: a layer's force mesh identified from the FEM's
// pressing of that layer, by the needle force and the deflection profile of
// the layer's top surface together, so that the force comes from the mesh's
// own deflections (Eq. 5) and the mesh deforms as the FEM's surface does.
//
// surface_pressing_reference(fem, scene, k): the pressing of layer k in the
//   FEM result. Samples: the FEM's surface profiles of layer k taken before
//   its breakthrough while the surface still follows the tip (deflection at
//   the smallest profile radius >= kFollowFraction of the contact
//   deflection: the crack has not run ahead of the tip). Per sample: the
//   contact deflection z0 = tip depth - the layer's rest top depth (m), the
//   FEM's tip force there (tip_force column; the total force if the curve has
//   no parts; N) and the profile (deflection = -u_z at radius r, m).
// identify_force_mesh(start, thickness, density, reference, options): the
//   model is layer k's ForceMesh on a plane, quasi-static, advanced through
//   the samples' z0 in order; its reaction and ring deflections dZ_j, ring j
//   at r = (j - 1) L (deflection_profile_error's convention). Residuals:
//     force:      (F_model - F_fem) / F_max x sqrt(w_force / n)
//     deflection: (dZ_j - D_fem(r_j)) / D_max x sqrt(w_deflection / m), every
//                 sample and ring j >= 2 inside the profile's radii
//   (F_max, D_max: the largest FEM force and deflection of the samples; n, m
//   their counts). Levenberg-Marquardt in x = ln p within [p0 / f, f p0] over
//   K, k_s, k_a (surface_axial_stiffness) and z_v (virtual_stiffening); L
//   stays; w stays or is chosen among w0 +- rings_search_radius (options). A start of 0 for k_a or z_v (linear springs) starts at k_s and at
//   the layer thickness.
// Out: parameters before and after, force and deflection RMSE relative to
//   F_max and D_max before and after, per-sample model and FEM values for the
//   report, the Jacobian statistics at the optimum (standard errors of ln p,
//   correlations) and the optimiser's status.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "puncture/scene.hpp"
#include "puncture/validation/fem_comparison.hpp"
#include "puncture/validation/identifiability.hpp"

namespace puncture::validation {

constexpr double kFollowFraction = 0.8;
/// Fewest profiles a force mesh is identified from. Each profile gives the
/// force and the deflections of every ring inside its radii, so two give
/// 2 (1 + w) residuals for the four parameters; whether the stiffening (k_a,
/// z_v) is told apart over their depths is for the fit's standard errors to
/// say (the report flags each parameter). A layer broken soon after the tip
/// meets it (the default slab's muscle: two profiles) is still identified.
constexpr std::size_t kMinPressingProfiles = 2;

struct SurfacePressingReference {
  std::string layer;
  std::vector<double> contact_deflection_m;
  std::vector<double> force_N;
  std::vector<RadialProfile> profiles;  ///< deflection = -uz_m at r_m
  std::size_t size() const { return contact_deflection_m.size(); }
};

/// Empty (size 0) when the FEM has no usable profile of the layer.
SurfacePressingReference surface_pressing_reference(const FemResultFiles& fem, const Scene& scene, std::size_t layer);

struct SurfaceIdentificationOptions {
  double force_weight = 1.0;
  double deflection_weight = 1.0;
  double bound_factor = 1000.0;
  int threads = 0;  ///< Jacobian columns at once; 0: every core
  /// w is chosen among w0 - r .. w0 + r (>= 2, (w - 1) L < max_extent_m) by
  /// the fitted objective, every candidate compared over the rings of the
  /// largest (rings beyond a smaller mesh count as undeflected): the extent
  /// of the FEM's deformed surface identifies w when the objectives differ by
  /// more than 2 %; otherwise w stays (not identifiable). 0: w stays.
  int rings_search_radius = 0;
  double max_extent_m = std::numeric_limits<double>::infinity();
};

struct SurfaceFitQuality {
  double force_rmse_relative = 0.0;       ///< / F_max
  double deflection_rmse_relative = 0.0;  ///< / D_max
};

struct SurfaceIdentificationResult {
  std::string layer;
  ForceMeshParams before, after;
  SurfaceFitQuality quality_before, quality_after;
  std::vector<std::string> parameter_names;  ///< "K", "k_s", "k_a", "z_v"
  std::vector<double> standard_error_ln;     ///< of ln p (relative standard error), +inf: not determined
  std::vector<bool> at_bound;
  JacobianStatistics statistics;
  std::string status;
  double cost = 0.0;                                ///< the fitted objective (sum of squared residuals)
  std::vector<std::pair<int, double>> rings_costs;  ///< (w, fitted objective) of every candidate w
  /// True when the candidates' objectives differ by more than 2 % (w chosen
  /// by them); false: they do not tell w apart and w stays at the start's.
  bool rings_identified = false;
  // Per sample, for the report: z0, FEM and model force, FEM and model deflection at the rings.
  std::vector<double> contact_deflection_m, fem_force_N, model_force_N;
  std::vector<std::vector<double>> ring_radius_m, fem_deflection_m, model_deflection_m;
};

SurfaceIdentificationResult identify_force_mesh(const ForceMeshParams& start, double thickness_m, double density_kg_per_m3,
                                                const SurfacePressingReference& reference,
                                                const SurfaceIdentificationOptions& options = {});

/// What the fit determined of one force-mesh value of `result`, for the
/// preset's provenance: the value's JSON pointer relative to the layer, its
/// status ("identified"; "at a bound"; "not identifiable": relative standard
/// error not determined or above 100 %, or w when the candidates' objectives
/// differ by < 2 %) and why. Index 0-3: K, k_s, k_a, z_v (parameter_names);
/// 4: w (only when w was searched: rings_costs.size() > 1).
struct SurfaceParameterStatus {
  std::string pointer, status, reason;
  double relative_standard_error = std::numeric_limits<double>::quiet_NaN();  ///< of ln p; NaN for w
};
std::vector<SurfaceParameterStatus> surface_parameter_statuses(const SurfaceIdentificationResult& result);

/// Markdown table: one row per identified layer (parameters before -> after
/// with relative standard errors, force and deflection RMSE before -> after).
std::string surface_identification_markdown(const std::vector<SurfaceIdentificationResult>& results);
/// CSV for plots: layer,depth_index,contact_deflection_mm,r_mm,fem_deflection_mm,model_deflection_mm.
std::string surface_identification_csv(const std::vector<SurfaceIdentificationResult>& results);

}  // namespace puncture::validation
