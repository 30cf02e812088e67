// udp_device.hpp: the network device (protocol in udp_protocol.hpp).
//
// Binds a UDP socket (non-blocking) to `bind_address:port`. Every haptic tick
// read() drains the socket and keeps the newest valid POSE (by sequence
// number; older, duplicate and malformed datagrams are counted and dropped);
// write() sends one FORCE message to the address that POSE came from. Before
// the first POSE, or when none arrived for `timeout_s`, the device reports
// NoPose: the loop holds the needle where it was and the FORCE messages carry
// the no-pose flag. Without a velocity in the POSE the loop differentiates the
// positions (NeedleFromPose, low-pass at the app's --velocity-cutoff).
// A POSE with the fresh-tissue flag asks for a fresh tissue (served once).
// No allocation and no blocking call in read()/write() (recvfrom/sendto with
// MSG_DONTWAIT).
#pragma once

#include <cstdint>
#include <string>

#include "puncture/realtime/device.hpp"
#include "puncture/realtime/udp_protocol.hpp"

namespace puncture::realtime {

struct UdpDeviceOptions {
  std::string bind_address = "127.0.0.1";  ///< "0.0.0.0" to accept bridges on other hosts
  std::uint16_t port = 47011;               ///< 0: any free port (see port())
  double timeout_s = 0.1;                   ///< no valid POSE for this long: NoPose
};

struct UdpDeviceCounters {
  std::int64_t received = 0;     ///< valid POSE messages used or superseded
  std::int64_t malformed = 0;    ///< wrong size, magic, version, type or non-finite values
  std::int64_t stale = 0;        ///< sequence not newer than the last one used (duplicate / reordered)
  std::int64_t lost = 0;         ///< gaps in the sequence numbers
  std::int64_t sent = 0;         ///< FORCE messages sent
  std::int64_t send_errors = 0;  ///< sendto failures (e.g. bridge gone)
  std::int64_t no_pose_ticks = 0;
};

class UdpDevice final : public HapticDevice {
 public:
  /// Opens and binds the socket; throws std::runtime_error naming the address on failure.
  explicit UdpDevice(UdpDeviceOptions options);
  ~UdpDevice() override;
  UdpDevice(const UdpDevice&) = delete;
  UdpDevice& operator=(const UdpDevice&) = delete;

  std::string name() const override { return "udp"; }
  std::uint16_t port() const { return port_; }
  void read(std::int64_t tick, double time_s, DeviceInput& input) noexcept override;
  void fresh_tissue_result(bool done) noexcept override;
  void write(const ForceOutput& output) noexcept override;

  /// Copy of the counters; read only after the haptic loop stopped.
  UdpDeviceCounters counters() const;

 private:
  int fd_ = -1;
  std::uint16_t port_ = 0;
  double timeout_s_;
  bool have_pose_ = false;
  bool have_peer_ = false;
  alignas(8) unsigned char peer_[16] = {};  ///< sockaddr_in of the newest valid POSE
  udp::PoseMessage pose_;
  double pose_time_s_ = 0.0;  ///< model time when the newest POSE arrived
  bool fresh_pending_ = false;
  std::uint32_t fresh_sequence_ = 0;
  bool fresh_seen_ = false;
  UdpDeviceCounters c_;
};

}  // namespace puncture::realtime
