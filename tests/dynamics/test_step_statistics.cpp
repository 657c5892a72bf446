// Simulation::step_statistics: the profiling totals of how the (sub)steps were taken add up with the
// counts kept before them (subdivisions, rejected_substeps, joint_iterations), and each cause of a
// rejection is counted where it happened.
#include <gtest/gtest.h>

#include <random>

#include "aloft/model.hpp"
#include "aloft/simulation.hpp"
#include "aloft/spec.hpp"
#include "support/presets.hpp"
#include "support/shaking.hpp"

namespace aloft {
namespace {

// The invariants that hold after any run: every try is taken or rejected once, under one cause; every
// step's substeps are the leaves of its halvings (a step halved k times takes k + 1 substeps); the
// corrections by phase are all the Newton corrections (rejected_substeps() and joint_iterations() are
// derived from these totals); a spin rejection has at least one measure over its limit.
void expect_totals_add_up(const Simulation& sim, long long steps) {
  const StepStatistics& s = sim.step_statistics();
  EXPECT_EQ(s.attempts, s.accepted + sim.rejected_substeps());
  EXPECT_EQ(s.rejected_spin + s.rejected_contact_turn + s.rejected_joints + s.rejected_contact_motion,
            sim.rejected_substeps());
  EXPECT_EQ(s.accepted, steps + sim.subdivisions());
  EXPECT_EQ(s.joint_corrections + s.contact_pass_corrections + s.push_corrections, sim.joint_iterations());
  EXPECT_LE(s.rejected_spin, s.spin_turn_over + s.spin_anchor_over + s.spin_drift_over);
  EXPECT_LE(s.spin_turn_over, s.rejected_spin);
  EXPECT_LE(s.spin_anchor_over, s.rejected_spin);
  EXPECT_LE(s.spin_drift_over, s.rejected_spin);
  EXPECT_LE(s.pushes, s.accepted + s.rejected_contact_motion);  // a push is followed by the motion check
}

TEST(StepStatistics, ASwingWithoutContactsTakesEveryStepWhole) {
  const Model model = test::load_preset("steel-fish", BalanceMode::Mass);
  Simulation sim(model);
  sim.set_collisions(false);
  State& state = sim.mutable_state();
  for (int i = 1; i < model.count; ++i) state.angular[i] = Vec3(0, 0.5, 0);  // each arm turning gently
  const int steps = 500;
  for (int k = 0; k < steps; ++k) ASSERT_TRUE(sim.step()) << sim.failure()->message;
  const StepStatistics& s = sim.step_statistics();
  expect_totals_add_up(sim, steps);
  // Half a rad/s turns an arm 5e-4 rad per 1 ms step, far inside every limit of the step-size rule:
  // nothing is halved, and nothing of the collision response runs.
  EXPECT_EQ(s.attempts, steps);
  EXPECT_EQ(s.accepted, steps);
  EXPECT_EQ(s.contact_passes + s.pushes + s.contact_pass_corrections + s.push_corrections, 0);
}

TEST(StepStatistics, TheShakenSteelFishCountsItsRejectionsAndContactWork) {
  const Model model = test::load_preset("steel-fish", BalanceMode::Mass);
  Simulation sim(model);
  ASSERT_TRUE(sim.collisions());
  // The shaking of Collisions.SteelFishShakenHard... for 20 s: the arms swing through half a turn, knock
  // and spin, so that steps are halved and contacts are solved again after the joints' impulses.
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  const long long steps = 20000;
  for (int step = 0; step < steps; ++step) {
    test::shake(model, sim, rng, g, step);
    ASSERT_TRUE(sim.step()) << sim.failure()->message;
  }
  expect_totals_add_up(sim, steps);
  const StepStatistics& s = sim.step_statistics();
  std::printf("shaken steel fish, %lld steps: %lld tries, %lld taken; rejected %lld spin, %lld contact turn, "
              "%lld joints, %lld contact motion; corrections %lld / %lld / %lld; %lld contact passes, %lld pushes\n",
              steps, s.attempts, s.accepted, s.rejected_spin, s.rejected_contact_turn, s.rejected_joints,
              s.rejected_contact_motion, s.joint_corrections, s.contact_pass_corrections, s.push_corrections,
              s.contact_passes, s.pushes);
  // What the shaking must have made happen for the counts to mean anything.
  EXPECT_GT(sim.rejected_substeps(), 0);
  EXPECT_GT(s.contact_passes, 0);
  EXPECT_GT(s.pushes, 0);
}

}  // namespace
}  // namespace aloft
