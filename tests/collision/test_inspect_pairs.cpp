// `aloft inspect` reports the pruning: in JSON as the top-level key "collision_pairs", in text as a
// "Collision pairs" section, with the same numbers prune_pairs() gives.

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "aloft/collision.hpp"
#include "support/presets.hpp"

namespace aloft {
namespace {

std::string run(const std::string& arguments) {
  const std::string command = std::string(ALOFT_CLI) + " " + arguments + " 2>&1";
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return out;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  EXPECT_EQ(pclose(pipe), 0) << command;
  return out;
}

TEST(InspectPairs, JsonAndTextMatchPrunePairs) {
  const std::string path = test::preset_path("steel-fish");
  const CollisionPairs p = prune_pairs(load_mobile(path));
  const auto json = nlohmann::json::parse(run("inspect " + path + " --json"));
  const auto& c = json.at("collision_pairs");
  EXPECT_EQ(c.at("total").get<long long>(), p.total);
  EXPECT_EQ(c.at("pruned").get<long long>(), p.total - p.candidate_count);
  EXPECT_EQ(c.at("joined").get<long long>(), p.joined);
  EXPECT_EQ(c.at("never_touch").get<long long>(), p.never_touch);
  ASSERT_EQ(c.at("candidates").size(), p.candidates.size());
  EXPECT_EQ(c.at("candidates")[0][0].get<std::string>(), "hook");  // pairs by name, sorted by index
  EXPECT_TRUE(json.contains("components"));                        // the existing keys are still there
  const std::string text = run("inspect " + path);
  EXPECT_NE(text.find("Collision pairs: 10 of 36 pruned (8 joined by a joint, 2 can never touch"), std::string::npos)
      << text;
  EXPECT_NE(text.find("O3 white leaf  --  O5 arm"), std::string::npos);
}

}  // namespace
}  // namespace aloft
