#include "puncture/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace puncture {

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
  // Rays searching for a contact start this far above the tip: above every surface.
  contact_search_height_m_ = std::max(0.0, scene.insertion.start_height_m) + scene.total_thickness_m() +
                             scene.sample.diameter_m;

  layers_.resize(scene.layers.size());
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const Layer& in = scene.layers[k];
    LayerModel& layer = layers_[k];
    if (!layer_surfaces[k]) throw std::invalid_argument("PunctureSimulator: layer surface " + std::to_string(k) + " is null");
    if (!(in.thickness_m > 0.0)) throw std::invalid_argument("layer \"" + in.name + "\": thickness must be positive");
    layer.name = in.name;
    layer.top_depth_m = scene.layer_top_depth_m(k);
    layer.thickness_m = in.thickness_m;
    layer.surface = std::move(layer_surfaces[k]);
    if (damping_on_) {
      if (!(in.damping_N_s_per_m2 >= 0.0)) throw std::invalid_argument("layer \"" + in.name + "\": damping must be >= 0");
      layer.damping_N_s_per_m2 = in.damping_N_s_per_m2;
    }
    if (scene.effects.surface_force) {
      double s = 0.0;
      SurfacePoint centre;
      const Eigen::Vector3d origin(0.0, 0.0, contact_search_height_m_);
      if (!layer.surface->intersect_ray(origin, -Eigen::Vector3d::UnitZ(), s, centre))
        throw std::invalid_argument("layer \"" + in.name + "\": the insertion axis misses its surface");
      layer.mesh.emplace(*layer.surface, centre, in.force_mesh, in.thickness_m, in.density_kg_per_m3, integration);
      if (scene.effects.resumption) {
        const Eigen::VectorXd masses = Eigen::VectorXd::Constant(layer.mesh->node_count(), layer.mesh->node_mass_kg());
        layer.resumption.emplace(layer.mesh->rest_positions(), masses, in.resumption_rate);
      }
    }
  }
  events_.reserve(layers_.size());
  result_.layers.resize(layers_.size());
}

const Eigen::Matrix3Xd& PunctureSimulator::node_rest_positions(std::size_t k) const {
  return layers_[k].mesh ? layers_[k].mesh->rest_positions() : empty_positions_;
}

const Eigen::Matrix3Xd& PunctureSimulator::node_positions(std::size_t k) const {
  const LayerModel& layer = layers_[k];
  if (!layer.mesh) return empty_positions_;
  if (layer.resumption && layer.resumption->active()) return layer.resumption->positions();
  return layer.mesh->positions();
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

bool PunctureSimulator::press_active_layer(const NeedleState& needle, double& surface_force_sum_N) {
  LayerModel& layer = layers_[active_];
  LayerTickResult& out = result_.layers[active_];
  const Eigen::Vector3d& tip = needle.tip_position_m;
  const Eigen::Vector3d& dir = needle.direction;

  if (!layer.contact_set) {
    double s = 0.0;
    SurfacePoint hit;
    const Eigen::Vector3d origin = tip - dir * (contact_search_height_m_ + std::abs(tip.z()));
    if (!layer.surface->intersect_ray(origin, dir, s, hit)) {
      out.state = layer.state = LayerState::Untouched;
      return false;  // the needle is not over this surface: try again next tick
    }
    layer.contact = hit;
    // The tip is already past the crossing: the contact starts where the tip is.
    if (hit.normal.dot(hit.position - tip) > 0.0) layer.contact.position = tip;
    layer.contact_set = true;
  }

  const double deflection = std::max(0.0, layer.contact.normal.dot(layer.contact.position - tip));
  out.contact_deflection_m = deflection;

  double surface_force = 0.0;
  bool broke = false;
  if (layer.mesh) {
    layer.mesh->advance(deflection);
    surface_force = std::max(0.0, layer.mesh->contact_reaction_N());
    out.deformed_rings = layer.mesh->deformed_rings();
    broke = layer.mesh->broken();
  } else {
    broke = deflection > 0.0;
  }
  layer.state = deflection > 0.0 ? LayerState::Pressed : LayerState::Untouched;

  if (!broke) {
    out.state = layer.state;
    out.surface_force_N = surface_force;
    surface_force_sum_N += surface_force;
    return false;
  }

  // Breakthrough: the surface force vanishes from this tick on.
  layer.state = LayerState::Punctured;
  out.state = LayerState::Punctured;
  out.surface_force_N = 0.0;
  PunctureEvent event;
  event.layer = static_cast<int>(active_);
  event.layer_name = layer.name;
  event.time_s = needle.time_s;
  event.depth_m = needle.depth_m();
  event.surface_force_N = surface_force;
  event.total_force_N = surface_force;  // tick() adds the damping of the layers above
  events_.push_back(event);  // capacity reserved at construction
  if (layer.resumption) layer.resumption->start(layer.mesh->positions());
  ++active_;
  return true;
}

const TickResult& PunctureSimulator::tick(const NeedleState& needle) {
  if (!needle.tip_position_m.allFinite() || !needle.direction.allFinite() ||
      !std::isfinite(needle.axial_velocity_m_per_s) || !std::isfinite(needle.time_s))
    throw std::invalid_argument("PunctureSimulator::tick: non-finite needle state");

  result_.time_s = needle.time_s;
  result_.depth_m = needle.depth_m();
  result_.velocity_m_per_s = needle.axial_velocity_m_per_s;
  for (LayerTickResult& r : result_.layers) r = LayerTickResult{};

  // 1. Resumption of the layers broken in earlier ticks.
  for (std::size_t k = 0; k < active_; ++k)
    if (layers_[k].resumption) layers_[k].resumption->step();

  // 2-4. The reachable layer; a breakthrough hands the needle to the next one.
  double surface_total = 0.0;
  const std::size_t events_before = events_.size();
  while (active_ < layers_.size() && press_active_layer(needle, surface_total)) {
  }

  // 5. Damping of the punctured layers.
  double damping_total = 0.0;
  for (std::size_t k = 0; k < active_; ++k) {
    LayerTickResult& out = result_.layers[k];
    out.state = LayerState::Punctured;
    if (!damping_on_) continue;
    const LayerModel& layer = layers_[k];
    out.shaft_length_m = shaft_length_in_layer_m(result_.depth_m, layer.top_depth_m, layer.thickness_m);
    out.damping_force_N =
        puncture_damping_force_N(layer.damping_N_s_per_m2, out.shaft_length_m, needle.axial_velocity_m_per_s);
    damping_total += out.damping_force_N;
  }
  result_.total_force_N = surface_total + damping_total;
  for (std::size_t e = events_before; e < events_.size(); ++e)
    for (int k = 0; k < events_[e].layer; ++k) events_[e].total_force_N += result_.layers[k].damping_force_N;

  if (!std::isfinite(result_.total_force_N))
    throw std::runtime_error("PunctureSimulator::tick: the needle force became non-finite at t = " +
                             std::to_string(needle.time_s) + " s");
  return result_;
}

}  // namespace puncture
