// The random-mobile generator: exact component counts, determinism, valid files that compile for many
// sizes and seeds, balance (the designed pose is an equilibrium and stays still when simulated),
// non-overlapping leaves, and speed at 65535 components.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <variant>
#include <vector>

#include "aloft/generate.hpp"
#include "aloft/model.hpp"
#include "aloft/simulation.hpp"
#include "aloft/spec.hpp"

namespace aloft {
namespace {

Model generated(int components, unsigned seed, double total_mass = 1.0) {
  GenerateOptions o;
  o.components = components;
  o.seed = seed;
  o.total_mass = total_mass;
  return compile(parse_mobile_text(generate_mobile(o), "generated.json"));
}

// Largest distance any component moved from the designed pose during `steps` steps from rest.
double drift_from_rest(const Model& model, int steps) {
  Simulation sim(model);
  for (int s = 0; s < steps; ++s) EXPECT_TRUE(sim.step());
  double worst = 0;
  for (int i = 0; i < model.count; ++i)
    worst = std::max(worst, (sim.state().position[i] - model.rest_position[i]).norm());
  return worst;
}

TEST(Generate, ExactCountAndOneFixedHook) {
  for (int n : {2, 3, 4, 5, 6, 7, 8, 15, 16, 100, 127, 128}) {
    const Model m = generated(n, 7);
    EXPECT_EQ(m.count, n);
    EXPECT_EQ(m.names[0], "hook");
    EXPECT_EQ(m.parent[0], -1);
    for (int i = 1; i < n; ++i) EXPECT_LE(m.children[i].size(), 2u) << n;
  }
}

TEST(Generate, Deterministic) {
  GenerateOptions o;
  o.components = 200;
  o.seed = 42;
  const std::string a = generate_mobile(o), b = generate_mobile(o);
  EXPECT_EQ(a, b);
  o.seed = 43;
  EXPECT_NE(a, generate_mobile(o));
}

TEST(Generate, RejectsBadOptions) {
  GenerateOptions o;
  o.components = 1;
  EXPECT_THROW(generate_mobile(o), std::invalid_argument);
  o.components = 10;
  o.total_mass = 0;
  EXPECT_THROW(generate_mobile(o), std::invalid_argument);
}

TEST(Generate, CompilesBalancedForManySizesAndSeeds) {
  for (int n = 2; n <= 300; ++n) {
    std::vector<unsigned> seeds{1u, 1000u + static_cast<unsigned>(n)};
    if (n <= 40) seeds.insert(seeds.end(), {2u, 3u, 4u, 5u, 6u, 7u, 8u, 9u});
    for (unsigned seed : seeds) {
      SCOPED_TRACE("components " + std::to_string(n) + ", seed " + std::to_string(seed));
      Model m;
      ASSERT_NO_THROW(m = generated(n, seed, 0.5));
      ASSERT_EQ(m.count, n);
      EXPECT_EQ(m.balance.mode, BalanceMode::Mass);
      EXPECT_LT(m.balance.max_imbalance, 1e-6);
      EXPECT_NEAR(m.balance.total_mass, 0.5, 1e-9);
      for (int i = 1; i < n; ++i) ASSERT_GT(m.mass[i], 0);
    }
  }
}

TEST(Generate, StaysAtRest) {
  for (int n : {2, 3, 4, 9, 16, 31, 64, 255}) {
    for (unsigned seed : {1u, 5u}) {
      const Model m = generated(n, seed);
      EXPECT_LT(drift_from_rest(m, 200), 1e-6) << n << " components, seed " << seed;
    }
  }
}

TEST(Generate, LargeMobile) {
  const Model m = generated(8191, 11);
  EXPECT_EQ(m.count, 8191);
  EXPECT_LT(m.balance.max_imbalance, 1e-6);
  EXPECT_LT(drift_from_rest(m, 200), 1e-6);
}

// Horizontal bounding boxes (x, z) of the leaves' shapes must not overlap.
TEST(Generate, LeavesDoNotOverlap) {
  for (unsigned seed : {1u, 2u, 3u}) {
    GenerateOptions o;
    o.components = 301;
    o.seed = seed;
    const MobileSpec spec = parse_mobile_text(generate_mobile(o));
    std::vector<std::string> parents;
    for (const ComponentSpec& c : spec.components)
      if (c.parent) parents.push_back(*c.parent);
    std::sort(parents.begin(), parents.end());
    struct Box2 {
      double x0, x1, z0, z1;
    };
    std::vector<Box2> boxes;
    for (const ComponentSpec& c : spec.components) {
      if (c.fixed || std::binary_search(parents.begin(), parents.end(), c.name)) continue;
      Box2 b{1e9, -1e9, 1e9, -1e9};
      auto add = [&](const Vec3& p, double r) {
        b.x0 = std::min(b.x0, p.x() - r), b.x1 = std::max(b.x1, p.x() + r);
        b.z0 = std::min(b.z0, p.z() - r), b.z1 = std::max(b.z1, p.z() + r);
      };
      for (const ShapeSpec& s : c.shapes) {
        if (const auto* sp = std::get_if<Sphere>(&s.shape)) add(sp->center, sp->radius);
        if (const auto* w = std::get_if<Wire>(&s.shape)) add(w->from, w->radius), add(w->to, w->radius);
        if (const auto* pl = std::get_if<Plate>(&s.shape))
          for (const Vec2& q : pl->points) add(pl->to_world(q), pl->thickness);
      }
      boxes.push_back(b);
    }
    ASSERT_GT(boxes.size(), 100u);
    for (size_t i = 0; i < boxes.size(); ++i)
      for (size_t j = i + 1; j < boxes.size(); ++j) {
        const bool apart = boxes[i].x1 < boxes[j].x0 || boxes[j].x1 < boxes[i].x0 || boxes[i].z1 < boxes[j].z0 ||
                           boxes[j].z1 < boxes[i].z0;
        EXPECT_TRUE(apart) << "leaves " << i << " and " << j << " overlap (seed " << seed << ")";
      }
  }
}

// Generate + parse + compile of 65535 components in a few seconds of processor time (all threads; processor
// time rather than wall time, so that a loaded machine does not fail the test).
TEST(Generate, SixtyFiveThousandComponentsCompileBalanced) {
  // The time this takes is measured by the BM_Load benchmark (bench/bench_step.cpp), not here.
  const Model m = generated(65535, 3);
  EXPECT_EQ(m.count, 65535);
  EXPECT_LT(m.balance.max_imbalance, 1e-6);
}

}  // namespace
}  // namespace aloft
