#include "puncture/realtime/session_statistics.hpp"

namespace puncture::realtime {

nlohmann::json haptic_session_json(const HapticLoop& loop, double target_rate_Hz, double spin_margin_us) {
  const HapticLoopCounters& c = loop.counters();
  nlohmann::json j = haptic_statistics_json(loop.statistics(), target_rate_Hz);
  j["scheduling"] = loop.scheduling();
  j["spin_margin_us"] = spin_margin_us;
  j["model_ticks"] = c.model_ticks;
  j["held_ticks"] = c.held_ticks;
  j["no_pose_ticks"] = c.no_pose_ticks;
  j["fresh_tissues"] = c.fresh_tissues;
  return j;
}

nlohmann::json view_session_json(const ViewStatistics& view, double target_fps, const HapticLoopCounters& c) {
  nlohmann::json j = view_statistics_json(view, target_fps);
  j["samples_dropped"] = c.samples_dropped;
  j["snapshots"] = c.snapshots;
  return j;
}

nlohmann::json guard_json(const Haptics& haptics, const HapticLoopCounters& c) {
  return {{"max_force_N", haptics.max_force_N},
          {"max_force_rate_N_per_s", haptics.max_force_rate_N_per_s},
          {"magnitude_clamped_ticks", c.magnitude_clamped},
          {"rate_clamped_ticks", c.rate_clamped},
          {"max_tissue_force_N", c.max_tissue_force_N},
          {"max_force_sent_N", c.max_sent_force_N}};
}

nlohmann::json stability_json(const Haptics& haptics, double tick_period_s, const RenderedImpedance& impedance,
                              const StabilityAssessment& stability) {
  return {{"criterion", "Colgate-Brown passivity: K T / 2 + B <= b"},
          {"stiffness_K_N_per_m", impedance.stiffness_N_per_m},
          {"stiffness_layer", impedance.stiffness_layer},
          {"damping_B_N_s_per_m", impedance.damping_N_s_per_m},
          {"device_damping_b_N_s_per_m", haptics.device_damping_N_s_per_m},
          {"tick_period_s", tick_period_s},
          {"passivity_demand_N_s_per_m", stability.passivity_demand_N_s_per_m},
          {"max_passive_stiffness_N_per_m", stability.max_passive_stiffness_N_per_m},
          {"passive", stability.passive},
          {"within_device_stiffness", stability.within_device_stiffness},
          {"peak_force_scripted_N", impedance.peak_force_N},
          {"warnings", stability.warnings}};
}

nlohmann::json puncture_events_json(const Scene& scene, const std::vector<std::vector<PunctureEvent>>& events) {
  nlohmann::json ev = nlohmann::json::array();
  for (std::size_t g = 0; g < events.size(); ++g)
    for (const PunctureEvent& e : events[g])
      ev.push_back({{"tissue", g},
                    {"layer", scene.layers.at(static_cast<std::size_t>(e.layer)).name},
                    {"time_s", e.time_s},
                    {"depth_mm", e.depth_m * 1e3},
                    {"total_force_N", e.total_force_N}});
  return ev;
}

bool replay_identical(const HapticLoopCounters& c, std::size_t recorded_ticks) {
  return c.replay_mismatches == 0 && c.replay_compared == static_cast<std::int64_t>(recorded_ticks);
}

nlohmann::json replay_json(const std::string& file, std::size_t recorded_ticks, const HapticLoopCounters& c) {
  return {{"file", file},
          {"recorded_ticks", recorded_ticks},
          {"compared_ticks", c.replay_compared},
          {"mismatched_ticks", c.replay_mismatches},
          {"first_mismatch_tick", c.first_mismatch_tick},
          {"bit_for_bit", replay_identical(c, recorded_ticks)}};
}

nlohmann::json udp_json(const UdpDevice& udp) {
  const UdpDeviceCounters u = udp.counters();
  return {{"port", udp.port()},     {"received", u.received}, {"malformed", u.malformed},
          {"stale", u.stale},       {"lost", u.lost},         {"sent", u.sent},
          {"send_errors", u.send_errors}};
}

}  // namespace puncture::realtime
