// byte_order.hpp (internal): little-endian encoding of the integers and
// IEEE-754 doubles of the UDP protocol and the recording format,
// independent of the host's byte order.
#pragma once

#include <cstdint>
#include <cstring>

namespace puncture::realtime::le {

inline void put_u16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_u32(std::uint8_t* p, std::uint32_t v) noexcept {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void put_u64(std::uint8_t* p, std::uint64_t v) noexcept {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void put_f64(std::uint8_t* p, double d) noexcept {
  std::uint64_t v;
  std::memcpy(&v, &d, 8);
  put_u64(p, v);
}
inline std::uint16_t get_u16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
inline std::uint32_t get_u32(const std::uint8_t* p) noexcept {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return v;
}
inline std::uint64_t get_u64(const std::uint8_t* p) noexcept {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}
inline double get_f64(const std::uint8_t* p) noexcept {
  const std::uint64_t v = get_u64(p);
  double d;
  std::memcpy(&d, &v, 8);
  return d;
}

}  // namespace puncture::realtime::le
