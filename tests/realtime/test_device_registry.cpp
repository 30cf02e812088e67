// The device registry: each built-in device is made by its name with the
// setup it needs; an unknown name or a missing setup is an error naming what
// is wrong; a registered device is then made by its name like the others.
#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

#include "puncture/realtime/device_registry.hpp"
#include "puncture/realtime/pointer_device.hpp"
#include "puncture/realtime/scripted_device.hpp"
#include "realtime_test_scenes.hpp"

namespace puncture::realtime {
namespace {

DeviceSetup setup_for(const Scene& scene) {
  DeviceSetup s;
  s.scene = &scene;
  s.tick_period_s = 1e-3;
  s.udp.port = 0;  // any free port
  return s;
}

TEST(DeviceRegistry, BuiltInDevicesAreMadeByName) {
  const Scene scene = testing::short_insertion_scene();
  const DeviceSetup setup = setup_for(scene);
  const std::vector<std::string> names = device_names();
  for (const char* n : {"mouse", "scripted", "replay", "udp"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  EXPECT_NE(dynamic_cast<PointerDevice*>(make_device("mouse", setup).get()), nullptr);
  EXPECT_NE(dynamic_cast<ScriptedDevice*>(make_device("scripted", setup).get()), nullptr);
  EXPECT_NE(dynamic_cast<UdpDevice*>(make_device("udp", setup).get()), nullptr);
  // The scripted device drives the scene's insertion: it moves the tip down.
  std::unique_ptr<HapticDevice> scripted = make_device("scripted", setup);
  scripted->start();
  DeviceInput first, later;
  scripted->read(0, 0.0, first);
  for (int i = 1; i <= 50; ++i) scripted->read(i, i * 1e-3, later);  // 50 ms into the insertion
  ASSERT_EQ(first.status, DeviceInput::Status::Pose);
  ASSERT_EQ(later.status, DeviceInput::Status::Pose);
  EXPECT_LT(later.pose.position_m.z(), first.pose.position_m.z());
}

TEST(DeviceRegistry, UnknownNamesAndMissingSetupsAreNamedErrors) {
  const Scene scene = testing::short_insertion_scene();
  try {
    make_device("phantom-omni", setup_for(scene));
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown device 'phantom-omni'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("scripted"), std::string::npos) << "lists the known devices: " << e.what();
  }
  try {
    make_device("replay", setup_for(scene));
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("needs a recording"), std::string::npos) << e.what();
  }
  EXPECT_THROW(make_device("scripted", DeviceSetup{}), std::invalid_argument);  // no scene
}

TEST(DeviceRegistry, ARegisteredDeviceIsMadeByItsName) {
  const Scene scene = testing::short_insertion_scene();
  int made = 0;
  register_device({"test-stage", "a stage at a fixed depth (test)", [&made](const DeviceSetup& s) {
                     ++made;
                     return std::make_unique<ScriptedDevice>(s.scene->insertion, s.tick_period_s, false);
                   }});
  const std::vector<std::string> names = device_names();
  EXPECT_EQ(names.back(), "test-stage");
  EXPECT_NE(make_device("test-stage", setup_for(scene)), nullptr);
  EXPECT_EQ(made, 1);
  EXPECT_THROW(register_device({"", "nameless", nullptr}), std::invalid_argument);
}

}  // namespace
}  // namespace puncture::realtime
