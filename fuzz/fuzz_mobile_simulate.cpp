// libFuzzer target: arbitrary bytes as a mobile file, parsed, compiled and, when that succeeds, simulated
// for a few steps from the swinging state with collisions on. The only acceptable failures are an
// InputError (the file) and a step that returns false with a reason (Simulation::failure(): the state
// went non-finite, or a piece spins too fast for any step). A crash, a sanitizer report, another
// exception, a hang, a step that returns true with a non-finite state, or a false one without a reason
// is a bug. Mobiles of more than kMostComponents are only compiled, to keep each run short.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "aloft/error.hpp"
#include "aloft/model.hpp"
#include "aloft/simulation.hpp"
#include "aloft/spec.hpp"
#include "aloft/state.hpp"

namespace {

constexpr int kMostComponents = 40;
constexpr int kSteps = 20;  // 20 ms at the default step: enough for the first contacts of a swinging start

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
  aloft::Model model;
  try {
    model = aloft::compile(aloft::parse_mobile_text(text, "fuzz.json", "/nonexistent-aloft-fuzz-dir"));
  } catch (const aloft::InputError&) {
    return 0;
  }
  if (model.count > kMostComponents) return 0;
  aloft::Simulation sim(model, aloft::swinging_state(model, 2.0, 1));
  sim.set_collisions(true);
  for (int k = 0; k < kSteps; ++k) {
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
