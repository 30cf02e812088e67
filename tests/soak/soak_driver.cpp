// soak_driver.cpp: see soak_driver.hpp.
#include "soak_driver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "../core/allocation_counter.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/needle.hpp"
#include "puncture/scene_io.hpp"

namespace puncture::soak {

namespace {

constexpr double kMm = 1e-3;
const char* const kIntegrators[3] = {"quasi_static", "explicit", "implicit"};

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The needle of one episode: piecewise-linear random motion along its
/// inclined axis (z_ is the tip's height, the needle's own speed is the
/// vertical one / cos a).
class RandomTrajectory {
 public:
  RandomTrajectory(std::mt19937_64& rng, const SoakOptions& o, double top_m, double bottom_m, double dt_s)
      : rng_(rng), o_(o), top_m_(top_m), bottom_m_(bottom_m), dt_s_(dt_s) {
    std::uniform_real_distribution<double> offset(-o.max_lateral_offset_mm * kMm, o.max_lateral_offset_mm * kMm);
    x_ = offset(rng_), y_ = offset(rng_);
    std::uniform_real_distribution<double> angle(0.0, o.max_angle_deg * M_PI / 180.0), azimuth(0.0, 2.0 * M_PI);
    angle_rad_ = angle(rng_);
    const double phi = azimuth(rng_);
    direction_ = Eigen::Vector3d(std::sin(angle_rad_) * std::cos(phi), std::sin(angle_rad_) * std::sin(phi),
                                 -std::cos(angle_rad_));
    z_ = top_m_;
    next_segment();
  }

  double angle_deg() const { return angle_rad_ * 180.0 / M_PI; }

  /// Advances one tick; returns the needle state at the end of it.
  NeedleState step(SoakReport& report) {
    NeedleState s;
    s.time_s = (++tick_) * dt_s_;
    double v = 0.0;  // along -z (inserting)
    if (dwell_left_ > 0) {
      --dwell_left_;
      ++report.dwell_ticks;
      if (dwell_left_ == 0) next_segment();
    } else {
      const double dz = target_z_ - z_;
      const double step = speed_ * dt_s_;
      if (std::abs(dz) <= step) {
        z_ = target_z_;
        v = -dz / dt_s_;
        std::uniform_real_distribution<double> u(0.0, 1.0);
        if (u(rng_) < o_.dwell_probability)
          dwell_left_ = 1 + static_cast<long long>(u(rng_) * o_.max_dwell_s / dt_s_);
        else
          next_segment();
      } else {
        z_ += dz > 0 ? step : -step;
        v = dz > 0 ? -speed_ : speed_;
      }
    }
    if (v != 0.0) {
      const int dir = v > 0 ? 1 : -1;
      if (last_dir_ != 0 && dir != last_dir_) ++report.reversals;
      last_dir_ = dir;
    }
    // On the inclined line through the entry point (x_, y_, 0), at height z_.
    const double path = z_ / direction_.z();
    s.tip_position_m = Eigen::Vector3d(x_ + path * direction_.x(), y_ + path * direction_.y(), z_);
    s.direction = direction_;
    s.axial_velocity_m_per_s = v / -direction_.z();
    return s;
  }

  double speed_m_per_s() const { return speed_; }

 private:
  void next_segment() {
    std::uniform_real_distribution<double> depth(bottom_m_, top_m_);
    std::uniform_real_distribution<double> log_speed(std::log(o_.min_speed_mm_per_s), std::log(o_.max_speed_mm_per_s));
    target_z_ = depth(rng_);
    speed_ = std::exp(log_speed(rng_)) * kMm;
  }

  std::mt19937_64& rng_;
  const SoakOptions& o_;
  double top_m_, bottom_m_, dt_s_;
  double x_ = 0, y_ = 0, z_ = 0, target_z_ = 0, speed_ = 0, angle_rad_ = 0;
  Eigen::Vector3d direction_ = -Eigen::Vector3d::UnitZ();
  long long dwell_left_ = 0;
  long long tick_ = 0;
  int last_dir_ = 0;
};

/// With the layer_interaction effect on, scene_io refuses the ring rule below
/// the first layer (the deflection carried from the layer above would break
/// it at first touch). Each such layer breaks instead at a critical force:
/// the surface force at which the ring rule broke it in a scripted insertion
/// of the same scene without layer_interaction (for the default scene about
/// 1.3 N for fat and 2.6 N for muscle, results/default_run/).
void replace_ring_rule_below_first_layer(nlohmann::json& scene_json, const std::string& path) {
  const nlohmann::json& effects = scene_json["effects"];
  if (std::find(effects.begin(), effects.end(), "layer_interaction") == effects.end()) return;
  std::vector<std::size_t> rings;
  for (std::size_t k = 1; k < scene_json["layers"].size(); ++k) {
    const nlohmann::json& l = scene_json["layers"][k];
    const bool ring_rule = !l.contains("force_law") || !l["force_law"].contains("breakthrough") ||
                           l["force_law"]["breakthrough"].value("criterion", std::string("rings")) == "rings";
    if (ring_rule) rings.push_back(k);
  }
  if (rings.empty()) return;
  nlohmann::json without = scene_json;
  nlohmann::json kept = nlohmann::json::array();
  for (const auto& e : effects)
    if (e != "layer_interaction") kept.push_back(e);
  without["effects"] = kept;
  const Scene scene = parse_scene(without.dump(), path + " (soak: ring-rule breakthrough forces)");
  RealtimeModel model = build_realtime_model(scene);
  const ScriptedTrajectory insertion(scene.insertion);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  for (int i = 0; i * dt <= insertion.duration(); ++i) model.simulator->tick(insertion.sample(i * dt));
  std::vector<double> force_N(scene.layers.size(), 0.0);
  for (const PunctureEvent& e : model.simulator->puncture_events())
    force_N[static_cast<std::size_t>(e.layer)] = e.surface_force_N;
  for (std::size_t k : rings) {
    if (!(force_N[k] > 0.0))
      throw std::runtime_error(path + ": /layers/" + std::to_string(k) +
                               "/force_law/breakthrough: the soak turns layer_interaction on, which needs "
                               "critical_force or critical_energy below the first layer, and the scene's scripted "
                               "insertion does not break this layer with the ring rule to take its force from: "
                               "give the layer a critical_force criterion");
    scene_json["layers"][k]["force_law"]["breakthrough"] = {{"criterion", "critical_force"},
                                                            {"critical_force_N", force_N[k]}};
  }
}

}  // namespace

SoakReport run_soak(const SoakOptions& o, const std::function<void(double)>& progress) {
  SoakReport report;
  report.allocation_count_from_sanitizer = test::allocation_count_from_sanitizer();
  const std::string path =
      o.scene_path.empty() ? std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json" : o.scene_path;
  nlohmann::json scene_json = nlohmann::json::parse(read_file(path));
  // Every effect on; coupled_surfaces and layer_interaction exclude each
  // other, so episodes take turns (three integrators each) with one of them.
  nlohmann::json effects = nlohmann::json::array();
  for (const std::string& e : known_effects())
    if (e != "coupled_surfaces") effects.push_back(e);
  scene_json["effects"] = effects;
  report.effects = known_effects();
  std::string base_text = scene_json.dump();
  for (const auto& edit : o.scene_edits) edit(base_text);
  scene_json = nlohmann::json::parse(base_text);
  replace_ring_rule_below_first_layer(scene_json, path);
  base_text = scene_json.dump();

  std::mt19937_64 rng(o.seed);
  std::uniform_int_distribution<long long> episode_length(o.min_episode_ticks, o.max_episode_ticks);
  std::vector<double> tick_us;
  tick_us.reserve(200000);
  const auto t0 = std::chrono::steady_clock::now();
  double next_progress = 0.05;

  while (report.ticks < o.ticks) {
    const int integrator = static_cast<int>(report.episodes % 3);
    nlohmann::json j = nlohmann::json::parse(base_text);
    j["realtime"]["integrator"] = kIntegrators[integrator];
    if ((report.episodes / 3) % 2 == 1)
      for (auto& e : j["effects"])
        if (e == "layer_interaction") e = "coupled_surfaces";
    const Scene scene = parse_scene(j.dump(), path + " (soak episode " + std::to_string(report.episodes) + ")");
    RealtimeModel model = build_realtime_model(scene);
    PunctureSimulator& sim = *model.simulator;
    const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
    // From the start height down to 2 mm above the sample base.
    RandomTrajectory needle(rng, o, scene.insertion.start_height_m, -(scene.total_thickness_m() - 2e-3), dt);
    report.max_angle_deg = std::max(report.max_angle_deg, needle.angle_deg());
    const std::size_t n_layers = sim.layer_count();
    std::vector<double> force_prev(n_layers, 0.0), deflection_prev(n_layers, 0.0);
    double work = 0.0;
    const long long length = std::min(episode_length(rng), o.ticks - report.ticks);
    for (long long i = 0; i < length; ++i) {
      const NeedleState state = needle.step(report);
      report.max_speed_mm_per_s = std::max(report.max_speed_mm_per_s, std::abs(state.axial_velocity_m_per_s) / kMm);
      const bool sample = (report.ticks % 50) == 0;
      const auto ts = sample ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
      test::start_counting_allocations();
      const TickResult* result = nullptr;
      try {
        result = &sim.tick(state);
      } catch (const std::exception& e) {
        test::stop_counting_allocations();
        ++report.non_finite;
        if (report.failures.size() < 10)
          report.failures.push_back("episode " + std::to_string(report.episodes) + " tick " + std::to_string(i) +
                                    ": tick() threw: " + e.what());
        ++report.ticks;
        break;  // the simulator's state is not defined after a throw: next episode
      }
      const long allocated = test::stop_counting_allocations();
      if (sample) tick_us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - ts).count());
      report.allocations += allocated;
      if (allocated > 0 && report.failures.size() < 10)
        report.failures.push_back("episode " + std::to_string(report.episodes) + " tick " + std::to_string(i) + ": " +
                                  std::to_string(allocated) + " heap allocations in tick()");
      ++report.ticks;
      ++report.ticks_per_integrator[integrator];

      bool finite = std::isfinite(result->total_force_N);
      for (std::size_t k = 0; k < n_layers; ++k) {
        const LayerTickResult& l = result->layers[k];
        finite = finite && std::isfinite(l.surface_force_N) && std::isfinite(l.damping_force_N) &&
                 std::isfinite(l.contact_deflection_m);
        if (l.state == LayerState::Pressed || deflection_prev[k] != 0.0) {
          work += 0.5 * (force_prev[k] + l.surface_force_N) * (l.contact_deflection_m - deflection_prev[k]);
        }
        force_prev[k] = l.state == LayerState::Punctured ? 0.0 : l.surface_force_N;
        deflection_prev[k] = l.state == LayerState::Punctured ? 0.0 : l.contact_deflection_m;
      }
      const double energy = sim.mesh_energy_J();
      finite = finite && std::isfinite(energy);
      if (!finite) {
        ++report.non_finite;
        if (report.failures.size() < 10)
          report.failures.push_back("episode " + std::to_string(report.episodes) + " tick " + std::to_string(i) +
                                    ": non-finite force or energy");
        break;
      }
      report.max_abs_force_N = std::max(report.max_abs_force_N, std::abs(result->total_force_N));
      report.max_energy_J = std::max(report.max_energy_J, energy);
      report.max_energy_to_work = std::max(report.max_energy_to_work, energy / (std::max(work, 0.0) + 1e-9));
      if (energy > work * (1.0 + o.energy_rel_tolerance) + 1e-9) {
        ++report.energy_violations;
        if (report.failures.size() < 10) {
          std::ostringstream m;
          m << "episode " << report.episodes << " (" << kIntegrators[integrator] << ") tick " << i
            << ": mesh energy " << energy << " J exceeds the work done on the meshes " << work << " J";
          report.failures.push_back(m.str());
        }
      }
    }
    // The drawn surfaces at the episode's end (coupled or shifted by the chain) are finite.
    for (std::size_t k = 0; k < n_layers; ++k)
      if (!sim.node_positions(k).allFinite() && report.failures.size() < 10)
        report.failures.push_back("episode " + std::to_string(report.episodes) + ": layer " + std::to_string(k) +
                                  "'s drawn surface is not finite");
    report.punctures += static_cast<long long>(sim.puncture_events().size());
    if (sim.active_layer() == n_layers) ++report.episodes_all_punctured;
    ++report.episodes;
    if (progress && static_cast<double>(report.ticks) >= next_progress * static_cast<double>(o.ticks)) {
      progress(static_cast<double>(report.ticks) / static_cast<double>(o.ticks));
      next_progress += 0.05;
    }
  }
  report.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!tick_us.empty()) {
    std::sort(tick_us.begin(), tick_us.end());
    report.median_tick_us = tick_us[tick_us.size() / 2];
    report.p99_tick_us = tick_us[std::min(tick_us.size() - 1, tick_us.size() * 99 / 100)];
  }
  return report;
}

}  // namespace puncture::soak
