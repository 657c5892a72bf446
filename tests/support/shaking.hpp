#pragma once
// The shaking of the shaken Steel Fish tests, for the tests that step along it.

#include <random>

#include "aloft/model.hpp"
#include "aloft/simulation.hpp"

namespace aloft::test {

// Every 50 steps (from step 0) a new uniform acceleration of the whole mobile, 0.5 g rms per axis, drawn
// from g with rng, as if the hook were jerked about; call it before each step with the step's number.
inline void shake(const Model& m, Simulation& sim, std::mt19937& rng, std::normal_distribution<double>& g, int step) {
  if (step % 50 != 0) return;
  const Vec3 jerk = 0.5 * 9.81 * Vec3(g(rng), g(rng), g(rng));
  for (int i = 1; i < m.count; ++i) sim.loads().force[i] = m.mass[i] * jerk;
}

}  // namespace aloft::test
