// puncture_force_shares.hpp: what the real-time model's force at each
// puncture is made of, term by term, beside what the FEM's force is made of
// just before the same break (the real-time physics acceptance asks that
// Eq. 5 carry the majority of each layer's pre-puncture force).
//
// In:  the run's PunctureEvents (puncture_force.hpp; N) and, optionally, the
//      FEM's insertion curve with its parts (tip, cutting, friction) and
//      layer states (metrics.hpp).
// Out: per event the needle force just before the break (total) split into
//      eq5         Eq. 5 on the force mesh's own deflections
//      mesh_dynamics  the mesh's contact reaction minus Eq. 5 (its nodes'
//                  inertia and damping; 0 at equilibrium)
//      tip_stiffening g(z0) of the tip spring
//      cutting     the open crack of the layer above (its cutting force while
//                  the layer under the tip is pressed: met at the break)
//      other       total - (the four above): the shaft (friction and d h v
//                  of the layers above) and the prediction's linearisation
//      with each share = term / total. The first three are the layer's own
//      pressing force (its surface force, surface_N); eq5_share_of_surface()
//      is Eq. 5's share of it. The rest are forces of the layers above.
//      reference: the FEM's force at its last insertion load step with the
//      layer pressed before its puncture, split as the FEM counts it (tip:
//      the force on the needle's tip; cutting: the cohesive energy per
//      advance of every crack, the cracks above and the layer's own crack
//      opening ahead of the tip before it has run through the layer;
//      friction: the shaft), so a reader sees how much of the needle force
//      the pressing of the tip carries at that break in the reference.
// As a markdown table and as JSON.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "puncture/puncture_force.hpp"
#include "puncture/validation/metrics.hpp"

namespace puncture::validation {

/// A reference curve's force and its parts at one insertion sample (N, m).
struct ReferenceForceParts {
  double depth_m = 0.0;
  double total_N = 0.0, tip_N = 0.0, cutting_N = 0.0, friction_N = 0.0;
};

/// The last insertion sample of `curve` with layer `layer` pressed before its
/// first punctured sample; nothing when the curve has no parts or no state
/// column of that layer, or the layer is never punctured or never pressed
/// before it.
std::optional<ReferenceForceParts> reference_parts_before_puncture(const InsertionCurve& curve,
                                                                    const std::string& layer);

struct PunctureForceShares {
  std::string layer;
  double depth_m = 0.0;
  double total_N = 0.0, eq5_N = 0.0, mesh_dynamics_N = 0.0, tip_stiffening_N = 0.0, cutting_N = 0.0, other_N = 0.0;
  std::optional<ReferenceForceParts> reference;  ///< the FEM before the same layer's break
  /// The layer's own pressing force (its surface force): Eq. 5 + mesh dynamics + tip stiffening.
  double surface_N() const { return eq5_N + mesh_dynamics_N + tip_stiffening_N; }
  double eq5_share() const { return total_N != 0.0 ? eq5_N / total_N : 0.0; }
  double eq5_share_of_surface() const { return surface_N() != 0.0 ? eq5_N / surface_N() : 0.0; }
};

/// One entry per event; `reference` (may be null) fills each entry's reference parts.
std::vector<PunctureForceShares> puncture_force_shares(const std::vector<PunctureEvent>& events,
                                                       const InsertionCurve* reference = nullptr);
std::string puncture_force_shares_markdown(const std::vector<PunctureForceShares>& shares);
nlohmann::json puncture_force_shares_json(const std::vector<PunctureForceShares>& shares);

}  // namespace puncture::validation
