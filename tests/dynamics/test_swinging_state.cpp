// swinging_state (aloft/state.hpp): the benchmarks' start, which `aloft bench --start swinging:SEED`
// offers too. It must be a state the simulation can start from as it is (every joint together in
// position and in velocity), turn every moving component at a rate within [max_rate / 2, max_rate] in
// directions that cover the sphere, and be the same state for the same seed on every machine, since the
// recorded figures in docs/performance.md are timed from it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "aloft/generate.hpp"
#include "aloft/spec.hpp"
#include "aloft/state.hpp"

#include "support/presets.hpp"

namespace aloft {
namespace {

Model generated(int components) {
  GenerateOptions options;
  options.components = components;
  options.seed = 1;
  options.total_mass = 1.0;
  return compile(parse_mobile_text(generate_mobile(options), "generated.json"));
}

// Velocity (m/s, world) of the world point `point` carried by body i.
Vec3 point_velocity(const State& state, int i, const Vec3& point) {
  return state.velocity[i] + state.angular[i].cross(point - state.position[i]);
}

TEST(SwingingState, KeepsEveryJointTogetherAndTurnsEachComponentWithinTheRates) {
  for (const Model& model : {generated(1023), load_mobile(test::preset_path("steel-fish"))}) {
    const double max_rate = 0.5;  // rad/s
    const State state = swinging_state(model, max_rate, 3);
    const State rest = rest_state(model);
    EXPECT_EQ(state.position, rest.position);  // the designed pose itself
    EXPECT_EQ(state.velocity[0], Vec3::Zero());
    EXPECT_EQ(state.angular[0], Vec3::Zero());
    EXPECT_EQ(max_joint_separation(model, state), max_joint_separation(model, rest));
    for (int i = 1; i < model.count; ++i) {
      const double rate = state.angular[i].norm();
      // The draw is (0.5 + 0.5 u) max_rate, u in [0, 1); 1e-15 allows the rounding of the unit axis.
      EXPECT_GE(rate, 0.5 * max_rate * (1 - 1e-15)) << "component " << i;
      EXPECT_LT(rate, max_rate * (1 + 1e-15)) << "component " << i;
      // The joint's two sides move together: the parent's and the child's velocity at the joint agree.
      // Speeds are below 1 m/s here (0.5 rad/s over arms of a few metres at most), so a few roundings of
      // the cross products are below 1e-14 m/s.
      const Vec3 joint = joint_on_child(model, state, i);
      const Vec3 gap = point_velocity(state, i, joint) - point_velocity(state, model.parent[i], joint);
      EXPECT_LT(gap.norm(), 1e-14) << "component " << i;
    }
  }
}

// place_on_joints and set_velocities_keeping_joints, which build it: from any orientations and angular
// velocities (here every component turned 0.3 rad about its own axis, spinning at 2 rad/s), the joints
// hold in position and in velocity.
TEST(SwingingState, PlacingOnTheJointsKeepsThemTogetherInPositionAndVelocity) {
  const Model model = generated(127);
  State state = rest_state(model);
  for (int i = 1; i < model.count; ++i) {
    const Vec3 axis = Vec3(std::cos(i), std::sin(i), 0.5).normalized();  // spread, no two alike
    state.orientation[i] = (Quat(Eigen::AngleAxisd(0.3, axis)) * state.orientation[i]).normalized();
    state.angular[i] = 2.0 * axis;
  }
  const double apart_before = max_joint_separation(model, state);
  EXPECT_GT(apart_before, 1e-3);  // m: the turns opened the joints
  place_on_joints(model, state);
  // Joint arms of a metre or less and a few roundings each along a path of at most 7 joints: 1e-14 m.
  EXPECT_LT(max_joint_separation(model, state), 1e-14);
  set_velocities_keeping_joints(model, state);
  for (int i = 1; i < model.count; ++i) {
    // Speeds of a few m/s at most (2 rad/s over paths of a few metres): 1e-13 m/s is a few roundings.
    const Vec3 joint = joint_on_child(model, state, i);
    const Vec3 gap = point_velocity(state, i, joint) - point_velocity(state, model.parent[i], joint);
    EXPECT_LT(gap.norm(), 1e-13) << "component " << i;
  }
}

TEST(SwingingState, SpreadsTheTurnsOverEveryDirection) {
  const Model model = generated(1023);
  const State state = swinging_state(model, 0.5, 7);
  const int moving = model.count - 1;
  Vec3 mean_axis = Vec3::Zero();
  double mean_rate = 0;
  for (int i = 1; i < model.count; ++i) {
    mean_axis += state.angular[i].normalized() / moving;
    mean_rate += state.angular[i].norm() / moving;
  }
  // Uniform directions: each coordinate of a random unit vector has variance 1/3, so the mean of 1022
  // has a standard deviation of 0.018 per coordinate; 0.1 is more than 5 of them for the norm.
  EXPECT_LT(mean_axis.norm(), 0.1);
  // Rates uniform in [0.25, 0.5] rad/s: mean 0.375, standard deviation 0.072 / sqrt(1022) = 0.0023.
  EXPECT_NEAR(mean_rate, 0.375, 0.01);
}

TEST(SwingingState, TheSameSeedGivesTheSameStateAndAnotherSeedAnother) {
  const Model model = generated(127);
  const State a = swinging_state(model, 0.5, 7), b = swinging_state(model, 0.5, 7);
  EXPECT_EQ(a.angular, b.angular);
  EXPECT_EQ(a.velocity, b.velocity);
  const State c = swinging_state(model, 0.5, 1);
  int differ = 0;
  for (int i = 1; i < model.count; ++i) differ += c.angular[i] != a.angular[i];
  EXPECT_EQ(differ, model.count - 1);
  // The draw is splitmix64's, not a <random> distribution's (whose algorithms differ between standard
  // libraries): seed 7's first component turns at this angular velocity on every machine (the figures in
  // docs/performance.md start from it). 1e-15 rad/s allows a last-bit difference in cos, sin or sqrt.
  const Vec3 expected(-0.099129846498905216, 0.43691719549564789, 0.02069122117743127);
  EXPECT_LT((a.angular[1] - expected).norm(), 1e-15) << a.angular[1].transpose();
}

}  // namespace
}  // namespace aloft
