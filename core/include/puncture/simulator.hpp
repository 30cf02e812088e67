// simulator.hpp: the haptic tick of the real-time model (seed paper Sec.
// 2.2-2.3, with the force law of core/README.md "Force law").
//
// PunctureSimulator owns, per layer (top to bottom): the layer's contact
// surface, its force mesh (Effects::surface_force), its surface resumption
// (Effects::resumption, needs the force mesh), its damping coefficient
// (Effects::damping), its Karnopp shaft friction (Effects::friction), its
// cutting force (Effects::cutting) and its tip stiffening
// (Effects::stiffening). An effect that is off is not constructed and costs
// one check per tick. Everything is allocated at construction: tick() does
// no heap allocation.
//
// Names. The needle layer is the first layer not yet punctured (the tip can
// touch no other). With Effects::layer_interaction the needle layer and
// every layer below it form a chain of springs in series along the needle
// axis (layer_chain.hpp): each layer's force mesh is deflected relative to
// the surface of the layer below, so a layer pressed by the one above
// carries the load in its own force mesh (its state is Pressed) and the
// surface the needle meets next has already moved. Without it only the
// needle layer is loaded (the paper's model).
//
// One tick (needle state in, TickResult out; forces in N, positive when they
// resist insertion, see puncture_force.hpp):
//   1. punctured layers with resumption advance Eq. (8) to the tick's time;
//   2. contact: the needle layer's contact point is where the needle axis
//      crosses its rest surface (ContactSurface::intersect_ray), set when the
//      tip reaches the surface (with layer interaction: the surface as moved
//      by the chain). The force mesh is laid out there, along the surface
//      normal (ForceMesh::relayout, if it is not already laid there; with
//      layer interaction the meshes of the layers below are laid at the
//      axis' crossings with their surfaces when they are at rest). A contact
//      is released when the tip is back above the rest surface, so the next
//      touch lays the mesh where it happens.
//      Without layer interaction the layer below does not move, so a layer
//      pressed deeper than its own thickness (the skin, or the fat pressed
//      onto the muscle) leaves the tip below the next layer's rest surface
//      when it breaks. The broken layer left between the tip and that fixed
//      surface is then squeezed to nothing: the next layer's contact is made
//      at the tip in the same tick (its deflection counts from there), as the
//      FEM's soft layers are compressed ahead of the tip rather than carried,
//      and the tip keeps cutting the squeezed layer while it presses (5.);
//   3. the tip's penetration D past the contact point along the contact
//      normal drives the chain (displacement-driven: one common force F,
//      deflections summing to D; without interaction the chain is the needle
//      layer alone and F its mesh reaction). F >= 0 is the surface force; it
//      acts on the needle along the contact normal n (a frictionless tip:
//      F (-n . d) along the needle, the rest across it; core/README.md, "The
//      needle at an angle"). If
//      the needle layer has no contact yet, the chain below is loaded by the
//      cutting force of the layer above (force-driven) or relaxes;
//   4. breakthrough of the needle layer by its criterion
//      (BreakthroughCriterion: ring w deformed, critical surface force, or
//      critical stored energy); the surface force vanishes from this tick
//      on, a PunctureEvent is recorded, resumption starts from the broken
//      node positions, the crack front is set at the tip and the next layer
//      becomes the needle layer (its contact is checked in the same tick).
//      Without a force mesh (surface_force off) a layer breaks as soon as the
//      tip passes its contact point;
//   5. cutting: the last punctured layer, while the tip is inside it, adds
//      the cutting force (cutting.hpp, through shaft_forces.hpp, the rule the
//      comparison harness also calls; a PunctureEvent's total force holds
//      it): until the next layer is touched, or,
//      when the next layer was met at the break (contact at the tip, the
//      broken layer squeezed between them), while the tip presses it (the
//      FEM's tip force and cohesive cutting force act together there);
//      every punctured layer with a rupture release length adds the release
//      of the load the tip carried at its break beyond its cutting force (its
//      surface force and the crack above still cut, cutting.hpp), counted as
//      its cutting force, whatever the layers below do;
//   6. every punctured layer adds its shaft friction phi h (shaft_friction.hpp,
//      through shaft_forces.hpp)
//      and the damping force d h v (Table 1), with h the shaft length inside
//      the layer's depth range [top, top + thickness] of the scene;
//   7. a mesh laid out anew (step 2) starts in the tangent plane of the
//      contact point (exact force at once: the mechanics are deflections
//      along the normals) and gets its nodes projected onto the curved
//      surface kLayoutNodesPerTick per tick (a few us each on an SH surface),
//      so an off-axis contact costs no spike in one tick; a layer that breaks
//      before its layout is complete recovers towards the layout projected so
//      far, its goals moving with the projection (SurfaceResumption::move_goals).
// Effects::coupled_surfaces (without layer interaction) draws the layers'
// surfaces as one deformed slab (coupled_surfaces.hpp): the layers below the
// needle layer follow its surface through the half-space transmission, a
// layer met at the tip keeps the deformation the pressing left on it, and a
// broken layer rests on the layer below. It changes node_positions() only,
// never a force; it is computed when the surfaces are read, not in tick()
// (except the broken surface's profile and one matrix-vector product at a
// break, allocation-free).
// The force meshes are laid out at construction around the point where the
// scene's insertion line (x = y = 0, direction -z; inclined at
// insertion.angle_deg, needle.hpp) crosses each surface, and laid anew where
// the needle first meets a surface elsewhere (a needle off that line);
// the mesh step is the fixed haptic step 1 / RealtimeSettings::haptic_rate_Hz.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "puncture/contact_surface.hpp"
#include "puncture/cutting.hpp"
#include "puncture/force_mesh.hpp"
#include "puncture/coupled_surfaces.hpp"
#include "puncture/layer_chain.hpp"
#include "puncture/needle.hpp"
#include "puncture/puncture_force.hpp"
#include "puncture/resumption.hpp"
#include "puncture/scene.hpp"
#include "puncture/shaft_forces.hpp"

namespace puncture {

struct LayerTickResult {
  LayerState state = LayerState::Untouched;
  double surface_force_N = 0.0;       ///< force of the layer's surface on the tip (the needle layer only)
  double support_force_N = 0.0;       ///< load carried from the layer above (layer interaction; not on the needle)
  double cutting_force_N = 0.0;       ///< crack advance (the punctured layer the tip is in), both parts (cutting.hpp)
  double friction_force_N = 0.0;      ///< Karnopp shaft friction phi h (0 unless Punctured)
  double damping_force_N = 0.0;       ///< d h v (0 unless Punctured)
  int deformed_rings = 0;             ///< rings whose mean deflection exceeds the threshold
  double contact_deflection_m = 0.0;  ///< needle layer: tip past the contact point; chain layers: own deflection
  double shaft_length_m = 0.0;        ///< h: needle length inside the layer
  double stored_energy_J = 0.0;       ///< elastic energy of the needle layer's mesh (critical-energy criterion only)
};

struct TickResult {
  double time_s = 0.0;
  double depth_m = 0.0;           ///< tip depth below the undeformed skin surface (vertical)
  double path_depth_m = 0.0;      ///< tip past the entry point along the needle: depth_m / cos a (a: axis to the vertical)
  double velocity_m_per_s = 0.0;  ///< along the needle axis, > 0 inserting
  double total_force_N = 0.0;     ///< along the needle axis, > 0 resisting insertion: tip + cutting + friction
  double tip_force_N = 0.0;       ///< axial: surface force of the needle layer (its axial part) + the open crack's bevel part (cutting.hpp)
  double surface_force_N = 0.0;   ///< surface force of the needle layer alone, along its contact normal (the mesh's load)
  double lateral_force_N = 0.0;   ///< |force on the needle across its axis| (0 along the surface normal)
  Eigen::Vector3d force_on_needle_N = Eigen::Vector3d::Zero();  ///< the tissue's whole force on the needle, scene frame
  /// Moment of force_on_needle_N about the entry point (the axis' crossing with z = 0), N m, scene frame:
  /// (path_depth_m d) x force, which only the lateral part makes.
  Eigen::Vector3d torque_about_entry_N_m = Eigen::Vector3d::Zero();
  double cutting_force_N = 0.0;   ///< sum of the layers' cutting forces less the open crack's bevel part (in tip_force_N)
  double friction_force_N = 0.0;  ///< sum of shaft friction and damping d h v
  std::vector<LayerTickResult> layers;  ///< one per layer, sized at construction
};

/// Node projections per tick after a mesh was laid at a new contact point.
constexpr int kLayoutNodesPerTick = 4;

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
  /// Index of the needle layer (== layer_count() once all are punctured).
  std::size_t active_layer() const { return active_; }
  const std::vector<PunctureEvent>& puncture_events() const { return events_; }

  /// True while the needle is in contact with layer k (and after it broke).
  bool has_contact(std::size_t k) const { return layers_[k].contact_set; }
  /// Where layer k's contact deflection is measured from (its last contact).
  const SurfacePoint& contact_point(std::size_t k) const { return layers_[k].contact; }

  /// nullptr when Effects::surface_force is off.
  const ForceMesh* force_mesh(std::size_t k) const { return layers_[k].mesh ? &*layers_[k].mesh : nullptr; }
  const SurfaceResumption* resumption(std::size_t k) const {
    return layers_[k].resumption ? &*layers_[k].resumption : nullptr;
  }
  /// Deflection (m) of layer k's contact node relative to the layer below.
  double relative_deflection_m(std::size_t k) const { return layers_[k].deflection_m; }
  /// Deflection (m) of layer k's surface at its contact node: its own plus
  /// that of every layer below (layer interaction), along the normals.
  double surface_deflection_m(std::size_t k) const;
  /// Crack front of a punctured layer along the needle axis (m), see cutting.hpp.
  double crack_front_m(std::size_t k) const { return layers_[k].front_m; }
  const KarnoppFriction* friction(std::size_t k) const {
    return layers_[k].friction ? &layers_[k].friction->stick_slip : nullptr;
  }
  /// Layer k's relaxed shaft contact length h_eff (m, shaft_pressure_relaxation.hpp) of the last tick; nullptr without friction.
  const ShaftPressureRelaxation* shaft_contact_pressure(std::size_t k) const {
    return layers_[k].friction ? &layers_[k].friction->contact_pressure : nullptr;
  }

  /// Force-mesh node rest positions (3 x N, m); empty (3 x 0) without force meshes.
  const Eigen::Matrix3Xd& node_rest_positions(std::size_t k) const;
  /// Current positions: the mesh while the layer is intact, the resumption
  /// after it broke; with layer interaction shifted by the deflection of the
  /// layers below, with coupled surfaces as drawn by SurfaceCoupling (not for
  /// use inside the haptic loop).
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
    ForceLaw law;
    std::unique_ptr<ContactSurface> surface;
    std::optional<ForceMesh> mesh;
    std::optional<SurfaceResumption> resumption;
    std::optional<LayerShaftFriction> friction;
    const StiffeningLaw* stiffening = nullptr;  ///< &law.stiffening when the effect is on
    LayerState state = LayerState::Untouched;
    bool contact_set = false;
    bool contact_at_tip = false;  ///< contact below the rest surface (no layer interaction)
    /// Without layer interaction: from this position of the tip along the
    /// needle axis on, a contact below the rest surface is made at the tip
    /// (+inf: only at the surface crossing; the tip at the break of the layer
    /// above when it broke below this layer's rest surface). See try_contact.
    double tip_contact_from_m = 0.0;
    SurfacePoint contact;
    double contact_time_s = 0.0;   ///< when the needle's contact with this layer began
    double contact_axial_m = 0.0;  ///< the tip along the needle axis then (the mean pressing speed's start)
    double deflection_m = 0.0;    ///< committed deflection of the contact node relative to the layer below
    double front_m = 0.0;         ///< crack front along the needle axis (punctured layers)
    double break_axial_m = 0.0;   ///< tip position along the needle axis at the break (punctured layers)
    double release_N = 0.0;       ///< R of the rupture release (cutting.hpp): load at the tip at the break beyond C
    double release_length_m = 0.0;  ///< l(v_b) of the rupture release at the break speed (cutting.hpp)
    double fracture_limit_N = 0.0;  ///< G_c w: the most of its cutting force that is fracture (cutting.hpp)
    mutable Eigen::Matrix3Xd shifted_positions;
  };

  /// Where a ray along the needle that searches for a surface crossing starts: above every surface.
  Eigen::Vector3d search_origin(const NeedleState& needle) const;
  /// Sets the contact of the needle layer if the tip has reached its surface.
  bool try_contact(const NeedleState& needle);
  /// The tick's force as a vector, its part across the needle (lateral_N, N, scene frame: the surface
  /// force's) and its moment about the entry point (TickResult), from total_force_N along the needle.
  void resolve_force_vector(const NeedleState& needle, const Eigen::Vector3d& lateral_N);
  /// Lays the force mesh of layer k where the needle axis crosses its rest
  /// surface, if it is at rest and laid elsewhere.
  void lay_mesh_on_axis(std::size_t k, const NeedleState& needle, const SurfacePoint* hit);
  /// Steps the meshes of the chain [active_, chain_end_) (see the header).
  /// Returns the needle layer's surface force (0 without contact).
  double step_chain(const NeedleState& needle, double transmitted_force_N);
  /// Layer k's criterion at its surface force (N), its threshold at the layer's mean pressing speed (breakthrough_rate.hpp).
  bool breakthrough(std::size_t k, double surface_force_N, const NeedleState& needle);
  /// crack_above_N: the crack force of the layer above still cut at the break (N; 0 unless this layer was met
  /// at the tip), which passes with the surface force to this layer's rupture release.
  void record_puncture(const NeedleState& needle, double surface_force_N, double cutting_force_N,
                       double crack_above_N);
  /// The tick's phases (tick() calls them in this order; see the header comment).
  void resume_broken_layers(double time_s);
  void update_needle_contact(const NeedleState& needle);
  /// Cutting force (N, by part) of the deepest punctured layer at axial speed v (shaft_forces.hpp),
  /// its crack front advanced.
  CuttingForceParts crack_force(double tip_axial_m, double axial_speed_m_per_s);
  /// Rupture release of every punctured layer (cutting.hpp), written to each
  /// layer's cutting force of this tick; returns their sum (N).
  double rupture_release(double tip_axial_m);
  /// Chain under the needle stepped; returns the needle layer's surface force.
  double press_needle_layer(const NeedleState& needle, double transmitted_force_N);
  /// Layers breaking under surface_force_N (several in one tick if the next is met already broken);
  /// true if any broke.
  /// cutting_force_N: what the needle's cracks add at the first break (crack + rupture releases);
  /// crack_force_N: the open crack's part of it (crack_force()).
  bool break_through(const NeedleState& needle, double surface_force_N, double cutting_force_N,
                     double crack_force_N);
  /// Friction and damping of every punctured layer; returns their sum (N).
  double shaft_friction_and_damping(const NeedleState& needle);
  /// Puncture events of this tick: their total force includes the layers above's shaft forces.
  void add_shaft_forces_to_events(double time_s);
  /// Meshes laid at a new contact point get a few more nodes projected onto the surface.
  void refine_pending_layouts();
  /// Layer k's own node positions: its mesh while intact, its resumption after it broke (needs a mesh).
  const Eigen::Matrix3Xd& own_positions(std::size_t k) const;
  /// Own deflection of layer k's nodes along the inward normals (m) into `out`.
  void own_deflection(std::size_t k, Eigen::Ref<Eigen::VectorXd> out) const;
  /// Coupled surfaces: layer k broke under surface_force_N with the tip at tip_depth_m.
  void freeze_coupled_break(std::size_t k, double surface_force_N, double tip_depth_m);
  /// Coupled surfaces: the drawn deflections of this tick (computed once per tick).
  void update_drawn_surfaces() const;

  std::vector<LayerModel> layers_;
  std::vector<PunctureEvent> events_;
  TickResult result_;
  std::size_t active_ = 0;
  bool damping_on_ = false;
  bool cutting_on_ = false;
  bool interaction_ = false;
  bool first_tick_ = true;
  double deepest_axial_m_ = -std::numeric_limits<double>::infinity();  ///< deepest tip position so far (m along the axis)
  double contact_search_height_m_ = 0.0;
  double relayout_tolerance_m_ = 0.0;
  std::array<ChainLink, kMaxChainLinks> links_{};
  std::array<double, kMaxChainLinks> link_deflection_m_{};
  Eigen::Matrix3Xd empty_positions_;
  std::vector<int> empty_rings_;
  std::optional<SurfaceCoupling> coupling_;  ///< Effects::coupled_surfaces
  Eigen::VectorXd break_deflection_;         ///< own deflection of a layer at its break (sized to the largest mesh)
  std::uint64_t ticks_ = 0;
  mutable std::uint64_t drawn_tick_ = ~std::uint64_t{0};
  mutable std::vector<Eigen::VectorXd> own_deflection_, drawn_deflection_;
};

}  // namespace puncture
