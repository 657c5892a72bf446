// The benchmarks' starts by name (see include/aloft/bench_start.hpp).

#include "aloft/bench_start.hpp"

#include <charconv>

namespace aloft {

std::optional<BenchStart> parse_bench_start(std::string_view text) {
  if (text == "breeze") return BenchStart{};
  if (text == "rest") return BenchStart{BenchStart::From::kRest};
  if (text == "swinging") return BenchStart{BenchStart::From::kSwinging};
  constexpr std::string_view prefix = "swinging:";
  if (!text.starts_with(prefix) || text.size() == prefix.size()) return std::nullopt;
  BenchStart start{BenchStart::From::kSwinging};
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data() + prefix.size(), end, start.seed);
  if (ec != std::errc() || ptr != end) return std::nullopt;
  return start;
}

}  // namespace aloft
