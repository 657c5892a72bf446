#pragma once
// WAV files built byte by byte for the reader's tests.

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace aloft::test {

inline void put16(std::vector<std::uint8_t>& b, unsigned v) {
  b.push_back(v & 0xff);
  b.push_back((v >> 8) & 0xff);
}
inline void put32(std::vector<std::uint8_t>& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back((v >> (8 * i)) & 0xff);
}
inline void put_tag(std::vector<std::uint8_t>& b, const char* tag) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(tag[i]));
}

// A WAV with the given format code, channels, rate, bits and raw sample bytes; `extensible` wraps the format
// in WAVE_FORMAT_EXTENSIBLE; `extra_chunk` adds a "LIST" chunk of 3 bytes (odd: padded) before "data".
inline std::vector<std::uint8_t> wav_bytes(unsigned format, unsigned channels, std::uint32_t rate, unsigned bits,
                                           const std::vector<std::uint8_t>& data, bool extensible = false,
                                           bool extra_chunk = false) {
  std::vector<std::uint8_t> b;
  put_tag(b, "RIFF");
  put32(b, 0);  // patched below
  put_tag(b, "WAVE");
  put_tag(b, "fmt ");
  put32(b, extensible ? 40 : 16);
  put16(b, extensible ? 0xFFFE : format);
  put16(b, channels);
  put32(b, rate);
  put32(b, rate * channels * bits / 8);
  put16(b, channels * bits / 8);
  put16(b, bits);
  if (extensible) {
    put16(b, 22);        // cbSize
    put16(b, bits);      // valid bits
    put32(b, 0);         // channel mask
    put16(b, format);    // sub-format GUID: format code, then the fixed tail
    const std::uint8_t tail[14] = {0x00, 0x00, 0x00, 0x00, 0x10, 0x00, 0x80, 0x00, 0x00, 0xAA, 0x00, 0x38, 0x9B, 0x71};
    b.insert(b.end(), tail, tail + 14);
  }
  if (extra_chunk) {
    put_tag(b, "LIST");
    put32(b, 3);
    b.push_back('a');
    b.push_back('b');
    b.push_back('c');
    b.push_back(0);  // pad byte
  }
  put_tag(b, "data");
  put32(b, static_cast<std::uint32_t>(data.size()));
  b.insert(b.end(), data.begin(), data.end());
  const std::uint32_t riff = static_cast<std::uint32_t>(b.size() - 8);
  std::memcpy(b.data() + 4, &riff, 4);  // little-endian host (x86)
  return b;
}

}  // namespace aloft::test
