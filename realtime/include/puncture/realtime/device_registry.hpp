// device_registry.hpp: the needle devices by name, and how each is built.
//
// The app (--device NAME) and scripts build a device from its name and a
// DeviceSetup; a new device registers a factory once (register_device) and
// is then available under its name everywhere. Built in: "mouse"
// (PointerDevice), "scripted" (ScriptedDevice: the scene's insertion),
// "replay" (ReplayDevice: needs setup.recording) and "udp" (UdpDevice: a
// haptic-device bridge over UDP, setup.udp). realtime/README.md, "Adding a
// device", shows the steps.
//
// In:  a name, a DeviceSetup (the scene, the haptic tick period in s, the
//      device-specific options).
// Out: the device (owned by the caller); std::invalid_argument naming the
//      known devices for an unknown name or a setup the device cannot use.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "puncture/realtime/device.hpp"
#include "puncture/realtime/udp_device.hpp"
#include "puncture/scene.hpp"

namespace puncture::realtime {

struct Recording;

/// What a device may be built from. The scene and the recording must outlive the device.
struct DeviceSetup {
  const Scene* scene = nullptr;
  double tick_period_s = 1e-3;
  bool repeat = true;                   ///< scripted: repeat the insertion cycle
  const Recording* recording = nullptr;  ///< replay: the recorded session
  UdpDeviceOptions udp;                  ///< udp: address, port, timeout
};

using DeviceFactory = std::function<std::unique_ptr<HapticDevice>(const DeviceSetup&)>;

struct DeviceEntry {
  std::string name;         ///< as given to --device
  std::string description;  ///< one line for --help
  DeviceFactory make;
};

/// Every registered device, the built-in ones first, in registration order.
std::vector<DeviceEntry> registered_devices();
/// Their names, in the same order.
std::vector<std::string> device_names();
/// Registers a device under entry.name (replacing one of that name). Not for
/// the haptic thread; call before devices are made.
void register_device(DeviceEntry entry);
/// Builds the device called `name`.
std::unique_ptr<HapticDevice> make_device(const std::string& name, const DeviceSetup& setup);

}  // namespace puncture::realtime
