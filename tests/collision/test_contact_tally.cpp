// ContactTally: which pairs touched, in how many steps, when and how deeply; and on a real run, the two
// leaning balls touch in every step from their first knock on.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <vector>

#include "aloft/contact_tally.hpp"
#include "aloft/model.hpp"
#include "aloft/simulation.hpp"
#include "aloft/spec.hpp"
#include "support/leaning_balls.hpp"

namespace aloft {
namespace {

Contact contact(int a, int b, double distance) {
  Contact c;
  c.a = a;
  c.b = b;
  c.distance = distance;
  return c;
}

TEST(ContactTally, CountsEachPairOncePerStepWithinTheTouchingGap) {
  ContactTally tally;
  const double gap = ContactTally::kTouchingGap;
  // Step 1: two contacts of (1, 2), one overlapping by 0.01 mm; (2, 3) just beyond the gap.
  tally.add_step({contact(1, 2, -1e-5), contact(1, 2, 0.5 * gap), contact(2, 3, 1.01 * gap)}, {}, 0.001);
  // Step 2: (1, 2) exactly at the gap, (0, 3) overlapping by 0.03 mm.
  tally.add_step({contact(0, 3, -3e-5), contact(1, 2, gap)}, {}, 0.002);
  // Step 3: nothing touches.
  tally.add_step({contact(2, 3, 2 * gap)}, {}, 0.003);
  // Step 4: (0, 3) again.
  tally.add_step({contact(0, 3, 0.0)}, {}, 0.004);

  EXPECT_EQ(tally.steps_touching(), 3);
  const std::vector<ContactTally::Pair> pairs = tally.pairs();
  ASSERT_EQ(pairs.size(), 2u);  // (2, 3) never came within the gap
  // Both touched in 2 steps: the tie goes by the first component.
  EXPECT_EQ(pairs[0].a, 0);
  EXPECT_EQ(pairs[0].b, 3);
  EXPECT_EQ(pairs[0].steps, 2);
  EXPECT_EQ(pairs[0].first, 0.002);
  EXPECT_EQ(pairs[0].last, 0.004);
  EXPECT_DOUBLE_EQ(pairs[0].deepest, 3e-5);
  EXPECT_EQ(pairs[1].a, 1);
  EXPECT_EQ(pairs[1].b, 2);
  EXPECT_EQ(pairs[1].steps, 2);  // not 3: its two contacts of step 1 count once
  EXPECT_EQ(pairs[1].first, 0.001);
  EXPECT_EQ(pairs[1].last, 0.002);
  EXPECT_DOUBLE_EQ(pairs[1].deepest, 1e-5);
  // The components of the pairs touching at or after a time: (0, 3) last at 0.004, (1, 2) at 0.002.
  std::vector<std::uint8_t> touching;
  tally.components_touching_since(0.003, 5, touching);
  EXPECT_EQ(touching, (std::vector<std::uint8_t>{1, 0, 0, 1, 0}));
  tally.components_touching_since(0.002, 5, touching);
  EXPECT_EQ(touching, (std::vector<std::uint8_t>{1, 1, 1, 1, 0}));
}

TEST(ContactTally, CountsAPairPushedApartThoughNeverThatClose) {
  ContactTally tally;
  // A knock stopped 0.3 mm short by its impulse, then (next step) the pair within the gap: 2 steps.
  tally.add_step({contact(1, 2, 3e-4)}, {{1, 2}, {1, 2}}, 0.001);
  tally.add_step({contact(1, 2, 5e-5)}, {}, 0.002);
  // A pushed pair with no contact listed (the look after the impulses dropped it).
  tally.add_step({}, {{3, 4}}, 0.003);
  EXPECT_EQ(tally.steps_touching(), 3);
  const std::vector<ContactTally::Pair> pairs = tally.pairs();
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].a, 1);
  EXPECT_EQ(pairs[0].steps, 2);
  EXPECT_EQ(pairs[0].first, 0.001);
  EXPECT_EQ(pairs[0].deepest, 0.0);  // never overlapped
  EXPECT_EQ(pairs[1].a, 3);
  EXPECT_EQ(pairs[1].b, 4);
  EXPECT_EQ(pairs[1].steps, 1);
}

TEST(ContactTally, OrdersThePairsByHowOftenTheyTouched) {
  ContactTally tally;
  tally.add_step({contact(4, 5, 0.0)}, {}, 0.001);
  tally.add_step({contact(4, 5, 0.0), contact(1, 7, 0.0)}, {}, 0.002);
  tally.add_step({contact(4, 5, 0.0), contact(1, 7, 0.0), contact(2, 3, 0.0)}, {}, 0.003);
  const std::vector<ContactTally::Pair> pairs = tally.pairs();
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].a, 4);
  EXPECT_EQ(pairs[0].steps, 3);
  EXPECT_EQ(pairs[1].a, 1);
  EXPECT_EQ(pairs[1].steps, 2);
  EXPECT_EQ(pairs[2].a, 2);
  EXPECT_EQ(pairs[2].steps, 1);
}

// The balls are drawn 10 degrees apart, swing together, bounce a few times (e = 0.3) and then lean on
// each other. The first knock comes a little before a quarter swing of a 0.5 m pendulum (about 0.35 s);
// from 2 s on they touch in every step, no deeper than a resting contact is left (the 0.05 mm slop).
TEST(ContactTally, TheLeaningBallsTouchFromTheirFirstKnockOn) {
  const Model model = compile(parse_mobile_text(test::kLeaningBalls));
  Simulation sim(model);
  ContactTally whole, late;
  for (int step = 0; step < 3000; ++step) {
    ASSERT_TRUE(sim.step());
    whole.add_step(sim.contacts(), sim.pushed_pairs(), sim.state().time);
    if (step >= 2000) late.add_step(sim.contacts(), sim.pushed_pairs(), sim.state().time);
  }
  const std::vector<ContactTally::Pair> pairs = whole.pairs();
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(model.names[pairs[0].a], "left");
  EXPECT_EQ(model.names[pairs[0].b], "right");
  EXPECT_GT(pairs[0].first, 0.25);
  EXPECT_LT(pairs[0].first, 0.45);
  EXPECT_DOUBLE_EQ(pairs[0].last, sim.state().time);
  EXPECT_EQ(whole.steps_touching(), pairs[0].steps);
  ASSERT_EQ(late.pairs().size(), 1u);
  EXPECT_EQ(late.pairs()[0].steps, 1000);
  EXPECT_LT(late.pairs()[0].deepest, 1e-4);
  std::printf("leaning balls: first knock at %.3f s, touching in %lld of 3000 steps\n", pairs[0].first,
              pairs[0].steps);
}

}  // namespace
}  // namespace aloft
