#include "puncture/realtime/udp_protocol.hpp"

#include <cmath>
#include <cstring>

#include "byte_order.hpp"

namespace puncture::realtime::udp {
using namespace le;

namespace {

void put_header(std::uint8_t* p, std::uint16_t type) noexcept {
  put_u32(p, kMagic);
  put_u16(p + 4, kVersion);
  put_u16(p + 6, type);
}
bool header_ok(const std::uint8_t* p, std::uint16_t type) noexcept {
  return get_u32(p) == kMagic && get_u16(p + 4) == kVersion && get_u16(p + 6) == type;
}

}  // namespace

void encode(const PoseMessage& m, std::uint8_t (&out)[kPoseSize]) noexcept {
  std::memset(out, 0, kPoseSize);
  put_header(out, kTypePose);
  put_u32(out + 8, m.sequence);
  put_u32(out + 12, m.flags);
  put_f64(out + 16, m.device_time_s);
  for (int i = 0; i < 3; ++i) put_f64(out + 24 + 8 * i, m.position_m[i]);
  put_f64(out + 48, m.orientation.w());
  put_f64(out + 56, m.orientation.x());
  put_f64(out + 64, m.orientation.y());
  put_f64(out + 72, m.orientation.z());
  for (int i = 0; i < 3; ++i) put_f64(out + 80 + 8 * i, m.velocity_m_per_s[i]);
  put_u32(out + 104, m.buttons);
}

void encode(const ForceMessage& m, std::uint8_t (&out)[kForceSize]) noexcept {
  std::memset(out, 0, kForceSize);
  put_header(out, kTypeForce);
  put_u32(out + 8, m.tick_sequence);
  put_u32(out + 12, m.echo_sequence);
  put_u32(out + 16, m.flags);
  put_u32(out + 20, m.layer_states);
  put_f64(out + 24, m.model_time_s);
  for (int i = 0; i < 3; ++i) put_f64(out + 32 + 8 * i, m.force_N[i]);
  put_f64(out + 56, m.tissue_force_N);
  put_f64(out + 64, m.depth_m);
}

bool decode(const std::uint8_t* p, std::size_t size, PoseMessage& m) noexcept {
  if (size != kPoseSize || !header_ok(p, kTypePose)) return false;
  m.sequence = get_u32(p + 8);
  m.flags = get_u32(p + 12);
  m.device_time_s = get_f64(p + 16);
  for (int i = 0; i < 3; ++i) m.position_m[i] = get_f64(p + 24 + 8 * i);
  m.orientation = Eigen::Quaterniond(get_f64(p + 48), get_f64(p + 56), get_f64(p + 64), get_f64(p + 72));
  for (int i = 0; i < 3; ++i) m.velocity_m_per_s[i] = get_f64(p + 80 + 8 * i);
  m.buttons = get_u32(p + 104);
  if (!m.position_m.allFinite() || !m.orientation.coeffs().allFinite() || !std::isfinite(m.device_time_s))
    return false;
  if ((m.flags & kPoseVelocityValid) && !m.velocity_m_per_s.allFinite()) return false;
  if (!(m.orientation.norm() > 1e-6)) return false;
  return true;
}

bool decode(const std::uint8_t* p, std::size_t size, ForceMessage& m) noexcept {
  if (size != kForceSize || !header_ok(p, kTypeForce)) return false;
  m.tick_sequence = get_u32(p + 8);
  m.echo_sequence = get_u32(p + 12);
  m.flags = get_u32(p + 16);
  m.layer_states = get_u32(p + 20);
  m.model_time_s = get_f64(p + 24);
  for (int i = 0; i < 3; ++i) m.force_N[i] = get_f64(p + 32 + 8 * i);
  m.tissue_force_N = get_f64(p + 56);
  m.depth_m = get_f64(p + 64);
  return true;
}

}  // namespace puncture::realtime::udp
