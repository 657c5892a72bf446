// The shipped mobiles: they hang still where designed, their joints hold, and runs are deterministic.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>

#include "aloft/simulation.hpp"
#include "support/presets.hpp"

namespace aloft {
namespace {

class Preset : public ::testing::TestWithParam<const char*> {};

TEST_P(Preset, BalancedPresetStaysInItsDesignedPose) {
  const Model model = load_mobile(test::preset_path(GetParam()));
  EXPECT_LT(model.balance.max_imbalance, 1e-6);
  Simulation sim(model);
  double worst_degrees = 0;
  for (int k = 0; k < 60000; ++k) {  // 60 s
    ASSERT_TRUE(sim.step());
    if (k % 100 == 0)
      for (int i = 1; i < model.count; ++i)
        worst_degrees = std::max(worst_degrees, sim.state().orientation[i].angularDistance(model.rest_orientation[i]) *
                                                    180.0 / std::numbers::pi);
  }
  // 0.1 degree (the requirement); balance leaves at most 1e-6 m of lever, i.e. ~1e-5 degree of tilt.
  EXPECT_LT(worst_degrees, 0.1);
  std::printf("%s: largest turn from the designed pose over 60 s %.3g degrees\n", GetParam(), worst_degrees);
}

TEST_P(Preset, JointsHoldForTenMinutesOfSwinging) {
  // Unbalanced (mode "none") so that it swings hard for the whole ten minutes.
  const Model model = test::load_preset(GetParam(), BalanceMode::None);
  Simulation sim(model);
  double worst = 0;
  for (int k = 0; k < 600000; ++k) {  // 10 min at 1 ms
    ASSERT_TRUE(sim.step());
    if (k % 50 == 0) worst = std::max(worst, max_joint_separation(model, sim.state()));
  }
  // 1e-6 m (the requirement): each step closes the joints to 1e-7 m per coordinate at 1 ms
  // (Simulation::joint_tolerance), so at most 1.7e-7 m apart; measured 1.6e-7 m.
  EXPECT_LT(worst, 1e-6);
  std::printf("%s: largest joint separation over 10 min %.3g m\n", GetParam(), worst);
}

TEST_P(Preset, SameFileSameTrajectoryBitForBit) {
  const Model a = test::load_preset(GetParam(), BalanceMode::None);
  const Model b = test::load_preset(GetParam(), BalanceMode::None);
  Simulation sa(a), sb(b);
  for (int k = 0; k < 3000; ++k) {
    ASSERT_TRUE(sa.step());
    ASSERT_TRUE(sb.step());
  }
  for (int i = 0; i < a.count; ++i) {
    EXPECT_EQ(0, std::memcmp(sa.state().position[i].data(), sb.state().position[i].data(), 3 * sizeof(double)));
    EXPECT_EQ(0, std::memcmp(sa.state().orientation[i].coeffs().data(), sb.state().orientation[i].coeffs().data(),
                             4 * sizeof(double)));
  }
}

INSTANTIATE_TEST_SUITE_P(Shipped, Preset, ::testing::Values("steel-fish", "southern-cross"),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name;
                         });

TEST(Simulation, NonFiniteStateIsReportedWithComponentAndTime) {
  const Model model = load_mobile(test::preset_path("steel-fish"));
  Simulation sim(model);
  ASSERT_TRUE(sim.advance(0.01));
  const State before = sim.state();
  sim.loads().force[3] = Vec3(std::nan(""), 0, 0);
  EXPECT_FALSE(sim.step());
  ASSERT_TRUE(sim.failure().has_value());
  // The NaN spreads through the joints within the step, so the first non-finite component in tree
  // order is named (any of them is a fair answer); the time is the failed step's.
  const int bad = sim.failure()->component;
  ASSERT_GE(bad, 1);
  EXPECT_EQ(sim.failure()->component_name, model.names[bad]);
  EXPECT_NEAR(sim.failure()->time, 0.011, 1e-12);
  EXPECT_NE(sim.failure()->message.find(model.names[bad]), std::string::npos);
  EXPECT_NE(sim.failure()->message.find("t = 0.011"), std::string::npos);
  EXPECT_NE(sim.failure()->message.find("NaN or infinite"), std::string::npos) << sim.failure()->message;
  // The last finite state is kept.
  EXPECT_EQ(sim.state().time, before.time);
  EXPECT_TRUE(sim.state().position[3].allFinite());
}

// A simulation whose loads() was never asked for skips reading them (simulation.hpp): the same motion,
// bit for bit, as one whose loads were asked for and left at zero; and loads written through a reference
// kept from the first call act from then on.
TEST(Simulation, LoadsActFromTheFirstTimeTheyAreAskedFor) {
  const Model model = load_mobile(test::preset_path("steel-fish"));
  Simulation untouched(model), asked(model), pushed(model);
  asked.loads();
  ExternalLoads& held = pushed.loads();
  for (Simulation* sim : {&untouched, &asked, &pushed}) ASSERT_TRUE(sim->advance(0.05));
  held.force[3] = Vec3(0.01, 0, 0);  // N, sideways
  for (Simulation* sim : {&untouched, &asked, &pushed}) ASSERT_TRUE(sim->advance(0.05));
  for (int i = 1; i < model.count; ++i) {
    EXPECT_EQ(untouched.state().position[i], asked.state().position[i]) << model.names[i];
    EXPECT_EQ(untouched.state().angular[i], asked.state().angular[i]) << model.names[i];
  }
  // The balanced Steel Fish at rest does not move by itself (to rounding, ~1e-15 m); pushed for 0.05 s
  // by 0.01 N, component 3 moves by a good fraction of (F / m) t^2 / 2, far more than 1e-6 m.
  EXPECT_LT((untouched.state().position[3] - model.rest_position[3]).norm(), 1e-9);
  EXPECT_GT((pushed.state().position[3] - untouched.state().position[3]).norm(), 1e-6);
}

// A component spun far beyond what any step can follow (1e6 rad/s: 3.9 rad even in a 1/256 ms step,
// beyond the step-size rule's 0.2 rad) stops the simulation with a report that names it and says why,
// not a joint that failed to close nor the first component in the tree.
TEST(Simulation, ASpinNoStepCanFollowIsReportedWithItsComponent) {
  const Model model = load_mobile(test::preset_path("steel-fish"));
  Simulation sim(model);
  ASSERT_TRUE(sim.advance(0.01));
  const int spinner = 5;
  sim.mutable_state().angular[spinner] = Vec3(0, 1e6, 0);
  const double before = sim.state().time;
  EXPECT_FALSE(sim.step());
  ASSERT_TRUE(sim.failure().has_value());
  EXPECT_EQ(sim.failure()->component, spinner);
  EXPECT_EQ(sim.failure()->component_name, model.names[spinner]);
  const std::string& message = sim.failure()->message;
  EXPECT_NE(message.find("'" + model.names[spinner] + "' spins too fast"), std::string::npos) << message;
  EXPECT_EQ(sim.state().time, before);
}

}  // namespace
}  // namespace aloft
