#pragma once
// A whole text field as a decimal number, the same way in every text reader (OBJ meshes, speed CSVs) and for
// the command line's numbers: std::from_chars, so no hexadecimal ("0x10" is not 16), no locale, and "inf"
// and "nan" are named as not finite rather than taken; an optional leading '+', which writers sometimes emit.

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>
#include <system_error>

namespace aloft {

enum class NumberResult { ok, not_a_number, not_finite };

// from_chars does not take a leading '+'.
inline std::string_view without_plus(std::string_view s) {
  if (s.size() > 1 && s[0] == '+' && s[1] != '-' && s[1] != '+') s.remove_prefix(1);
  return s;
}

// `s` whole as a finite double in `value`. A number too small for a double (1e-400) reads as 0 or a
// subnormal: ok; one too large (1e400) is not finite.
inline NumberResult parse_double(std::string_view s, double& value) {
  s = without_plus(s);
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, value, std::chars_format::general);
  if (r.ptr != end || s.empty()) return NumberResult::not_a_number;
  if (r.ec == std::errc::result_out_of_range) {
    // Too large (non-finite) or too small (rounds to zero or a subnormal: acceptable); strtod tells which.
    const std::string copy(s);
    value = std::strtod(copy.c_str(), nullptr);
    return std::isfinite(value) ? NumberResult::ok : NumberResult::not_finite;
  }
  if (r.ec != std::errc()) return NumberResult::not_a_number;
  return std::isfinite(value) ? NumberResult::ok : NumberResult::not_finite;
}

}  // namespace aloft
