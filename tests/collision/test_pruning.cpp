// Pair pruning: the counts add up, joined pairs are out, the Steel Fish keeps what the reach test
// must keep, and no pruned pair ever comes close in random poses the joints allow.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>

#include "aloft/collision.hpp"
#include "aloft/generate.hpp"
#include "aloft/spec.hpp"
#include "collision/narrow_phase.hpp"
#include "collision/prune.hpp"
#include "support/presets.hpp"

namespace aloft {
namespace {

int index_of(const Model& m, const std::string& name) {
  return static_cast<int>(std::find(m.names.begin(), m.names.end(), name) - m.names.begin());
}

bool listed(const std::vector<std::pair<int, int>>& pairs, int a, int b) {
  return std::binary_search(pairs.begin(), pairs.end(), std::pair{std::min(a, b), std::max(a, b)});
}

// A pose the joints allow: every joint turned by a random rotation of angle up to max_turn (rad),
// composed from the hook down.
State random_pose(const Model& model, double max_turn, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  State state = rest_state(model);
  std::vector<Quat> turn(model.count, Quat::Identity());
  for (int i = 1; i < model.count; ++i) {
    const int p = model.parent[i];
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    turn[i] = (turn[p] * Quat(Eigen::AngleAxisd(max_turn * 0.5 * (u(rng) + 1), axis))).normalized();
    state.orientation[i] = (turn[i] * model.rest_orientation[i]).normalized();
  }
  place_on_joints(model, state);
  return state;
}

// Do components a and b come within `gap` (m) at `state`? Every pair of their convex pieces.
bool within(const std::vector<internal::ComponentGeometry>& g, const State& state, int a, int b, double gap) {
  const internal::Pose pa{state.orientation[a].toRotationMatrix(), state.position[a]};
  const internal::Pose pb{state.orientation[b].toRotationMatrix(), state.position[b]};
  internal::PieceContact c;
  for (const auto& x : g[a].pieces)
    for (const auto& y : g[b].pieces)
      if (internal::piece_contact(x, pa, y, pb, gap, c)) return true;
  return false;
}

TEST(Pruning, SteelFish) {
  const Model m = load_mobile(test::preset_path("steel-fish"));
  const CollisionPairs p = prune_pairs(m);
  ASSERT_TRUE(p.listed);
  EXPECT_EQ(p.total, 36);  // 9 components
  EXPECT_EQ(p.joined, 8);
  EXPECT_EQ(p.total, p.candidate_count + p.joined + p.never_touch +
                         static_cast<long long>(p.touching_at_rest.size()));
  EXPECT_EQ(p.candidate_count, static_cast<long long>(p.candidates.size()));
  for (int i = 1; i < m.count; ++i) EXPECT_FALSE(listed(p.candidates, m.parent[i], i)) << m.names[i];
  const int o3 = index_of(m, "O3 white leaf"), o4 = index_of(m, "O4 red ball"), o5 = index_of(m, "O5 arm"),
            o6 = index_of(m, "O6 arm");
  // Siblings too far apart to ever reach each other: O3 (reach 0.382 m) and O6 (0.332 m) hang 0.750 m apart
  // on O2; O4 (0.250 m) and O5 (0.261 m) hang 0.517 m apart on O6.
  EXPECT_FALSE(listed(p.candidates, o3, o6));
  EXPECT_FALSE(listed(p.candidates, o4, o5));
  // O3 and O5 (which the paper prunes) are kept: O5 hangs 0.33 m from O6's joint and reaches 0.26 m
  // beyond, so with O6 swung towards O3 the reaches (0.38 + 0.59 m) exceed the 0.75 m gap: a sound
  // kinematic test cannot prune them.
  EXPECT_TRUE(listed(p.candidates, o3, o5));
  EXPECT_EQ(p.never_touch, 2);
}

TEST(Pruning, NoPrunedPairComesCloseInRandomPoses) {
  GenerateOptions options;
  options.components = 31;
  options.seed = 4;
  std::vector<Model> models = {load_mobile(test::preset_path("steel-fish")),
                               compile(parse_mobile_text(generate_mobile(options), "generated-31"))};
  std::mt19937 rng(9);
  long long pruned_checked = 0;
  for (const Model& m : models) {
    const auto geometry = internal::build_model_geometry(m);
    const CollisionPairs p = prune_pairs(m);
    std::vector<std::pair<int, int>> never;  // a < b, not joined, not candidate, not touching at rest
    for (int b = 1; b < m.count; ++b)
      for (int a = 0; a < b; ++a)
        if (m.parent[b] != a && !listed(p.candidates, a, b) && !listed(p.touching_at_rest, a, b))
          never.emplace_back(a, b);
    EXPECT_EQ(static_cast<long long>(never.size()), p.never_touch) << m.name;
    // Joints turned by up to pi: every orientation is reachable. 300 poses per mobile.
    for (int k = 0; k < 300; ++k) {
      const State s = random_pose(m, 3.14159, rng);
      for (const auto& [a, b] : never) {
        EXPECT_FALSE(within(geometry, s, a, b, internal::kPruneClearance)) << m.name << " " << a << " " << b;
        ++pruned_checked;
      }
    }
  }
  EXPECT_GT(pruned_checked, 0);  // the test checked something (the Steel Fish has 2 pruned pairs)
}

TEST(Pruning, TwoPiecesHungFromOnePointTouchAtRest) {
  EXPECT_TRUE(prune_pairs(load_mobile(test::preset_path("steel-fish"))).touching_at_rest.empty());
  // Two spheres of a tiny custom mobile hung from one hook point, overlapping at rest.
  const std::string text = R"({"name": "pair", "aloft": 1, "balance": {"mode": "none"},
    "components": [
      {"name": "hook", "fixed": true, "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.01}}]},
      {"name": "left", "parent": "hook", "joint": [0, 0.99, 0], "shapes": [
        {"wire": {"from": [0, 0.99, 0], "to": [0, 0.8, 0], "radius": 0.001}},
        {"sphere": {"center": [0, 0.75, 0], "radius": 0.05}}]},
      {"name": "right", "parent": "hook", "joint": [0, 0.99, 0], "shapes": [
        {"wire": {"from": [0, 0.99, 0], "to": [0, 0.6, 0], "radius": 0.001}},
        {"sphere": {"center": [0, 0.55, 0], "radius": 0.05}}]}]})";
  const Model pair = compile(parse_mobile_text(text, "pair.json"));
  const CollisionPairs q = prune_pairs(pair);
  ASSERT_EQ(q.touching_at_rest.size(), 1u);  // the two threads coincide along 0.19 m
  EXPECT_TRUE(q.candidates.empty());
}

}  // namespace
}  // namespace aloft
