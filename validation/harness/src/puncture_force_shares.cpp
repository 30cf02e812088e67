#include "puncture/validation/puncture_force_shares.hpp"

#include <iomanip>
#include <sstream>

namespace puncture::validation {

std::optional<ReferenceForceParts> reference_parts_before_puncture(const InsertionCurve& curve,
                                                                    const std::string& layer) {
  const int k = curve.layer_index(layer);
  if (k < 0 || !curve.has_parts()) return std::nullopt;
  const std::vector<LayerState>& state = curve.layer_states[static_cast<std::size_t>(k)];
  std::optional<std::size_t> last_pressed;
  for (const std::size_t i : insertion_phase(curve)) {
    if (state[i] == LayerState::Punctured) {
      if (!last_pressed) return std::nullopt;
      const std::size_t j = *last_pressed;
      return ReferenceForceParts{curve.depth_m[j], curve.force_N[j], curve.tip_force_N[j], curve.cutting_force_N[j],
                                 curve.friction_force_N[j]};
    }
    if (state[i] == LayerState::Pressed) last_pressed = i;
  }
  return std::nullopt;
}

std::vector<PunctureForceShares> puncture_force_shares(const std::vector<PunctureEvent>& events,
                                                       const InsertionCurve* reference) {
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
    if (reference) s.reference = reference_parts_before_puncture(*reference, s.layer);
    out.push_back(s);
  }
  return out;
}

namespace {

std::string percent(double part, double whole) {
  std::ostringstream c;
  c << std::fixed << std::setprecision(0) << (whole != 0.0 ? 100.0 * part / whole : 0.0) << " %";
  return c.str();
}

std::string newtons_and_share(double v, double total) {
  std::ostringstream c;
  c << std::fixed << std::setprecision(3) << v << " N (" << percent(v, total) << ")";
  return c.str();
}

}  // namespace

std::string puncture_force_shares_markdown(const std::vector<PunctureForceShares>& shares) {
  std::ostringstream m;
  m << "| layer | depth (mm) | force at the break | Eq. 5 | mesh dynamics | tip stiffening | cutting above | shaft and rest "
       "| Eq. 5 of the layer's own pressing force |\n"
       "|---|---|---|---|---|---|---|---|---|\n";
  for (const PunctureForceShares& s : shares)
    m << "| " << s.layer << " | " << std::fixed << std::setprecision(2) << s.depth_m * 1e3 << " | " << std::setprecision(3)
      << s.total_N << " N | " << newtons_and_share(s.eq5_N, s.total_N) << " | "
      << newtons_and_share(s.mesh_dynamics_N, s.total_N) << " | " << newtons_and_share(s.tip_stiffening_N, s.total_N)
      << " | " << newtons_and_share(s.cutting_N, s.total_N) << " | " << newtons_and_share(s.other_N, s.total_N) << " | "
      << percent(s.eq5_N, s.surface_N()) << " of " << std::setprecision(3) << s.surface_N() << " N |\n";

  bool any_reference = false;
  for (const PunctureForceShares& s : shares) any_reference = any_reference || s.reference.has_value();
  if (!any_reference) return m.str();
  m << "\nThe FEM's force at its last load step with the layer pressed before its break, by the FEM's own parts "
       "(tip: the force on the needle's tip; cutting: the cohesive energy per advance of every crack, the cracks "
       "above and the layer's own crack opening ahead of the tip before it has run through the layer; friction: the "
       "shaft), beside the real-time model's own pressing force of the layer (Eq. 5 + mesh dynamics + tip "
       "stiffening), as a share of each model's force.\n\n"
       "| layer | FEM depth (mm) | FEM force | tip | cutting (every crack) | shaft friction | "
       "real-time: the layer's own pressing |\n"
       "|---|---|---|---|---|---|---|\n";
  for (const PunctureForceShares& s : shares) {
    if (!s.reference) continue;
    const ReferenceForceParts& r = *s.reference;
    m << "| " << s.layer << " | " << std::fixed << std::setprecision(2) << r.depth_m * 1e3 << " | "
      << std::setprecision(3) << r.total_N << " N | " << newtons_and_share(r.tip_N, r.total_N) << " | "
      << newtons_and_share(r.cutting_N, r.total_N) << " | " << newtons_and_share(r.friction_N, r.total_N) << " | "
      << newtons_and_share(s.surface_N(), s.total_N) << " |\n";
  }
  return m.str();
}

nlohmann::json puncture_force_shares_json(const std::vector<PunctureForceShares>& shares) {
  nlohmann::json a = nlohmann::json::array();
  for (const PunctureForceShares& s : shares) {
    nlohmann::json j = {{"layer", s.layer},
                        {"depth_mm", s.depth_m * 1e3},
                        {"total_N", s.total_N},
                        {"eq5_N", s.eq5_N},
                        {"mesh_dynamics_N", s.mesh_dynamics_N},
                        {"tip_stiffening_N", s.tip_stiffening_N},
                        {"cutting_above_N", s.cutting_N},
                        {"shaft_and_rest_N", s.other_N},
                        {"surface_N", s.surface_N()},
                        {"eq5_share", s.eq5_share()},
                        {"eq5_share_of_surface", s.eq5_share_of_surface()},
                        {"reference", nullptr}};
    if (s.reference)
      j["reference"] = {{"depth_mm", s.reference->depth_m * 1e3},
                        {"total_N", s.reference->total_N},
                        {"tip_N", s.reference->tip_N},
                        {"cutting_above_N", s.reference->cutting_N},
                        {"friction_N", s.reference->friction_N}};
    a.push_back(j);
  }
  return a;
}

}  // namespace puncture::validation
