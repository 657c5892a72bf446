#pragma once
// Random balanced mobiles, for tests and scaling: a binary tree of bars (wires) hanging from a fixed
// hook, with plates and balls at the leaves. The result is a mobile file (JSON text) in balance mode
// "mass", so compile() derives the masses that make the designed pose an equilibrium.

#include <string>

namespace aloft {

struct GenerateOptions {
  int components = 15;        // total, the fixed hook included; >= 2
  unsigned seed = 1;
  double total_mass = 1.0;    // kg of the moving components
};

// The mobile file text (pretty-printed JSON). Same options, same text, on every machine.
std::string generate_mobile(const GenerateOptions& options);

}  // namespace aloft
