#include "puncture/realtime/view_snapshot.hpp"

#include <algorithm>

namespace puncture::realtime {

void init_snapshot(ViewSnapshot& s, const PunctureSimulator& sim) {
  s.layers.assign(sim.layer_count(), LayerSnapshot{});
  for (std::size_t k = 0; k < sim.layer_count(); ++k) {
    s.layers[k].rest_m = sim.node_rest_positions(k);
    s.layers[k].current_m = sim.node_positions(k);
  }
}

void fill_snapshot(ViewSnapshot& s, const PunctureSimulator& sim, const TickResult& r) noexcept {
  s.tip_force_N = r.tip_force_N;
  s.lateral_force_N = r.lateral_force_N;
  s.cutting_force_N = r.cutting_force_N;
  s.friction_force_N = r.friction_force_N;
  const std::size_t n = std::min(s.layers.size(), r.layers.size());
  for (std::size_t k = 0; k < n; ++k) {
    LayerSnapshot& l = s.layers[k];
    l.state = r.layers[k].state;
    l.surface_force_N = r.layers[k].surface_force_N;
    l.support_force_N = r.layers[k].support_force_N;
    l.cutting_force_N = r.layers[k].cutting_force_N;
    l.friction_force_N = r.layers[k].friction_force_N;
    l.damping_force_N = r.layers[k].damping_force_N;
    l.deformed_rings = r.layers[k].deformed_rings;
    l.has_contact = sim.has_contact(k);
    if (l.has_contact) l.contact_m = sim.contact_point(k).position;
    const Eigen::Matrix3Xd& rest = sim.node_rest_positions(k);
    const Eigen::Matrix3Xd& now = sim.node_positions(k);
    l.nodes_valid = rest.cols() == l.rest_m.cols() && now.cols() == l.current_m.cols() && rest.cols() > 0;
    if (l.nodes_valid) {
      l.rest_m = rest;  // same size: a copy, no allocation
      l.current_m = now;
      if (const ForceMesh* mesh = sim.force_mesh(k)) l.contact_normal = mesh->normals().col(0);
    }
  }
}

}  // namespace puncture::realtime
