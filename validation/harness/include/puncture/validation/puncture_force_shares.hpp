// puncture_force_shares.hpp: what the real-time model's force at each
// puncture is made of, term by term (the real-time physics acceptance asks
// that Eq. 5 carry the majority of each layer's pre-puncture force).
//
// In:  the run's PunctureEvents (puncture_force.hpp; N).
// Out: per event the needle force just before the break (total) split into
//      eq5         Eq. 5 on the force mesh's own deflections
//      mesh_dynamics  the mesh's contact reaction minus Eq. 5 (its nodes'
//                  inertia and damping; 0 at equilibrium)
//      tip_stiffening g(z0) of the tip spring
//      cutting     the open crack of the layer above (its cutting force while
//                  the layer under the tip is pressed: met at the break)
//      other       total - (the four above): the shaft (friction and d h v
//                  of the layers above) and the prediction's linearisation
//      with each share = term / total; as a markdown table and as JSON.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "puncture/puncture_force.hpp"

namespace puncture::validation {

struct PunctureForceShares {
  std::string layer;
  double depth_m = 0.0;
  double total_N = 0.0, eq5_N = 0.0, mesh_dynamics_N = 0.0, tip_stiffening_N = 0.0, cutting_N = 0.0, other_N = 0.0;
  double eq5_share() const { return total_N != 0.0 ? eq5_N / total_N : 0.0; }
};

std::vector<PunctureForceShares> puncture_force_shares(const std::vector<PunctureEvent>& events);
std::string puncture_force_shares_markdown(const std::vector<PunctureForceShares>& shares);
nlohmann::json puncture_force_shares_json(const std::vector<PunctureForceShares>& shares);

}  // namespace puncture::validation
