#pragma once
// Bytes from an input file, shown in a message: a NUL cut a message short, and control bytes garble the
// terminal it is printed on.

#include <cstdio>
#include <string>
#include <string_view>

namespace aloft {

// `bytes` with every byte that is not printable ASCII, and the quote and the backslash, written as \xNN;
// at most `limit` bytes of it, then "...".
inline std::string printable(std::string_view bytes, std::size_t limit = 80) {
  std::string out;
  for (std::size_t i = 0; i < bytes.size() && i < limit; ++i) {
    const unsigned char c = static_cast<unsigned char>(bytes[i]);
    if (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') {
      out += static_cast<char>(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", static_cast<unsigned>(c));
      out += hex;
    }
  }
  if (bytes.size() > limit) out += "...";
  return out;
}

}  // namespace aloft
