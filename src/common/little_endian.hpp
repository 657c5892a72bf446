#pragma once
// Unsigned values stored little-endian in a byte buffer, read the same on every host (the byte order of
// WAV files and of the contact-law recordings). `p` points at the value's first byte.

#include <cstdint>

namespace aloft {

inline std::uint16_t little_endian_u16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}

inline std::uint32_t little_endian_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

inline std::uint64_t little_endian_u64(const std::uint8_t* p) {
  return static_cast<std::uint64_t>(little_endian_u32(p)) | (static_cast<std::uint64_t>(little_endian_u32(p + 4)) << 32);
}

}  // namespace aloft
