// The UDP device protocol: byte layout at the documented offsets (checked
// byte by byte, not through the decoder), round trips, malformed datagrams
// rejected, sequence numbers with wrap-around; and the device over loopback
// with a tiny sender: newest pose used, stale ones dropped, force replies
// echo the pose sequence, silence becomes "no pose".
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <thread>

#include "puncture/realtime/udp_device.hpp"
#include "puncture/realtime/udp_protocol.hpp"

namespace puncture::realtime {
namespace {

double f64_at(const std::uint8_t* p) {
  double d;
  std::memcpy(&d, p, 8);  // the test host is little-endian (x86-64)
  return d;
}
std::uint32_t u32_at(const std::uint8_t* p) { return p[0] | (p[1] << 8) | (p[2] << 16) | (std::uint32_t(p[3]) << 24); }

TEST(UdpProtocol, PoseLayoutMatchesTheDocumentation) {
  udp::PoseMessage m;
  m.sequence = 0x01020304u;
  m.flags = udp::kPoseVelocityValid;
  m.device_time_s = 12.5;
  m.position_m = Eigen::Vector3d(0.001, -0.002, 0.003);
  m.orientation = Eigen::Quaterniond(0.5, 0.5, -0.5, 0.5);
  m.velocity_m_per_s = Eigen::Vector3d(0.0, 0.0, -0.01);
  m.buttons = 5;
  std::uint8_t b[udp::kPoseSize];
  udp::encode(m, b);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(b), 4), "PNCP");
  EXPECT_EQ(b[4], 1);  // version 1, little-endian u16
  EXPECT_EQ(b[5], 0);
  EXPECT_EQ(b[6], 1);  // type POSE
  EXPECT_EQ(b[8], 0x04);  // sequence, least significant byte first
  EXPECT_EQ(b[11], 0x01);
  EXPECT_EQ(u32_at(b + 12), 1u);
  EXPECT_EQ(f64_at(b + 16), 12.5);
  EXPECT_EQ(f64_at(b + 24), 0.001);
  EXPECT_EQ(f64_at(b + 32), -0.002);
  EXPECT_EQ(f64_at(b + 40), 0.003);
  EXPECT_EQ(f64_at(b + 48), 0.5);   // w first
  EXPECT_EQ(f64_at(b + 64), -0.5);  // y
  EXPECT_EQ(f64_at(b + 96), -0.01);
  EXPECT_EQ(u32_at(b + 104), 5u);
  EXPECT_EQ(u32_at(b + 108), 0u);

  udp::PoseMessage back;
  ASSERT_TRUE(udp::decode(b, sizeof b, back));
  EXPECT_EQ(back.sequence, m.sequence);
  EXPECT_EQ(back.position_m, m.position_m);
  EXPECT_EQ(back.orientation.coeffs(), m.orientation.coeffs());
  EXPECT_EQ(back.velocity_m_per_s, m.velocity_m_per_s);
  EXPECT_EQ(back.buttons, 5u);
}

TEST(UdpProtocol, ForceLayoutMatchesTheDocumentation) {
  udp::ForceMessage m;
  m.tick_sequence = 77;
  m.echo_sequence = 76;
  m.flags = 3;
  m.layer_states = 0b100110;
  m.model_time_s = 1.25;
  m.force_N = Eigen::Vector3d(0.0, 0.1, 0.75);
  m.tissue_force_N = 0.75;
  m.depth_m = 0.004;
  std::uint8_t b[udp::kForceSize];
  udp::encode(m, b);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(b), 4), "PNCP");
  EXPECT_EQ(b[6], 2);  // type FORCE
  EXPECT_EQ(u32_at(b + 8), 77u);
  EXPECT_EQ(u32_at(b + 12), 76u);
  EXPECT_EQ(u32_at(b + 16), 3u);
  EXPECT_EQ(u32_at(b + 20), 0b100110u);
  EXPECT_EQ(f64_at(b + 24), 1.25);
  EXPECT_EQ(f64_at(b + 40), 0.1);
  EXPECT_EQ(f64_at(b + 48), 0.75);
  EXPECT_EQ(f64_at(b + 56), 0.75);
  EXPECT_EQ(f64_at(b + 64), 0.004);
  udp::ForceMessage back;
  ASSERT_TRUE(udp::decode(b, sizeof b, back));
  EXPECT_EQ(back.force_N, m.force_N);
  EXPECT_EQ(back.layer_states, m.layer_states);
}

TEST(UdpProtocol, MalformedDatagramsAreRejected) {
  udp::PoseMessage m;
  std::uint8_t b[udp::kPoseSize];
  udp::encode(m, b);
  udp::PoseMessage out;
  EXPECT_FALSE(udp::decode(b, sizeof b - 1, out));  // wrong size
  std::uint8_t bad[udp::kPoseSize];
  std::memcpy(bad, b, sizeof b);
  bad[0] = 'X';
  EXPECT_FALSE(udp::decode(bad, sizeof bad, out));  // magic
  std::memcpy(bad, b, sizeof b);
  bad[4] = 2;
  EXPECT_FALSE(udp::decode(bad, sizeof bad, out));  // version
  std::memcpy(bad, b, sizeof b);
  bad[6] = 2;
  EXPECT_FALSE(udp::decode(bad, sizeof bad, out));  // type
  m.position_m.x() = std::nan("");
  udp::encode(m, b);
  EXPECT_FALSE(udp::decode(b, sizeof b, out));      // NaN position
}

TEST(UdpProtocol, SequenceNumbersWrapAround) {
  EXPECT_TRUE(udp::sequence_newer(2, 1));
  EXPECT_FALSE(udp::sequence_newer(1, 2));
  EXPECT_FALSE(udp::sequence_newer(5, 5));
  EXPECT_TRUE(udp::sequence_newer(3, 0xFFFFFFFEu));  // after the wrap
  EXPECT_FALSE(udp::sequence_newer(0xFFFFFFFEu, 3));
}

/// The tiny sender: a UDP socket that sends POSE messages to the device and reads its FORCE replies.
class Bridge {
 public:
  explicit Bridge(std::uint16_t device_port) {
    fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    to_.sin_family = AF_INET;
    to_.sin_port = htons(device_port);
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    timeval tv{0, 200000};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~Bridge() { ::close(fd_); }
  void send(std::uint32_t sequence, double z, std::uint32_t flags = 0) {
    udp::PoseMessage m;
    m.sequence = sequence;
    m.flags = flags;
    m.position_m = Eigen::Vector3d(0.0, 0.0, z);
    std::uint8_t b[udp::kPoseSize];
    udp::encode(m, b);
    ::sendto(fd_, b, sizeof b, 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_);
  }
  void send_raw(const void* data, std::size_t n) {
    ::sendto(fd_, data, n, 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_);
  }
  bool receive(udp::ForceMessage& m) {
    std::uint8_t b[256];
    const ssize_t n = ::recv(fd_, b, sizeof b, 0);
    return n > 0 && udp::decode(b, static_cast<std::size_t>(n), m);
  }

 private:
  int fd_ = -1;
  sockaddr_in to_{};
};

/// Reads until the device has consumed what was sent (loopback delivery is fast but asynchronous).
void read_after_delivery(UdpDevice& device, double t, DeviceInput& in) {
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  device.read(0, t, in);
}

TEST(UdpDevice, LoopbackSenderDrivesTheNeedle) {
  UdpDeviceOptions o;
  o.port = 0;  // any free port
  o.timeout_s = 0.05;
  UdpDevice device(o);
  ASSERT_GT(device.port(), 0);
  Bridge bridge(device.port());

  DeviceInput in;
  device.read(0, 0.0, in);
  EXPECT_EQ(in.status, DeviceInput::Status::NoPose);  // nothing sent yet

  bridge.send(10, -0.001);
  bridge.send(11, -0.002);
  bridge.send(9, -0.009);  // older: dropped
  const char junk[] = "not a pose";
  bridge.send_raw(junk, sizeof junk);
  read_after_delivery(device, 0.001, in);
  ASSERT_EQ(in.status, DeviceInput::Status::Pose);
  EXPECT_EQ(in.pose.position_m.z(), -0.002);  // the newest
  EXPECT_FALSE(in.pose.has_velocity);

  ForceOutput out;
  out.tick = 1;
  out.force_N = Eigen::Vector3d(0, 0, 0.42);
  out.layer_states = 1;
  device.write(out);
  udp::ForceMessage reply;
  ASSERT_TRUE(bridge.receive(reply));
  EXPECT_EQ(reply.echo_sequence, 11u);
  EXPECT_EQ(reply.tick_sequence, 1u);
  EXPECT_EQ(reply.force_N.z(), 0.42);

  bridge.send(14, -0.003);  // 12 and 13 lost
  read_after_delivery(device, 0.002, in);
  EXPECT_EQ(in.pose.position_m.z(), -0.003);
  // Silence longer than the timeout: no pose.
  device.read(0, 0.002 + 0.06, in);
  EXPECT_EQ(in.status, DeviceInput::Status::NoPose);

  bridge.send(15, 0.001, udp::kPoseFreshTissue);
  read_after_delivery(device, 0.07, in);
  EXPECT_TRUE(in.fresh_tissue);
  device.fresh_tissue_result(true);
  bridge.send(16, 0.001, udp::kPoseFreshTissue);  // the same request still flagged: served once
  read_after_delivery(device, 0.071, in);
  EXPECT_FALSE(in.fresh_tissue);

  const UdpDeviceCounters c = device.counters();
  EXPECT_EQ(c.received, 5);
  EXPECT_EQ(c.stale, 1);
  EXPECT_EQ(c.malformed, 1);
  EXPECT_EQ(c.lost, 2);
  EXPECT_EQ(c.sent, 1);
}

TEST(UdpDevice, BindFailureNamesTheAddress) {
  UdpDeviceOptions o;
  o.bind_address = "not-an-address";
  try {
    UdpDevice device(o);
    FAIL() << "accepted a bad address";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not-an-address"), std::string::npos);
  }
}

}  // namespace
}  // namespace puncture::realtime
