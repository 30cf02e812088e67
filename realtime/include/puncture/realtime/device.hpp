// device.hpp: the one interface every needle device implements (pose in,
// force out), and the conversion of a device pose into the model's needle.
//
// Frames and units: positions in m and forces in N in the scene frame
// (scene.hpp: skin surface z = 0, tissue below, needle entering along -z).
// The pose's orientation rotates the needle frame into the scene frame; the
// needle axis (shaft to tip, the insertion direction) is orientation * (0, 0, -1),
// so the identity is a needle pointing straight down.
//
// Per haptic tick the loop calls read() once, then write() once with the force
// to render (after the stability guard). Both run in the haptic thread: they
// must not block, lock or allocate.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>

#include "puncture/needle.hpp"
#include "puncture/simulator.hpp"

namespace puncture::realtime {

struct DevicePose {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  ///< needle tip
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();  ///< tip velocity, used when has_velocity
  bool has_velocity = false;
  std::uint32_t buttons = 0;
};

/// Outputs of one model tick that a replay compares bit for bit.
struct TickOutputs {
  double tissue_force_N = 0.0;  ///< TickResult::total_force_N (axial, > 0 resisting insertion)
  Eigen::Vector3d force_raw_N = Eigen::Vector3d::Zero();   ///< force on the needle before the guard
  Eigen::Vector3d force_sent_N = Eigen::Vector3d::Zero();  ///< after the guard: what the device renders
  std::uint32_t layer_states = 0;  ///< 2 bits per layer (layer k in bits 2k, 2k+1): 0 untouched, 1 pressed, 2 punctured
};

struct DeviceInput {
  enum class Status { Pose, NoPose, End };
  Status status = Status::NoPose;  ///< NoPose: hold the needle where it was (velocity 0); End: stop the session
  DevicePose pose;
  /// The device asks for a fresh (unpunctured) tissue before this tick. The
  /// loop answers with fresh_tissue_result(); if no fresh model is ready the
  /// tick is held (no model tick) and the device asks again next tick.
  bool fresh_tissue = false;
  /// Replay: the exact needle state to feed the model, and the outputs to expect.
  bool has_exact_needle = false;
  NeedleState needle;
  bool has_expected = false;
  TickOutputs expected;
};

/// What the loop sends back every tick.
struct ForceOutput {
  std::int64_t tick = 0;
  double time_s = 0.0;
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();  ///< guarded force to render on the device
  double tissue_force_N = 0.0;
  double depth_m = 0.0;
  std::uint32_t layer_states = 0;
  std::uint32_t flags = 0;  ///< ForceOutputFlags
};

enum ForceOutputFlags : std::uint32_t {
  kOutMagnitudeClamped = 1u << 0,
  kOutRateClamped = 1u << 1,
  kOutNoPose = 1u << 2,            ///< the device gave no pose this tick (needle held)
  kOutStabilityWarning = 1u << 3,  ///< the scene failed the stability check at start
  kOutHeld = 1u << 4,              ///< waiting for a fresh tissue: no model tick
};

class HapticDevice {
 public:
  virtual ~HapticDevice() = default;
  virtual std::string name() const = 0;
  /// Called once in the haptic thread before the first tick.
  virtual void start() {}
  virtual void read(std::int64_t tick, double time_s, DeviceInput& input) noexcept = 0;
  virtual void fresh_tissue_result(bool done) noexcept { (void)done; }
  virtual void write(const ForceOutput& output) noexcept = 0;
};

/// Device pose -> needle state of the model.
///   direction = orientation * (0, 0, -1) (normalised);
///   axial velocity = direction . velocity when the device reports velocity,
///   else the backward difference direction . (p_n - p_{n-1}) / T passed through a
///   first-order low-pass filter with cut-off `velocity_cutoff_Hz` (0: unfiltered);
///   zero on the first tick after reset().
class NeedleFromPose {
 public:
  NeedleFromPose(double tick_period_s, double velocity_cutoff_Hz);
  NeedleState convert(const DevicePose& pose, double time_s) noexcept;
  void reset() noexcept { has_previous_ = false; filtered_velocity_ = 0.0; }

 private:
  double dt_, alpha_;
  bool has_previous_ = false;
  Eigen::Vector3d previous_ = Eigen::Vector3d::Zero();
  double filtered_velocity_ = 0.0;
};

std::uint32_t pack_layer_states(const TickResult& result) noexcept;
LayerState unpack_layer_state(std::uint32_t packed, std::size_t layer) noexcept;

}  // namespace puncture::realtime
