// The portable generator (src/common/splitmix64.hpp): its stream is the published one, so a seed gives
// the same swinging state and the same gusts on every machine.

#include <gtest/gtest.h>

#include <cstdint>

#include "common/splitmix64.hpp"

namespace aloft {
namespace {

TEST(Splitmix64, GivesThePublishedStream) {
  // The first outputs from state 0 of Vigna's reference splitmix64.c (prng.di.unimi.it).
  std::uint64_t state = 0;
  EXPECT_EQ(splitmix64(state), 0xe220a8397b1dcdafULL);
  EXPECT_EQ(splitmix64(state), 0x6e789e6aa1b965f4ULL);
  EXPECT_EQ(splitmix64(state), 0x06c45d188009454fULL);
}

TEST(Splitmix64, UnitNumbersAreTheTop53BitsInZeroToOne) {
  std::uint64_t a = 12345, b = 12345;
  for (int k = 0; k < 1000; ++k) {
    const double u = splitmix64_unit(a);
    EXPECT_EQ(u, static_cast<double>(splitmix64(b) >> 11) / 9007199254740992.0);  // 2^53: exact
    EXPECT_GE(u, 0.0);
    EXPECT_LT(u, 1.0);
  }
}

}  // namespace
}  // namespace aloft
