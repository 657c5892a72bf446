#pragma once
// splitmix64 (Steele, Lea and Flood, 2014): a small, well-mixed 64-bit generator whose stream is the
// same on every platform and compiler, unlike <random>'s distributions. Used wherever a seed must give
// the same numbers on every machine: the swinging state's spins, the wind's turbulence, the benchmarks'
// displaced poses.

#include <cstdint>

namespace aloft {

// The stream's next number; `state` is advanced (any value is a valid state).
inline std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// The stream's next number as a double in [0, 1): its top 53 bits, so every value is equally likely.
inline double splitmix64_unit(std::uint64_t& state) { return static_cast<double>(splitmix64(state) >> 11) * 0x1p-53; }

}  // namespace aloft
