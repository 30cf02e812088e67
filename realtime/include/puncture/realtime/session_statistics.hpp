// session_statistics.hpp: the sections of a real-time session's statistics
// (puncture-app --stats) beyond the timing quantiles of session_report.hpp.
//   In:  what a finished session measured and counted: the HapticLoop after
//        join(), the view's ViewStatistics, the stability check
//        (force_guard.hpp), ModelSupplier::finish()'s puncture events, a
//        replay's comparison counters, the UDP device's counters.
//   Out: one JSON object per section; units in the key names (s, Hz, us, ms,
//        N, N/s, N/m, N s/m; puncture depths in mm).
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "puncture/realtime/force_guard.hpp"
#include "puncture/realtime/haptic_loop.hpp"
#include "puncture/realtime/session_report.hpp"
#include "puncture/realtime/udp_device.hpp"

namespace puncture::realtime {

/// "haptic": haptic_statistics_json() plus the thread's scheduling, the spin
/// margin (us) and the loop's tick counts (model, held, no pose, fresh tissues).
nlohmann::json haptic_session_json(const HapticLoop& loop, double target_rate_Hz, double spin_margin_us);

/// "view": view_statistics_json() plus the tick samples the view's ring
/// dropped and the snapshots the haptic thread published.
nlohmann::json view_session_json(const ViewStatistics& view, double target_fps, const HapticLoopCounters& counters);

/// "guard": the scene's force limits and how often the guard clamped.
nlohmann::json guard_json(const Haptics& haptics, const HapticLoopCounters& counters);

/// "stability": the Colgate-Brown passivity check, its inputs and warnings.
nlohmann::json stability_json(const Haptics& haptics, double tick_period_s, const RenderedImpedance& impedance,
                              const StabilityAssessment& stability);

/// "puncture_events": every puncture, per tissue (model) in order, with its
/// layer's name from `scene`, time (s), depth (mm) and total force (N).
nlohmann::json puncture_events_json(const Scene& scene, const std::vector<std::vector<PunctureEvent>>& events);

/// True when a replay compared every one of the `recorded_ticks` and none differed.
bool replay_identical(const HapticLoopCounters& counters, std::size_t recorded_ticks);

/// "replay": the recording's file, its ticks, the ticks compared and those that differed.
nlohmann::json replay_json(const std::string& file, std::size_t recorded_ticks, const HapticLoopCounters& counters);

/// "udp": the device's port and datagram counters (read after the loop stopped).
nlohmann::json udp_json(const UdpDevice& udp);

}  // namespace puncture::realtime
