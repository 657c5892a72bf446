#pragma once
// Where a benchmark's timed steps start, by the names `aloft bench --start` and aloft_step_profile take:
//   "breeze"         the designed pose pushed by set_breeze (aloft/simulation.hpp) for kBreezeSteps steps
//   "rest"           the designed pose at rest (rest_state)
//   "swinging"       the benchmarks' swinging state (swinging_state, aloft/state.hpp; max rate 0.5
//                    rad/s, seed 7 as BM_StepSpan)
//   "swinging:SEED"  the same of another seed (a whole number)

#include <cstdint>
#include <optional>
#include <string_view>

namespace aloft {

// Steps of the breeze: 0.3 s at the default 1 ms step. A count, not a time, so that every machine
// times the same motion.
inline constexpr int kBreezeSteps = 300;

struct BenchStart {
  enum class From { kBreeze, kSwinging, kRest };
  From from = From::kBreeze;
  std::uint64_t seed = 7;  // of the swinging state; swinging_state's default, BM_StepSpan's start
};

// The start a name gives; nothing when the text is none of the names above.
std::optional<BenchStart> parse_bench_start(std::string_view text);

}  // namespace aloft
