// device_registry.cpp: see device_registry.hpp.
#include "puncture/realtime/device_registry.hpp"

#include <mutex>
#include <stdexcept>

#include "puncture/realtime/pointer_device.hpp"
#include "puncture/realtime/replay.hpp"
#include "puncture/realtime/scripted_device.hpp"

namespace puncture::realtime {

namespace {

const Scene& scene_of(const DeviceSetup& setup, const char* device) {
  if (!setup.scene) throw std::invalid_argument(std::string("device '") + device + "' needs a scene");
  return *setup.scene;
}

std::vector<DeviceEntry> built_in_devices() {
  return {
      {"mouse", "the mouse and keyboard of the view (wheel or Up/Down: depth)",
       [](const DeviceSetup& s) {
         return std::make_unique<PointerDevice>(scene_of(s, "mouse"), s.tick_period_s);
       }},
      {"scripted", "the scene's scripted insertion (insertion, dwell, withdrawal), repeated",
       [](const DeviceSetup& s) {
         return std::make_unique<ScriptedDevice>(scene_of(s, "scripted").insertion, s.tick_period_s, s.repeat);
       }},
      {"replay", "a recorded session, tick by tick (needs the recording)",
       [](const DeviceSetup& s) -> std::unique_ptr<HapticDevice> {
         if (!s.recording) throw std::invalid_argument("device 'replay' needs a recording (--recording FILE)");
         return std::make_unique<ReplayDevice>(*s.recording);
       }},
      {"udp", "a haptic device bridge: poses in, forces out over UDP (apps/README.md)",
       [](const DeviceSetup& s) { return std::make_unique<UdpDevice>(s.udp); }},
  };
}

struct Registry {
  std::mutex mutex;
  std::vector<DeviceEntry> entries = built_in_devices();
};

Registry& registry() {
  static Registry r;
  return r;
}

}  // namespace

std::vector<DeviceEntry> registered_devices() {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  return r.entries;
}

std::vector<std::string> device_names() {
  std::vector<std::string> names;
  for (const DeviceEntry& e : registered_devices()) names.push_back(e.name);
  return names;
}

void register_device(DeviceEntry entry) {
  if (entry.name.empty() || !entry.make) throw std::invalid_argument("register_device: a device needs a name and a factory");
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  for (DeviceEntry& e : r.entries)
    if (e.name == entry.name) {
      e = std::move(entry);
      return;
    }
  r.entries.push_back(std::move(entry));
}

std::unique_ptr<HapticDevice> make_device(const std::string& name, const DeviceSetup& setup) {
  for (const DeviceEntry& e : registered_devices())
    if (e.name == name) return e.make(setup);
  std::string known;
  for (const std::string& n : device_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown device '" + name + "' (known: " + known + ")");
}

}  // namespace puncture::realtime
