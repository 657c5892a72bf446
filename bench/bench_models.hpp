#pragma once
// The mobiles the benchmarks run (presets from mobiles/, generated ones) and the common initial state:
// the designed pose with every component turning, so that the mobile swings.

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "aloft/generate.hpp"
#include "aloft/model.hpp"
#include "aloft/spec.hpp"
#include "aloft/state.hpp"

#ifndef ALOFT_MOBILES_DIR
#error "ALOFT_MOBILES_DIR (the source tree's mobiles/ directory) must be defined"
#endif

namespace aloft::bench {

// Path of a preset mobile ("steel-fish" -> <source>/mobiles/steel-fish.json).
inline std::string preset_path(const std::string& name) {
  return std::string(ALOFT_MOBILES_DIR) + "/" + name + ".json";
}

inline bool preset_exists(const std::string& name) { return std::filesystem::exists(preset_path(name)); }

// A random balanced mobile from generate_mobile (total mass 1 kg), compiled.
inline std::unique_ptr<Model> generated_model(int components, unsigned seed = 1) {
  GenerateOptions options;
  options.components = components;
  options.seed = seed;
  options.total_mass = 1.0;
  const std::string name = "generated-" + std::to_string(components);
  return std::make_unique<Model>(compile(parse_mobile_text(generate_mobile(options), name)));
}

inline std::unique_ptr<Model> preset_model(const std::string& name) {
  return std::make_unique<Model>(load_mobile(preset_path(name)));
}

// BM_StepSpan's fixed number of steps (1 ms each) from the swinging state for a generated mobile of
// `components`: a few simulated seconds where that takes seconds to time, so that knocks and quiet
// stretches both count (aloft_compare --collisions times the same spans).
inline int span_steps(int components) {
  if (components <= 15) return 20000;
  if (components <= 127) return 10000;
  if (components <= 1023) return 5000;
  if (components <= 8191) return 2000;
  return 30;
}

// The designed pose with a random angular velocity (world, uniform direction, magnitude uniform in
// [rate/2, rate] rad/s) on every moving component, and centre-of-mass velocities that keep every joint
// together: v_i = v_p + w_p x (j_i - x_p) + w_i x (x_i - j_i). Same seed, same state on every machine
// (a fixed 64-bit generator, no <random> distributions).
inline State swinging_state(const Model& model, double rate = 0.5, std::uint64_t seed = 7) {
  std::uint64_t s = seed * 0x9E3779B97F4A7C15ull + 1;
  auto unit = [&s] {  // splitmix64 -> [0, 1)
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53;
  };
  State state = rest_state(model);
  for (int i = 1; i < model.count; ++i) {
    const double z = 2 * unit() - 1;
    const double phi = 2 * M_PI * unit();
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    const Vec3 axis(r * std::cos(phi), r * std::sin(phi), z);
    state.angular[i] = rate * (0.5 + 0.5 * unit()) * axis;
  }
  for (int i = 1; i < model.count; ++i) {
    const int p = model.parent[i];
    const Vec3 joint = joint_on_child(model, state, i);
    state.velocity[i] = state.velocity[p] + state.angular[p].cross(joint - state.position[p]) +
                        state.angular[i].cross(state.position[i] - joint);
  }
  return state;
}

}  // namespace aloft::bench
