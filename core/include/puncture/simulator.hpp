// simulator.hpp: the haptic tick of the real-time model (seed paper Sec. 2.2-2.3).
//
// PunctureSimulator owns, per layer (top to bottom): the layer's contact
// surface, its force mesh (Effects::surface_force), its surface resumption
// (Effects::resumption, needs the force mesh) and its damping coefficient
// (Effects::damping). An effect that is off is not constructed and costs one
// check per tick. Everything is allocated at construction: tick() does no
// heap allocation.
//
// One tick (needle state in, TickResult out; forces in N, positive when they
// resist insertion, see puncture_force.hpp):
//   1. punctured layers with resumption advance one step of Eq. (8);
//   2. the active layer (first not punctured; lower layers are unreachable)
//      gets its contact point the first time it is reached: where the
//      needle axis crosses its surface (ContactSurface::intersect_ray), or,
//      if the tip is already below that crossing (e.g. thin skin pressed
//      deeper than its own thickness before it broke), the tip's current
//      position. The contact point stays fixed afterwards;
//   3. contact deflection = depth of the tip past the contact point along
//      the contact normal (>= 0); the force mesh advances one haptic step
//      with it; the surface force is its contact reaction, clamped to >= 0
//      (a blunt tip can only push);
//   4. when the force mesh reaches ring w the layer breaks: its surface force
//      vanishes from this tick on, a PunctureEvent is recorded, resumption
//      starts from the broken node positions and the next layer becomes the
//      active one (step 2-3 run for it in the same tick). Without a force
//      mesh (surface_force off) a layer breaks as soon as the tip passes
//      its contact point;
//   5. every punctured layer adds the damping force d h v (Table 1), with h
//      the shaft length inside the layer's depth range [top, top + thickness]
//      taken from the scene's layer thicknesses.
// The force meshes are laid out at construction around the point where the
// scene's insertion axis (x = y = 0, direction -z) crosses each surface; the
// mesh step is the fixed haptic step 1 / RealtimeSettings::haptic_rate_Hz.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "puncture/contact_surface.hpp"
#include "puncture/force_mesh.hpp"
#include "puncture/needle.hpp"
#include "puncture/puncture_force.hpp"
#include "puncture/resumption.hpp"
#include "puncture/scene.hpp"

namespace puncture {

struct LayerTickResult {
  LayerState state = LayerState::Untouched;
  double surface_force_N = 0.0;       ///< force-mesh reaction (0 unless Pressed)
  double damping_force_N = 0.0;       ///< d h v (0 unless Punctured)
  int deformed_rings = 0;             ///< rings whose mean deflection exceeds the threshold
  double contact_deflection_m = 0.0;  ///< depth of the tip past the contact point
  double shaft_length_m = 0.0;        ///< h: needle length inside the layer
};

struct TickResult {
  double time_s = 0.0;
  double depth_m = 0.0;           ///< tip depth below the undeformed skin surface
  double velocity_m_per_s = 0.0;  ///< along the needle axis, > 0 inserting
  double total_force_N = 0.0;     ///< sum of all surface and damping forces
  std::vector<LayerTickResult> layers;  ///< one per layer, sized at construction
};

class PunctureSimulator {
 public:
  /// layer_surfaces: one per scene layer, top to bottom. Throws
  /// std::invalid_argument on a count mismatch, no layers, an unknown
  /// integrator, a surface the insertion axis misses, or bad parameters.
  PunctureSimulator(const Scene& scene, std::vector<std::unique_ptr<ContactSurface>> layer_surfaces);

  /// One haptic tick. No heap allocation. Throws std::invalid_argument for a
  /// non-finite needle state, std::runtime_error if a force turns non-finite.
  const TickResult& tick(const NeedleState& needle);
  const TickResult& last_result() const { return result_; }

  std::size_t layer_count() const { return layers_.size(); }
  const std::string& layer_name(std::size_t k) const { return layers_[k].name; }
  LayerState layer_state(std::size_t k) const { return layers_[k].state; }
  /// Index of the layer the needle can touch (== layer_count() once all are punctured).
  std::size_t active_layer() const { return active_; }
  const std::vector<PunctureEvent>& puncture_events() const { return events_; }

  bool has_contact(std::size_t k) const { return layers_[k].contact_set; }
  const SurfacePoint& contact_point(std::size_t k) const { return layers_[k].contact; }

  /// nullptr when Effects::surface_force is off.
  const ForceMesh* force_mesh(std::size_t k) const { return layers_[k].mesh ? &*layers_[k].mesh : nullptr; }
  const SurfaceResumption* resumption(std::size_t k) const {
    return layers_[k].resumption ? &*layers_[k].resumption : nullptr;
  }
  /// Force-mesh node positions (3 x N, m); empty (3 x 0) without force meshes.
  const Eigen::Matrix3Xd& node_rest_positions(std::size_t k) const;
  /// Current positions: the mesh while the layer is intact, the resumption after it broke.
  const Eigen::Matrix3Xd& node_positions(std::size_t k) const;
  /// 1-based ring index of every node; empty without force meshes.
  const std::vector<int>& node_rings(std::size_t k) const;

  /// Mechanical energy stored in the force meshes of intact layers (J).
  double mesh_energy_J() const;

 private:
  struct LayerModel {
    std::string name;
    double top_depth_m = 0.0;
    double thickness_m = 0.0;
    double damping_N_s_per_m2 = 0.0;
    std::unique_ptr<ContactSurface> surface;
    std::optional<ForceMesh> mesh;
    std::optional<SurfaceResumption> resumption;
    LayerState state = LayerState::Untouched;
    bool contact_set = false;
    SurfacePoint contact;
  };

  /// Steps 2-4 for the active layer; returns true if it broke this tick.
  bool press_active_layer(const NeedleState& needle, double& surface_force_sum_N);

  std::vector<LayerModel> layers_;
  std::vector<PunctureEvent> events_;
  TickResult result_;
  std::size_t active_ = 0;
  bool damping_on_ = false;
  double contact_search_height_m_ = 0.0;
  Eigen::Matrix3Xd empty_positions_;
  std::vector<int> empty_rings_;
};

}  // namespace puncture
