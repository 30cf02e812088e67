// content_hash.hpp: FNV-1a 64 of a byte string, as 16 lower-case hex digits.
//
// In:  bytes (any), the offset basis (the standard one unless a caller wants
//      an independent second hash of the same bytes).
// Out: 16 hex digits. Used for content hashes of curves and for the FEM
//      cache keys; not a cryptographic hash.
#pragma once

#include <cstddef>
#include <string>

namespace puncture::io {

constexpr unsigned long long kFnv1a64OffsetBasis = 1469598103934665603ULL;

inline std::string fnv1a64_hex(const std::string& bytes, unsigned long long basis = kFnv1a64OffsetBasis) {
  unsigned long long h = basis;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  static const char* digits = "0123456789abcdef";
  std::string out(16, '0');
  for (int i = 15; i >= 0; --i, h >>= 4) out[static_cast<std::size_t>(i)] = digits[h & 0xF];
  return out;
}

}  // namespace puncture::io
