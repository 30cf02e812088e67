#include "puncture/simulator.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "puncture/breakthrough_rate.hpp"
#include "puncture/cutting.hpp"
#include "puncture/shaft_forces.hpp"
#include "puncture/stiffening.hpp"

namespace puncture {

namespace {
/// The share of a load along the surface normal n that acts along the needle:
/// -n . d, the cosine of the angle between them (1 along the sample axis).
double along_needle(const Eigen::Vector3d& normal, const NeedleState& needle) {
  return -normal.dot(needle.direction);
}
}  // namespace

PunctureSimulator::PunctureSimulator(const Scene& scene, std::vector<std::unique_ptr<ContactSurface>> layer_surfaces)
    : empty_positions_(3, 0) {
  if (scene.layers.empty()) throw std::invalid_argument("scene has no layers");
  if (layer_surfaces.size() != scene.layers.size())
    throw std::invalid_argument("PunctureSimulator: " + std::to_string(layer_surfaces.size()) +
                                " layer surfaces given for " + std::to_string(scene.layers.size()) + " layers");
  if (!(scene.realtime.haptic_rate_Hz > 0.0)) throw std::invalid_argument("realtime.haptic_rate_Hz must be positive");

  MeshIntegrationSettings integration;
  integration.integrator = parse_mesh_integrator(scene.realtime.integrator);
  integration.time_step_s = 1.0 / scene.realtime.haptic_rate_Hz;
  damping_on_ = scene.effects.damping;
  cutting_on_ = scene.effects.cutting;
  interaction_ = scene.effects.layer_interaction && scene.effects.surface_force;
  if (interaction_ && scene.layers.size() > static_cast<std::size_t>(kMaxChainLinks))
    throw std::invalid_argument("layer_interaction supports at most " + std::to_string(kMaxChainLinks) + " layers");
  // Rays searching for a contact start this far above the tip: above every surface.
  contact_search_height_m_ = std::max(0.0, scene.insertion.start_height_m) + scene.total_thickness_m() +
                             scene.sample.diameter_m;
  relayout_tolerance_m_ = 1e-9;

  layers_.resize(scene.layers.size());
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const Layer& in = scene.layers[k];
    LayerModel& layer = layers_[k];
    if (!layer_surfaces[k]) throw std::invalid_argument("PunctureSimulator: layer surface " + std::to_string(k) + " is null");
    if (!(in.thickness_m > 0.0)) throw std::invalid_argument("layer \"" + in.name + "\": thickness must be positive");
    layer.name = in.name;
    layer.top_depth_m = scene.layer_top_depth_m(k);
    layer.thickness_m = in.thickness_m;
    layer.law = in.force_law;
    layer.fracture_limit_N = fracture_limit_N(in, scene.needle);
    layer.surface = std::move(layer_surfaces[k]);
    if (damping_on_) {
      if (!(in.damping_N_s_per_m2 >= 0.0)) throw std::invalid_argument("layer \"" + in.name + "\": damping must be >= 0");
      layer.damping_N_s_per_m2 = in.damping_N_s_per_m2;
    }
    layer.tip_contact_from_m = std::numeric_limits<double>::infinity();
    if (scene.effects.friction) layer.friction.emplace(in.force_law.friction, in.material.viscoelastic);
    if (cutting_on_ && !(in.force_law.cutting_force_N >= 0.0 && in.force_law.cutting_release_m > 0.0 &&
                         in.force_law.rupture_release_m >= 0.0))
      throw std::invalid_argument("layer \"" + in.name +
                                  "\": cutting force must be >= 0, its release distance > 0 and its rupture release >= 0");
    if (scene.effects.stiffening) layer.stiffening = &layer.law.stiffening;
    if (scene.effects.surface_force) {
      // Laid where the scene's insertion line (needle.hpp: through the origin
      // at insertion.angle_deg) crosses the surface, so that a scripted
      // insertion meets every mesh where it lies and no tick lays one anew.
      double s = 0.0;
      SurfacePoint centre;
      NeedleState line;  // the tip at the entry point
      line.direction = insertion_direction(scene.insertion);
      if (!layer.surface->intersect_ray(search_origin(line), line.direction, s, centre))
        throw std::invalid_argument("layer \"" + in.name + "\": the insertion axis misses its surface");
      layer.mesh.emplace(*layer.surface, centre, in.force_mesh, in.thickness_m, in.density_kg_per_m3, integration);
      layer.shifted_positions = layer.mesh->rest_positions();
      if (scene.effects.resumption) layer.resumption.emplace(layer.mesh->rest_positions(), in.resumption_time_s);
    }
  }
  events_.reserve(layers_.size());
  result_.layers.resize(layers_.size());
  if (scene.effects.coupled_surfaces && scene.effects.surface_force && !interaction_) {
    std::vector<SurfaceCoupling::LayerGeometry> geometry(layers_.size());
    Eigen::Index largest = 0;
    for (std::size_t k = 0; k < layers_.size(); ++k) {
      if (!layers_[k].mesh) continue;
      geometry[k] = {&layers_[k].mesh->lattice(), scene.layers[k].force_mesh.spacing_L_m, layers_[k].top_depth_m};
      largest = std::max<Eigen::Index>(largest, layers_[k].mesh->node_count());
    }
    coupling_.emplace(geometry, scene.total_thickness_m());
    break_deflection_ = Eigen::VectorXd::Zero(largest);
    own_deflection_.resize(layers_.size());
    drawn_deflection_.resize(layers_.size());
    for (std::size_t k = 0; k < layers_.size(); ++k)
      if (layers_[k].mesh)  // sized once: drawing the surfaces allocates nothing
        own_deflection_[k] = drawn_deflection_[k] = Eigen::VectorXd::Zero(layers_[k].mesh->node_count());
  }
}

const Eigen::Matrix3Xd& PunctureSimulator::own_positions(std::size_t k) const {
  const LayerModel& layer = layers_[k];
  return layer.resumption && layer.resumption->active() ? layer.resumption->positions() : layer.mesh->positions();
}

void PunctureSimulator::own_deflection(std::size_t k, Eigen::Ref<Eigen::VectorXd> out) const {
  const LayerModel& layer = layers_[k];
  const Eigen::Matrix3Xd& pos = own_positions(k);
  const Eigen::Matrix3Xd& rest = layer.mesh->rest_positions();
  const Eigen::Matrix3Xd& normal = layer.mesh->normals();
  for (Eigen::Index i = 0; i < pos.cols(); ++i) out(i) = normal.col(i).dot(rest.col(i) - pos.col(i));
}

void PunctureSimulator::freeze_coupled_break(std::size_t k, double surface_force_N, double tip_depth_m) {
  if (!coupling_ || !layers_[k].mesh) return;
  auto own = break_deflection_.head(layers_[k].mesh->node_count());
  own_deflection(k, own);
  coupling_->freeze_break(k, own, surface_force_N, tip_depth_m);
}

void PunctureSimulator::update_drawn_surfaces() const {
  if (drawn_tick_ == ticks_) return;
  for (std::size_t k = 0; k < layers_.size(); ++k)
    if (layers_[k].mesh) own_deflection(k, own_deflection_[k]);  // sized at construction
  // The last broken layer carries the needle's load while no layer below bears
  // it by itself: none is pressed, or the one met at the tip (the broken layer
  // squeezed between them) has not yet taken its baseline over.
  SurfaceCoupling::LoadAfterBreak load;
  const bool next_bears_load =
      active_ < layers_.size() && layers_[active_].contact_set &&
      (!layers_[active_].contact_at_tip || coupling_->baseline_taken_over(active_, own_deflection_[active_]));
  const bool loaded = active_ > 0 && !next_bears_load;
  if (loaded) {
    load.layer = active_ - 1;
    load.tip_depth_m = result_.depth_m;
    load.tip_force_N = result_.tip_force_N + result_.cutting_force_N;
    load.shaft_force_N = result_.friction_force_N;
  }
  coupling_->drawn(own_deflection_, active_, drawn_deflection_, loaded ? &load : nullptr);
  drawn_tick_ = ticks_;
}

const Eigen::Matrix3Xd& PunctureSimulator::node_rest_positions(std::size_t k) const {
  return layers_[k].mesh ? layers_[k].mesh->rest_positions() : empty_positions_;
}

double PunctureSimulator::surface_deflection_m(std::size_t k) const {
  double y = 0.0;
  for (std::size_t j = k; j < layers_.size(); ++j) y += layers_[j].deflection_m;
  return y;
}

const Eigen::Matrix3Xd& PunctureSimulator::node_positions(std::size_t k) const {
  const LayerModel& layer = layers_[k];
  if (!layer.mesh) return empty_positions_;
  const Eigen::Matrix3Xd& own = own_positions(k);
  if (coupling_) {
    update_drawn_surfaces();
    layer.shifted_positions = own;
    const Eigen::VectorXd& drawn = drawn_deflection_[k];
    const Eigen::VectorXd& mine = own_deflection_[k];
    for (Eigen::Index i = 0; i < own.cols(); ++i)
      if (drawn(i) > mine(i)) layer.shifted_positions.col(i) -= (drawn(i) - mine(i)) * layer.mesh->normals().col(i);
    return layer.shifted_positions;
  }
  const double base = k + 1 < layers_.size() ? surface_deflection_m(k + 1) : 0.0;
  if (!interaction_ || base == 0.0) return own;
  // The layer rides on the surface of the layer below, moved by `base` along the normals.
  layer.shifted_positions = own - base * layer.mesh->normals();
  return layer.shifted_positions;
}

const std::vector<int>& PunctureSimulator::node_rings(std::size_t k) const {
  return layers_[k].mesh ? layers_[k].mesh->node_rings() : empty_rings_;
}

double PunctureSimulator::mesh_energy_J() const {
  double e = 0.0;
  for (const LayerModel& layer : layers_)
    if (layer.mesh && layer.state != LayerState::Punctured) e += layer.mesh->energy_J();
  return e;
}

void PunctureSimulator::lay_mesh_on_axis(std::size_t k, const NeedleState& needle, const SurfacePoint* hit) {
  LayerModel& layer = layers_[k];
  if (!layer.mesh) return;
  SurfacePoint crossing;
  if (hit) {
    crossing = *hit;
  } else {
    double s = 0.0;
    if (!layer.surface->intersect_ray(search_origin(needle), needle.direction, s, crossing)) return;
  }
  if (layer.mesh->laid_at(crossing, relayout_tolerance_m_)) return;
  // Only a mesh at rest is moved (a loaded one keeps its layout until it relaxed).
  if (layer.deflection_m != 0.0 || !layer.mesh->at_rest(1e-12)) return;
  layer.mesh->relayout(*layer.surface, crossing);
  if (layer.resumption && !layer.resumption->active()) layer.resumption->set_rest_positions(layer.mesh->rest_positions());
}

Eigen::Vector3d PunctureSimulator::search_origin(const NeedleState& needle) const {
  return needle.tip_position_m -
         needle.direction * needle.along_axis_m(contact_search_height_m_ + std::abs(needle.tip_position_m.z()));
}

bool PunctureSimulator::try_contact(const NeedleState& needle) {
  LayerModel& layer = layers_[active_];
  const Eigen::Vector3d& tip = needle.tip_position_m;
  double s = 0.0;
  SurfacePoint hit;
  if (!layer.surface->intersect_ray(search_origin(needle), needle.direction, s, hit)) return false;  // not over this surface
  const double penetration = hit.normal.dot(hit.position - tip);
  const double surface_moved = interaction_ ? surface_deflection_m(active_) : 0.0;
  if (penetration < surface_moved) return false;  // the tip has not reached the surface yet
  layer.contact = hit;
  layer.contact_at_tip = false;
  if (!interaction_ && penetration > 0.0 && std::isfinite(layer.tip_contact_from_m)) {
    // Reached with the tip already below the rest surface, as the layer
    // above broke (see the header): pressed from where the tip is.
    if (needle.tip_position_m.dot(needle.direction) < layer.tip_contact_from_m) return false;
    layer.contact.position = tip;
    layer.contact_at_tip = true;
  }
  layer.contact_set = true;
  layer.contact_time_s = needle.time_s;
  layer.contact_axial_m = needle.tip_position_m.dot(needle.direction);
  lay_mesh_on_axis(active_, needle, &hit);
  if (interaction_)
    for (std::size_t j = active_ + 1; j < layers_.size(); ++j) lay_mesh_on_axis(j, needle, nullptr);
  return true;
}

double PunctureSimulator::step_chain(const NeedleState& needle, double transmitted_force_N) {
  const std::size_t a = active_;
  LayerModel& top = layers_[a];
  const std::size_t end = interaction_ ? layers_.size() : a + 1;
  const int n = static_cast<int>(end - a);
  double penetration = 0.0;
  bool needle_driven = top.contact_set;
  if (needle_driven) {
    penetration = top.contact.normal.dot(top.contact.position - needle.tip_position_m);
    if (penetration <= 0.0 && !top.contact_at_tip) {
      top.contact_set = false;  // the tip is back above the rest surface: the next touch lays the mesh anew
      needle_driven = false;
    }
    result_.layers[a].contact_deflection_m = std::max(0.0, penetration);
  }
  if (!(needle_driven && penetration > 0.0)) {
    // Force-driven (or relaxing): nothing to do if it carries no load and is at rest.
    bool idle = transmitted_force_N == 0.0;
    for (std::size_t j = a; j < end && idle; ++j) idle = layers_[j].deflection_m == 0.0 && layers_[j].mesh->at_rest();
    if (idle) return 0.0;
  }

  for (int i = 0; i < n; ++i) {
    LayerModel& layer = layers_[a + i];
    layer.mesh->predict();
    links_[i].intercept_N = layer.mesh->predicted_reaction_N(0.0);
    links_[i].slope_N_per_m = layer.mesh->reaction_slope_N_per_m();
    links_[i].stiffening = layer.stiffening;
  }
  double force = transmitted_force_N;
  bool pushing = false;
  if (needle_driven && penetration > 0.0) {
    force = solve_series_chain(links_.data(), n, penetration, link_deflection_m_.data());
    pushing = force > 0.0;
    if (!pushing) force = 0.0;  // the meshes' own motion carries the surface past the tip
  }
  if (!pushing)
    for (int i = 0; i < n; ++i) link_deflection_m_[i] = link_deflection_m(links_[i], force);

  double surface_force = 0.0;
  for (int i = 0; i < n; ++i) {
    LayerModel& layer = layers_[a + i];
    LayerTickResult& out = result_.layers[a + i];
    const double r = link_deflection_m_[i];
    layer.mesh->commit(r);
    layer.deflection_m = r;
    out.deformed_rings = layer.mesh->deformed_rings();
    if (i == 0 && needle_driven) {
      if (pushing) surface_force = std::max(0.0, link_force_N(links_[0], r));
      out.surface_force_N = surface_force;
      layer.state = pushing ? LayerState::Pressed : LayerState::Untouched;
    } else {
      out.contact_deflection_m = r;
      out.support_force_N = r > 0.0 ? force : 0.0;
      layer.state = r > 0.0 ? LayerState::Pressed : LayerState::Untouched;
    }
    out.state = layer.state;
  }
  return surface_force;
}

bool PunctureSimulator::breakthrough(std::size_t k, double surface_force_N, const NeedleState& needle) {
  const LayerModel& layer = layers_[k];
  if (!layer.mesh) return result_.layers[k].contact_deflection_m > 0.0;
  if (layer.state != LayerState::Pressed) return false;
  const BreakthroughCriterion& c = layer.law.breakthrough;
  // The surface is loaded at the tip's speed along its normal (v cos a for a needle at a to it).
  const double normal_share = along_needle(layer.contact.normal, needle);
  const double rate = breakthrough_rate_factor(
      c, mean_pressing_speed_m_per_s(layer.contact_axial_m * normal_share, layer.contact_time_s,
                                     needle.axial_position_m() * normal_share, needle.time_s,
                                     c.reference_speed_m_per_s));
  switch (c.kind) {
    case BreakthroughCriterion::Kind::Rings: return layer.mesh->broken();
    case BreakthroughCriterion::Kind::CriticalForce: return surface_force_N >= c.critical_force_N * rate;
    case BreakthroughCriterion::Kind::CriticalEnergy: {
      double e = layer.mesh->virtual_spring_energy_J() + layer.mesh->surface_spring_energy_J();
      if (layer.stiffening) e += stiffening_energy_J(*layer.stiffening, layer.deflection_m);
      result_.layers[k].stored_energy_J = e;
      return e >= c.critical_energy_J * rate;
    }
  }
  return false;
}

void PunctureSimulator::record_puncture(const NeedleState& needle, double surface_force_N, double cutting_force_N,
                                        double crack_above_N) {
  LayerModel& layer = layers_[active_];
  LayerTickResult& out = result_.layers[active_];
  layer.state = LayerState::Punctured;
  out.state = LayerState::Punctured;
  out.surface_force_N = 0.0;  // the surface force vanishes from this tick on
  PunctureEvent event;
  event.layer = static_cast<int>(active_);
  event.layer_name = layer.name;
  event.time_s = needle.time_s;
  event.depth_m = needle.depth_m();
  event.surface_force_N = surface_force_N;
  event.cutting_force_N = cutting_force_N;
  // Along the needle axis (tick() adds the shaft forces of the layers above):
  // the surface force acts along the contact normal (see the header).
  const double axial_share = along_needle(layer.contact.normal, needle);
  event.total_force_N = surface_force_N * axial_share + cutting_force_N;
  if (layer.mesh) {
    event.eq5_force_N = layer.mesh->eq5_force_N();
    event.mesh_reaction_N = layer.mesh->contact_reaction_N();
    if (layer.stiffening) event.tip_stiffening_force_N = stiffening_force_N(*layer.stiffening, layer.deflection_m);
  }
  events_.push_back(event);               // capacity reserved at construction
  if (layer.mesh && layer.mesh->layout_pending() && layer.resumption) {
    // A break within a few ticks of the contact (a layer met at the tip by a
    // needle off the scene's insertion line): the recovery starts towards the
    // layout as far as it is projected, and refine_pending_layouts() moves its
    // goals as the remaining nodes reach the surface (projecting them all in
    // this tick would cost up to ~100 us).
    layer.resumption->set_rest_positions(layer.mesh->rest_positions());
  }
  if (coupling_) freeze_coupled_break(active_, surface_force_N, needle.depth_m());
  if (layer.resumption) layer.resumption->start(layer.mesh->positions(), needle.time_s);
  const double tip_axial = needle.tip_position_m.dot(needle.direction);
  layer.front_m = tip_axial;
  layer.break_axial_m = tip_axial;
  // The load the tip carried along the needle, its surface force's axial part
  // and the crack above still cut (a layer met at the tip), passes to this
  // layer's crack.
  layer.release_N = cutting_on_ ? rupture_release_N(layer.law, surface_force_N * axial_share + crack_above_N,
                                                    needle.axial_velocity_m_per_s)
                                : 0.0;
  layer.release_length_m = rupture_release_length_m(layer.law, needle.axial_velocity_m_per_s);
  ++active_;
  if (active_ < layers_.size() && !interaction_) {
    LayerModel& next = layers_[active_];
    next.tip_contact_from_m = std::numeric_limits<double>::infinity();
    double s = 0.0;
    SurfacePoint hit;
    if (next.surface->intersect_ray(search_origin(needle), needle.direction, s, hit) &&
        hit.normal.dot(hit.position - needle.tip_position_m) > 0.0) {
      // The tip is already below the next rest surface, which does not move
      // without layer interaction: the broken layer left between them is
      // squeezed to nothing, so the next layer is pressed from the tip on.
      next.tip_contact_from_m = tip_axial;
    }
  }
}

void PunctureSimulator::resume_broken_layers(double time_s) {
  for (std::size_t k = 0; k < active_; ++k)
    if (layers_[k].resumption) layers_[k].resumption->step(time_s);
}

void PunctureSimulator::update_needle_contact(const NeedleState& needle) {
  // A tip that starts below the first surface is in contact at once.
  if (first_tick_) layers_[0].tip_contact_from_m = -std::numeric_limits<double>::infinity();
  if (active_ < layers_.size() && !layers_[active_].contact_set) try_contact(needle);
  if (first_tick_) layers_[0].tip_contact_from_m = std::numeric_limits<double>::infinity();
  first_tick_ = false;
}

CuttingForceParts PunctureSimulator::crack_force(double tip_axial_m, double axial_speed_m_per_s) {
  // The punctured layer the tip is in is cut until the next layer is touched,
  // or, when that layer was met at the break (contact at the tip, the broken
  // layer squeezed between them), while the tip presses it.
  if (!cutting_on_ || active_ == 0) return {};
  const std::size_t n = layers_.size();
  const NextLayerContact next = active_ == n || !layers_[active_].contact_set ? NextLayerContact::None
                                : layers_[active_].contact_at_tip          ? NextLayerContact::MetAtTip
                                                                           : NextLayerContact::Touched;
  LayerModel& p = layers_[active_ - 1];
  return open_crack_force_N(p.law, p.front_m, tip_axial_m, axial_speed_m_per_s, next, p.fracture_limit_N);
}

double PunctureSimulator::rupture_release(double tip_axial_m) {
  if (!cutting_on_) return 0.0;
  double total = 0.0;
  for (std::size_t k = 0; k < active_; ++k) {
    const LayerModel& p = layers_[k];
    const double f = rupture_release_force_N(p.release_N, p.release_length_m, p.law.cutting_release_m,
                                             p.break_axial_m, deepest_axial_m_, tip_axial_m);
    result_.layers[k].cutting_force_N = f;
    total += f;
  }
  return total;
}

double PunctureSimulator::press_needle_layer(const NeedleState& needle, double transmitted_force_N) {
  if (active_ >= layers_.size()) return 0.0;
  if (layers_[active_].mesh) return step_chain(needle, transmitted_force_N);
  if (layers_[active_].contact_set) {
    const LayerModel& layer = layers_[active_];
    const double d = layer.contact.normal.dot(layer.contact.position - needle.tip_position_m);
    result_.layers[active_].contact_deflection_m = std::max(0.0, d);
  }
  return 0.0;
}

bool PunctureSimulator::break_through(const NeedleState& needle, double surface_force_N, double cutting_force_N,
                                      double crack_force_N) {
  const std::size_t n = layers_.size();
  bool broke = false;
  // The next layer becomes the needle layer in the same tick.
  while (active_ < n && layers_[active_].contact_set && breakthrough(active_, surface_force_N, needle)) {
    record_puncture(needle, surface_force_N, cutting_force_N, crack_force_N);
    surface_force_N = 0.0;
    // A further break in this tick is felt with the crack of the layer that just broke, opened at the tip.
    crack_force_N =
        cutting_on_ ? rate_cutting_force(layers_[active_ - 1].law, needle.axial_velocity_m_per_s).total_N() : 0.0;
    cutting_force_N = cutting_on_ ? crack_force_N + rupture_release(needle.tip_position_m.dot(needle.direction)) : 0.0;
    broke = true;
    const bool touched = active_ < n && try_contact(needle);
    if (coupling_) {
      // The layer met at the tip keeps the deformation the pressing left; the broken one rests on it.
      if (touched && layers_[active_].contact_at_tip) coupling_->freeze_baseline(active_);
      coupling_->clear_baseline(active_ - 1);
    }
    if (touched && !layers_[active_].mesh) {
      const LayerModel& layer = layers_[active_];
      result_.layers[active_].contact_deflection_m =
          std::max(0.0, layer.contact.normal.dot(layer.contact.position - needle.tip_position_m));
    }
  }
  if (active_ < n && !layers_[active_].mesh && layers_[active_].contact_set) {
    // Without a force mesh the layer the tip touches is pressed at zero force.
    LayerTickResult& out = result_.layers[active_];
    layers_[active_].state = out.contact_deflection_m > 0.0 ? LayerState::Pressed : LayerState::Untouched;
    out.state = layers_[active_].state;
  }
  return broke;
}

double PunctureSimulator::shaft_friction_and_damping(const NeedleState& needle) {
  double total = 0.0;
  for (std::size_t k = 0; k < active_; ++k) {
    LayerTickResult& out = result_.layers[k];
    LayerModel& layer = layers_[k];
    out.state = LayerState::Punctured;
    const LayerShaftForce shaft =
        punctured_layer_shaft_force(layer.top_depth_m, layer.thickness_m, layer.friction ? &*layer.friction : nullptr,
                                    damping_on_, layer.damping_N_s_per_m2, needle);
    out.shaft_length_m = shaft.shaft_length_m;
    out.friction_force_N = shaft.friction_N;
    out.damping_force_N = shaft.damping_N;
    total += out.friction_force_N + out.damping_force_N;
  }
  return total;
}

void PunctureSimulator::add_shaft_forces_to_events(double time_s) {
  for (PunctureEvent& e : events_)
    if (e.time_s == time_s) {
      for (int k = 0; k < e.layer; ++k)
        e.total_force_N += result_.layers[k].damping_force_N + result_.layers[k].friction_force_N;
      // The needle's whole force at the break scales the broken surface's load (coupled_surfaces.hpp).
      if (coupling_) coupling_->set_break_force(static_cast<std::size_t>(e.layer), e.total_force_N);
    }
}

void PunctureSimulator::refine_pending_layouts() {
  // Only the drawn surface depends on the layout.
  int budget = kLayoutNodesPerTick;
  for (LayerModel& layer : layers_) {
    if (budget <= 0) break;
    if (!layer.mesh || !layer.mesh->layout_pending()) continue;
    const int nodes = std::min(budget, layer.mesh->pending_nodes());
    layer.mesh->refine_layout(nodes);
    budget -= nodes;
    if (layer.resumption && layer.resumption->active())
      layer.resumption->move_goals(layer.mesh->rest_positions());  // a broken layer recovering
    else if (!layer.mesh->layout_pending() && layer.resumption)
      layer.resumption->set_rest_positions(layer.mesh->rest_positions());
  }
}

void PunctureSimulator::resolve_force_vector(const NeedleState& needle, const Eigen::Vector3d& lateral_N) {
  const Eigen::Vector3d& d = needle.direction;
  // The axial parts act along -d; the surface force's part across the needle is lateral_N.
  result_.force_on_needle_N = -result_.total_force_N * d + lateral_N;
  result_.lateral_force_N = lateral_N.norm();
  // The entry point: where the needle axis crosses the skin's undeformed plane z = 0.
  const double cos_axis = needle.axis_cosine();
  result_.path_depth_m = cos_axis >= kMinAxisCosine ? needle.depth_m() / cos_axis : needle.depth_m();
  const Eigen::Vector3d arm = cos_axis >= kMinAxisCosine ? Eigen::Vector3d(result_.path_depth_m * d)
                                                         : Eigen::Vector3d::Zero();
  result_.torque_about_entry_N_m = arm.cross(result_.force_on_needle_N);
}

const TickResult& PunctureSimulator::tick(const NeedleState& needle) {
  if (!needle.tip_position_m.allFinite() || !needle.direction.allFinite() ||
      !std::isfinite(needle.axial_velocity_m_per_s) || !std::isfinite(needle.time_s))
    throw std::invalid_argument("PunctureSimulator::tick: non-finite needle state");

  ++ticks_;  // drawn surfaces of the last tick are stale from here on
  result_.time_s = needle.time_s;
  result_.depth_m = needle.depth_m();
  result_.velocity_m_per_s = needle.axial_velocity_m_per_s;
  for (LayerTickResult& r : result_.layers) r = LayerTickResult{};
  const double tip_axial_m = needle.tip_position_m.dot(needle.direction);
  deepest_axial_m_ = std::max(deepest_axial_m_, tip_axial_m);

  // 1. Resumption of the layers broken in earlier ticks.
  resume_broken_layers(needle.time_s);
  // 2. Contact of the needle layer; the crack ahead of the tip.
  update_needle_contact(needle);
  CuttingForceParts crack = crack_force(tip_axial_m, needle.axial_velocity_m_per_s);
  double cut = crack.total_N() + rupture_release(tip_axial_m);
  // 3. The chain under the needle (or the needle layer alone).
  double surface_force = press_needle_layer(needle, interaction_ ? cut : 0.0);
  const Eigen::Vector3d surface_normal =
      active_ < layers_.size() && layers_[active_].contact_set ? layers_[active_].contact.normal : -needle.direction;
  // 4. Breakthrough: the crack through the layer that just broke starts at the tip.
  const bool broke = break_through(needle, surface_force, cut, crack.total_N());
  if (broke) {
    surface_force = 0.0;
    crack = crack_force(tip_axial_m, needle.axial_velocity_m_per_s);
    cut = crack.total_N() + rupture_release(tip_axial_m);
  }
  if (active_ > 0) result_.layers[active_ - 1].cutting_force_N += crack.total_N();
  // 5. Shaft friction and damping of the punctured layers.
  const double friction_total = shaft_friction_and_damping(needle);
  // The crack's viscous part (cutting.hpp) is the tissue the bevel wedges apart: tip force.
  // The surface force acts along the contact normal n: F (-n . d) along the needle, the rest across it.
  const double surface_share = along_needle(surface_normal, needle);
  const double surface_axial = surface_force * surface_share;
  result_.surface_force_N = surface_force;
  result_.tip_force_N = surface_axial + crack.bevel_N;
  result_.cutting_force_N = cut - crack.bevel_N;
  result_.friction_force_N = friction_total;
  result_.total_force_N = surface_axial + cut + friction_total;
  resolve_force_vector(needle, surface_force * (surface_normal + surface_share * needle.direction));
  if (broke) add_shaft_forces_to_events(needle.time_s);
  // 6. Meshes laid at a new contact point get their nodes projected onto the
  // surface a few per tick.
  refine_pending_layouts();

  if (!std::isfinite(result_.total_force_N) || !result_.force_on_needle_N.allFinite())
    throw std::runtime_error("PunctureSimulator::tick: the needle force became non-finite at t = " +
                             std::to_string(needle.time_s) + " s");
  return result_;
}

}  // namespace puncture
