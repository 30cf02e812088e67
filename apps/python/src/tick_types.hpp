// tick_types.hpp: what Simulator.tick returns to Python: one haptic tick's
// result (TickResult, copied), the needle direction (for the force vector)
// and the puncture events of this tick. Lengths stay in metres here; the
// bindings (tick_binding.cpp) give mm where the name says so.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "puncture/puncture_force.hpp"
#include "puncture/simulator.hpp"

namespace puncture::python {

/// A PunctureEvent with its own copy of the layer name (the event's view
/// points into the simulator, which Python may outlive).
struct EventRecord {
  PunctureEvent event;
  std::string layer_name;

  explicit EventRecord(const PunctureEvent& e) : event(e), layer_name(e.layer_name) { event.layer_name = {}; }
};

struct TickRecord {
  TickResult result;
  Eigen::Vector3d direction = -Eigen::Vector3d::UnitZ();  ///< needle direction (unit, insertion)
  std::vector<EventRecord> events;                        ///< punctures of this tick
  std::shared_ptr<const std::vector<std::string>> layer_names;  ///< shared with the simulator
};

}  // namespace puncture::python
