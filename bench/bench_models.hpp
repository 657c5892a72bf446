#pragma once
// The mobiles the benchmarks run (presets from mobiles/, generated ones) and how long BM_StepSpan runs
// them. Their common start is the library's swinging_state (aloft/state.hpp).

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

}  // namespace aloft::bench
