// parse_bench_start (aloft/bench_start.hpp): the names `aloft bench --start` and aloft_step_profile take.

#include <gtest/gtest.h>

#include "aloft/bench_start.hpp"

namespace aloft {
namespace {

TEST(BenchStart, NamesGiveTheirStartsAndAnythingElseNone) {
  using From = BenchStart::From;
  EXPECT_EQ(parse_bench_start("breeze")->from, From::kBreeze);
  EXPECT_EQ(parse_bench_start("rest")->from, From::kRest);
  EXPECT_EQ(parse_bench_start("swinging")->from, From::kSwinging);
  EXPECT_EQ(parse_bench_start("swinging")->seed, 7u);  // BM_StepSpan's
  EXPECT_EQ(parse_bench_start("swinging:3")->seed, 3u);
  EXPECT_EQ(parse_bench_start("swinging:18446744073709551615")->seed, 18446744073709551615u);  // 2^64 - 1
  for (const char* bad : {"", "Rest", "breeze:2", "rest:1", "swinging:", "swinging:-1", "swinging:+1", "swinging:1x",
                          "swinging: 1", "swinging:18446744073709551616", "swing"})
    EXPECT_FALSE(parse_bench_start(bad)) << "\"" << bad << "\"";
}

}  // namespace
}  // namespace aloft
