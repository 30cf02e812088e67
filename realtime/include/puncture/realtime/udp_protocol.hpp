// udp_protocol.hpp: the network device protocol (version 1), so a bridge
// process for a real haptic device (OpenHaptics, Force Dimension, Haply) can
// drive the app without the app linking the vendor's SDK.
//
// Transport: UDP datagrams, one message per datagram, at the haptic rate
// (1 kHz). The bridge sends POSE messages to the app's port; after every
// haptic tick the app sends one FORCE message to the address the newest valid
// POSE came from. All fields little-endian; doubles are IEEE-754 binary64.
// Positions in m, velocities in m/s, forces in N, times in s, scene frame
// (skin surface z = 0, tissue below; the bridge maps its workspace into it).
//
// POSE (bridge -> app), 112 bytes:
//   off size type     field
//     0    4 u32      magic 0x50434E50 (the bytes "PNCP")
//     4    2 u16      version = 1
//     6    2 u16      type = 1 (POSE)
//     8    4 u32      sequence: +1 per message (wraps); the app drops a message
//                     whose sequence is not newer than the last one it used
//    12    4 u32      flags: bit 0 velocity valid, bit 1 fresh tissue request
//    16    8 f64      device time (s, the bridge's clock; logged, not used)
//    24   24 f64[3]   tip position x, y, z
//    48   32 f64[4]   orientation quaternion w, x, y, z (needle frame -> scene
//                     frame; needle axis = q * (0, 0, -1))
//    80   24 f64[3]   tip velocity (used when flags bit 0 is set; otherwise the
//                     app differentiates the positions)
//   104    4 u32      buttons (bit mask, passed through)
//   108    4 u32      reserved, 0
// FORCE (app -> bridge), 72 bytes:
//     0    4 u32      magic 0x50434E50
//     4    2 u16      version = 1
//     6    2 u16      type = 2 (FORCE)
//     8    4 u32      tick sequence: the app's haptic tick (wraps)
//    12    4 u32      echo: sequence of the newest POSE used in this tick
//    16    4 u32      flags: bit 0 magnitude clamped, bit 1 rate clamped,
//                     bit 2 no pose (stale: no valid POSE for `timeout`),
//                     bit 3 stability warning, bit 4 held (fresh tissue pending)
//    20    4 u32      layer states, 2 bits per layer (layer k in bits 2k..2k+1):
//                     0 untouched, 1 pressed, 2 punctured
//    24    8 f64      model time (s)
//    32   24 f64[3]   force to render on the device (after the stability guard): the
//                     tissue's whole force on the needle, along it and, for a needle
//                     at an angle to the surface, across it (TickResult::force_on_needle_N)
//    56    8 f64      tissue force along the needle (> 0 resisting insertion, unguarded)
//    64    8 f64      tip depth below the skin surface (m)
// A receiver ignores datagrams of another size, magic, version or type.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>

namespace puncture::realtime::udp {

constexpr std::uint32_t kMagic = 0x50434E50u;
constexpr std::uint16_t kVersion = 1;
constexpr std::uint16_t kTypePose = 1;
constexpr std::uint16_t kTypeForce = 2;
constexpr std::size_t kPoseSize = 112;
constexpr std::size_t kForceSize = 72;
constexpr std::uint32_t kPoseVelocityValid = 1u << 0;
constexpr std::uint32_t kPoseFreshTissue = 1u << 1;

struct PoseMessage {
  std::uint32_t sequence = 0;
  std::uint32_t flags = 0;
  double device_time_s = 0.0;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();
  std::uint32_t buttons = 0;
};

struct ForceMessage {
  std::uint32_t tick_sequence = 0;
  std::uint32_t echo_sequence = 0;
  std::uint32_t flags = 0;
  std::uint32_t layer_states = 0;
  double model_time_s = 0.0;
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();
  double tissue_force_N = 0.0;
  double depth_m = 0.0;
};

void encode(const PoseMessage& m, std::uint8_t (&out)[kPoseSize]) noexcept;
void encode(const ForceMessage& m, std::uint8_t (&out)[kForceSize]) noexcept;
/// False for a wrong size, magic, version, type or a non-finite number.
bool decode(const std::uint8_t* data, std::size_t size, PoseMessage& out) noexcept;
bool decode(const std::uint8_t* data, std::size_t size, ForceMessage& out) noexcept;

/// True if sequence a is newer than b (serial-number arithmetic, RFC 1982).
inline bool sequence_newer(std::uint32_t a, std::uint32_t b) noexcept {
  return static_cast<std::int32_t>(a - b) > 0;
}

}  // namespace puncture::realtime::udp
