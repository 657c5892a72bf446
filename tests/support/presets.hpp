#pragma once
// Paths of the shipped mobiles, and helpers to load them with changed settings.

#include <string>

#include "aloft/model.hpp"

namespace aloft::test {

inline std::string preset_path(const std::string& name) {
  return std::string(ALOFT_SOURCE_DIR) + "/mobiles/" + name + ".json";
}

// The preset compiled with another balance mode and no air damping.
inline Model load_preset(const std::string& name, BalanceMode mode, bool damping = false) {
  MobileSpec spec = parse_mobile_file(preset_path(name));
  spec.balance.mode = mode;
  if (!damping) spec.damping = DampingSpec{};
  return compile(spec);
}

}  // namespace aloft::test
