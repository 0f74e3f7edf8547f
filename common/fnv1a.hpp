#pragma once
// 64-bit FNV-1a: the checksum of files that talus writes and reads back (a calibration checkpoint,
// a partial result). It detects damage and hand edits (any change of one byte changes it), not a
// forger, who can compute it as well.

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace talus {

inline constexpr std::uint64_t kFnv1aStart = 1469598103934665603ULL;

// Goes on from `h` (kFnv1aStart for a fresh hash) over `bytes`.
inline std::uint64_t Fnv1a64(std::string_view bytes, std::uint64_t h = kFnv1aStart) {
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return h;
}

// 16 lower-case hex digits.
inline std::string Fnv1a64Hex(std::string_view bytes) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(Fnv1a64(bytes)));
  return hex;
}

}  // namespace talus
