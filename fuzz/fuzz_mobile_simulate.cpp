// libFuzzer target: arbitrary bytes as a mobile file, parsed, compiled and, when that succeeds, simulated
// for a few steps from the swinging state with collisions on, blown by the file's wind sources (the first
// kMostWinds, each with its occlusion refreshed every kRefreshSteps). The only acceptable failures are an
// InputError (the file) and a step that returns false with a reason (Simulation::failure(): the state
// went non-finite, or a piece spins too fast for any step). A crash, a sanitizer report, another
// exception (a wind source the reader took but the wind refuses), a hang, a step that returns true with a
// non-finite state, or a false one without a reason is a bug. Mobiles of more than kMostComponents are
// only compiled, to keep each run short.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "aloft/error.hpp"
#include "aloft/model.hpp"
#include "aloft/simulation.hpp"
#include "aloft/spec.hpp"
#include "aloft/state.hpp"
#include "aloft/wind.hpp"

namespace {

constexpr int kMostComponents = 40;
constexpr int kSteps = 20;  // 20 ms at the default step: enough for the first contacts of a swinging start
constexpr std::size_t kMostWinds = 3;
constexpr int kRefreshSteps = 5;
constexpr int kItemBufferPixels = 64;  // per side: coarse, to keep each run short; the arithmetic is the same

// The file's wind sources as `aloft simulate` builds them (file_source_cone, file_source_settings).
std::vector<std::unique_ptr<aloft::Wind>> file_winds(const aloft::Model& model, const aloft::MobileSpec& spec) {
  std::vector<std::unique_ptr<aloft::Wind>> winds;
  for (std::size_t i = 0; i < spec.wind_sources.size() && i < kMostWinds; ++i) {
    const aloft::WindSourceSpec& w = spec.wind_sources[i];
    aloft::WindSettings coarse;
    coarse.resolution = kItemBufferPixels;
    try {
      const aloft::WindSettings settings = aloft::file_source_settings(w, i, coarse);
      winds.push_back(std::make_unique<aloft::Wind>(model, aloft::file_source_cone(w), settings));
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "%s: the reader took it, the wind refused it: %s\n", w.path.c_str(), e.what());
      std::abort();
    }
  }
  return winds;
}

bool finite(const aloft::State& s) {
  for (std::size_t i = 0; i < s.position.size(); ++i)
    if (!s.position[i].allFinite() || !s.velocity[i].allFinite() || !s.angular[i].allFinite() ||
        !s.orientation[i].coeffs().allFinite())
      return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  aloft::MobileSpec spec;
  aloft::Model model;
  try {
    spec = aloft::parse_mobile_text(text, "fuzz.json", "/nonexistent-aloft-fuzz-dir");
    model = aloft::compile(spec);
  } catch (const aloft::InputError&) {
    return 0;
  }
  if (model.count > kMostComponents) return 0;
  aloft::Simulation sim(model, aloft::swinging_state(model, 2.0, 1));
  sim.set_collisions(true);
  const std::vector<std::unique_ptr<aloft::Wind>> winds = file_winds(model, spec);
  for (int k = 0; k < kSteps; ++k) {
    if (!winds.empty()) {
      aloft::ExternalLoads& loads = sim.loads();
      loads.clear();
      for (std::size_t i = 0; i < winds.size(); ++i) {
        if (k % kRefreshSteps == 0) winds[i]->refresh_occlusion(sim.state());
        winds[i]->apply(sim.state(), spec.wind_sources[i].v0(sim.state().time), sim.timestep(), loads);
      }
    }
    if (!sim.step()) {
      if (!sim.failure() || sim.failure()->message.empty()) {
        std::fprintf(stderr, "step %d failed without a reason\n", k);
        std::abort();
      }
      return 0;
    }
    if (!finite(sim.state())) {
      std::fprintf(stderr, "step %d returned true with a non-finite state\n", k);
      std::abort();
    }
  }
  return 0;
}
