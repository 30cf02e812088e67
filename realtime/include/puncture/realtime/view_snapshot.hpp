// view_snapshot.hpp: what the haptic thread hands to the renderer.
//
// TickSample: a few numbers per haptic tick (for the live force-depth graph),
// sent through an SpscRing. ViewSnapshot: the whole visible state (needle,
// forces, per-layer state, force-mesh nodes at rest and now), sent through a
// TripleBuffer at the snapshot rate. init_snapshot() sizes a snapshot from a
// simulator (allocates; call before the loop); fill_snapshot() copies into it
// without allocating (a layer whose node count differs from the sized one is
// marked !nodes_valid rather than resized).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "puncture/needle.hpp"
#include "puncture/simulator.hpp"

namespace puncture::realtime {

struct TickSample {
  double time_s = 0.0;
  double depth_m = 0.0;
  double tissue_force_N = 0.0;   ///< model force along the needle (> 0 resisting)
  double sent_axial_N = 0.0;     ///< guarded force along the needle (> 0 resisting)
  double lateral_force_N = 0.0;  ///< model force across the needle (TickResult::lateral_force_N)
  std::uint32_t layer_states = 0;
  std::uint32_t flags = 0;       ///< ForceOutputFlags
  std::uint64_t model_generation = 0;
};

struct LayerSnapshot {
  LayerState state = LayerState::Untouched;
  double surface_force_N = 0.0;   ///< on the tip (the needle layer)
  double support_force_N = 0.0;   ///< carried from the layer above (layer interaction)
  double cutting_force_N = 0.0;
  double friction_force_N = 0.0;  ///< Karnopp shaft friction
  double damping_force_N = 0.0;
  int deformed_rings = 0;
  bool has_contact = false;
  Eigen::Vector3d contact_m = Eigen::Vector3d::Zero();
  bool nodes_valid = false;
  Eigen::Matrix3Xd rest_m;       ///< force-mesh node rest positions (3 x N)
  Eigen::Matrix3Xd current_m;    ///< current positions (mesh, or resumption after a puncture)
  Eigen::Vector3d contact_normal = Eigen::Vector3d::UnitZ();  ///< outward normal of the mesh's contact node
};

struct ViewSnapshot {
  std::int64_t tick = -1;
  std::uint64_t model_generation = 0;  ///< +1 at every fresh tissue
  double wall_time_s = 0.0;
  NeedleState needle;
  double tissue_force_N = 0.0;
  double tip_force_N = 0.0;       ///< TickResult: tip + cutting + friction = tissue force
  double cutting_force_N = 0.0;
  double friction_force_N = 0.0;  ///< shaft friction and damping
  double lateral_force_N = 0.0;   ///< TickResult: across the needle (inclined insertion)
  Eigen::Vector3d force_sent_N = Eigen::Vector3d::Zero();
  std::uint32_t flags = 0;
  std::vector<LayerSnapshot> layers;
};

void init_snapshot(ViewSnapshot& snapshot, const PunctureSimulator& simulator);
void fill_snapshot(ViewSnapshot& snapshot, const PunctureSimulator& simulator, const TickResult& result) noexcept;

}  // namespace puncture::realtime
