#include "puncture/validation/puncture_force_shares.hpp"

#include <iomanip>
#include <sstream>

namespace puncture::validation {

std::vector<PunctureForceShares> puncture_force_shares(const std::vector<PunctureEvent>& events) {
  std::vector<PunctureForceShares> out;
  for (const PunctureEvent& e : events) {
    PunctureForceShares s;
    s.layer = std::string(e.layer_name);
    s.depth_m = e.depth_m;
    s.total_N = e.total_force_N;
    s.eq5_N = e.eq5_force_N;
    s.mesh_dynamics_N = e.mesh_reaction_N - e.eq5_force_N;
    s.tip_stiffening_N = e.tip_stiffening_force_N;
    s.cutting_N = e.cutting_force_N;
    s.other_N = s.total_N - s.eq5_N - s.mesh_dynamics_N - s.tip_stiffening_N - s.cutting_N;
    out.push_back(s);
  }
  return out;
}

std::string puncture_force_shares_markdown(const std::vector<PunctureForceShares>& shares) {
  std::ostringstream m;
  auto cell = [&](double v, double total) {
    std::ostringstream c;
    c << std::fixed << std::setprecision(3) << v << " N (" << std::setprecision(0) << (total != 0.0 ? 100.0 * v / total : 0.0)
      << " %)";
    return c.str();
  };
  m << "| layer | depth (mm) | force at the break | Eq. 5 | mesh dynamics | tip stiffening | cutting above | shaft and rest |\n"
       "|---|---|---|---|---|---|---|---|\n";
  for (const PunctureForceShares& s : shares)
    m << "| " << s.layer << " | " << std::fixed << std::setprecision(2) << s.depth_m * 1e3 << " | " << std::setprecision(3)
      << s.total_N << " N | " << cell(s.eq5_N, s.total_N) << " | " << cell(s.mesh_dynamics_N, s.total_N) << " | "
      << cell(s.tip_stiffening_N, s.total_N) << " | " << cell(s.cutting_N, s.total_N) << " | "
      << cell(s.other_N, s.total_N) << " |\n";
  return m.str();
}

nlohmann::json puncture_force_shares_json(const std::vector<PunctureForceShares>& shares) {
  nlohmann::json a = nlohmann::json::array();
  for (const PunctureForceShares& s : shares)
    a.push_back({{"layer", s.layer},
                 {"depth_mm", s.depth_m * 1e3},
                 {"total_N", s.total_N},
                 {"eq5_N", s.eq5_N},
                 {"mesh_dynamics_N", s.mesh_dynamics_N},
                 {"tip_stiffening_N", s.tip_stiffening_N},
                 {"cutting_above_N", s.cutting_N},
                 {"shaft_and_rest_N", s.other_N},
                 {"eq5_share", s.eq5_share()}});
  return a;
}

}  // namespace puncture::validation
