#include "puncture/realtime/udp_device.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace puncture::realtime {

UdpDevice::UdpDevice(UdpDeviceOptions o) : timeout_s_(o.timeout_s) {
  static_assert(sizeof(peer_) >= sizeof(sockaddr_in), "peer storage");
  if (!(timeout_s_ > 0.0)) throw std::invalid_argument("udp device: timeout must be positive");
  const std::string where = o.bind_address + ":" + std::to_string(o.port);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(o.port);
  if (inet_pton(AF_INET, o.bind_address.c_str(), &addr.sin_addr) != 1)
    throw std::runtime_error("udp device: '" + o.bind_address + "' is not an IPv4 address");
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error("udp device: socket(): " + std::string(std::strerror(errno)));
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    throw std::runtime_error("udp device: cannot bind " + where + ": " + why);
  }
  socklen_t len = sizeof addr;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
}

UdpDevice::~UdpDevice() {
  if (fd_ >= 0) ::close(fd_);
}

void UdpDevice::read(std::int64_t, double time_s, DeviceInput& input) noexcept {
  alignas(8) std::uint8_t buffer[256];
  for (;;) {
    sockaddr_in from{};
    socklen_t from_len = sizeof from;
    const ssize_t n = ::recvfrom(fd_, buffer, sizeof buffer, MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&from), &from_len);
    if (n < 0) break;  // EAGAIN: drained (other errors: try again next tick)
    udp::PoseMessage m;
    if (!udp::decode(buffer, static_cast<std::size_t>(n), m)) {
      ++c_.malformed;
      continue;
    }
    if (have_pose_ && !udp::sequence_newer(m.sequence, pose_.sequence)) {
      ++c_.stale;
      continue;
    }
    if (have_pose_) c_.lost += static_cast<std::int64_t>(m.sequence - pose_.sequence) - 1;
    ++c_.received;
    pose_ = m;
    pose_time_s_ = time_s;
    have_pose_ = true;
    std::memcpy(peer_, &from, sizeof from);
    have_peer_ = true;
    // A fresh-tissue request is served once per run of flagged messages.
    const bool wants_fresh = (m.flags & udp::kPoseFreshTissue) != 0;
    if (wants_fresh && !fresh_seen_) fresh_pending_ = true;
    fresh_seen_ = wants_fresh;
  }

  input.has_exact_needle = false;
  input.has_expected = false;
  input.fresh_tissue = fresh_pending_;
  if (!have_pose_ || time_s - pose_time_s_ > timeout_s_) {
    input.status = DeviceInput::Status::NoPose;
    ++c_.no_pose_ticks;
    return;
  }
  input.status = DeviceInput::Status::Pose;
  input.pose.position_m = pose_.position_m;
  input.pose.orientation = pose_.orientation;
  input.pose.velocity_m_per_s = pose_.velocity_m_per_s;
  input.pose.has_velocity = (pose_.flags & udp::kPoseVelocityValid) != 0;
  input.pose.buttons = pose_.buttons;
}

void UdpDevice::fresh_tissue_result(bool done) noexcept {
  if (done) fresh_pending_ = false;
}

void UdpDevice::write(const ForceOutput& out) noexcept {
  if (!have_peer_) return;
  udp::ForceMessage m;
  m.tick_sequence = static_cast<std::uint32_t>(out.tick);
  m.echo_sequence = pose_.sequence;
  m.flags = out.flags;
  m.layer_states = out.layer_states;
  m.model_time_s = out.time_s;
  m.force_N = out.force_N;
  m.tissue_force_N = out.tissue_force_N;
  m.depth_m = out.depth_m;
  alignas(8) std::uint8_t buffer[udp::kForceSize];
  udp::encode(m, buffer);
  const ssize_t n = ::sendto(fd_, buffer, sizeof buffer, MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(peer_),
                             sizeof(sockaddr_in));
  if (n == static_cast<ssize_t>(sizeof buffer))
    ++c_.sent;
  else
    ++c_.send_errors;
}

UdpDeviceCounters UdpDevice::counters() const { return c_; }

}  // namespace puncture::realtime
