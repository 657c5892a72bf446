// The step-size rule (src/dynamics/step_size_rule.hpp): its error estimate against the drift's actual
// error, its shortcut for slow bodies, its anchor check, and whole runs of a thin fast spinner and a
// generic fast tumbler against a reference at a 32 times smaller step.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "aloft/simulation.hpp"
#include "dynamics/step_size_rule.hpp"
#include "support/model_builder.hpp"

namespace aloft {
namespace {

// A light bar as the breeze leaves them in a generated mobile (performance.md, "Halvings"): principal
// moments (kg m^2), least about body x (its axis).
const Vec3 kBarMoments(6.6e-9, 2.0e-7, 2.1e-7);
// A generic body: moments 1 : 2 : 3.
const Vec3 kGenericMoments(1e-3, 2e-3, 3e-3);

// One body of moments `moments` on a ball joint at its own centre of mass, no gravity, no damping, no
// collisions: the joint holds the centre still and exerts no torque, so a step is exactly the drift of a
// free rigid body, and L (world) is conserved.
Model free_body(const Vec3& moments) {
  Model m = test::empty_model(2);
  m.parent[1] = 0;
  m.mass[1] = 0.01;
  m.principal_moments[1] = moments;
  m.rest_orientation[1] = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  m.rest_position[1] = Vec3(0, 1, 0);
  m.joint_world[1] = m.rest_position[1];
  m.gravity = Vec3::Zero();
  m.damping = DampingSpec{};
  m.contact.enabled = false;
  test::finish_model(m);
  return m;
}

// The model's rest pose with body 1 turning at `body_angular` (rad/s, body frame).
State spinning(const Model& model, const Vec3& body_angular) {
  State s = rest_state(model);
  s.angular[1] = s.orientation[1] * body_angular;
  return s;
}

Mat3 world_inertia(const Model& model, const State& state, int i) {
  const Mat3 r = state.orientation[i].toRotationMatrix();
  return r * model.principal_moments[i].asDiagonal() * r.transpose();
}

// The rotation vector (rad, world) that takes orientation b to orientation a.
Vec3 rotation_between(const Quat& a, const Quat& b) {
  const Eigen::AngleAxisd d(a * b.conjugate());
  return d.angle() * d.axis();
}

TEST(StepSizeRule, DriftErrorEstimateIsTheDriftsActualError) {
  struct Case {
    const char* name;
    Vec3 moments, body_angular;
  };
  // The bar spinning about its axis with a tumble (47 rad/s: the fastest body at 127 components), and a
  // generic body tumbling at 44 rad/s.
  const Case cases[] = {{"bar", kBarMoments, Vec3(-47.2, 1.8, -1.4)}, {"generic", kGenericMoments, Vec3(30, 25, -20)}};
  for (const Case& c : cases) {
    for (const double h : {1e-3, 5e-4}) {
      const Model model = free_body(c.moments);
      const State start = spinning(model, c.body_angular);
      Simulation one(model, start);
      one.set_timestep(h);
      ASSERT_TRUE(one.step());
      Simulation reference(model, start);
      reference.set_timestep(h / 64);
      for (int k = 0; k < 64; ++k) ASSERT_TRUE(reference.step());
      const Vec3 actual = rotation_between(one.state().orientation[1], reference.state().orientation[1]);
      const Mat3 inertia = world_inertia(model, start, 1);
      const Vec3 estimate = drift_error(start.angular[1], inertia, inertia.inverse(), h);
      std::printf("%s h = %g s: actual error %.4e rad, estimate %.4e rad, difference %.2e of it\n", c.name, h,
                  actual.norm(), estimate.norm(), (actual - estimate).norm() / estimate.norm());
      // The estimate is the O(h^3) term; what is left is O(h^4), relatively O(h |w|) with a small constant:
      // 2 % at h |w| = 0.047 (measured against an RK4 integration), 1 % at half the step. 5 % leaves room
      // for the reference's own error (64 steps of (h/64)^3: 1/4096 of the estimate).
      EXPECT_LT((actual - estimate).norm(), 0.05 * estimate.norm()) << c.name << " h = " << h;
      // And the error is the drift's, not rounding: well above 1e-12 rad.
      EXPECT_GT(estimate.norm(), 1e-8);
    }
  }
}

// Random bodies with moments obeying the triangle inequality, from nearly equal to 1 : 30 : 31.
Vec3 random_moments(std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double a = 0.03 + unit(rng), b = 0.03 + unit(rng);
  const double c = std::abs(a - b) + (a + b - std::abs(a - b)) * unit(rng);
  return 1e-4 * Vec3(a, b, std::max(c, 1e-3));
}

TEST(StepSizeRule, AcceptsWhatTheOldRuleAcceptedUpToItsSampling) {
  // Each body's drift tolerance is the largest error of a 0.05 rad turn about any axis (the old rule's
  // limit), found from 96 sampled axes. So a 0.05 rad turn about a random axis is within it, up to what
  // the sampling misses near the maximum: axes 0.3 rad apart miss a smooth maximum by a few percent;
  // 10 % is a bound on that.
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  double largest = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Model model = free_body(random_moments(rng));
    const StepSizeRule rule(model);
    const State start = rest_state(model);
    const Mat3 inertia = world_inertia(model, start, 1);
    const double h = 1e-3;
    const std::vector<Mat3> inertias{Mat3::Identity(), inertia}, inverses{Mat3::Identity(), inertia.inverse()};
    std::vector<Vec3> angular(2, Vec3::Zero()), arms(2, Vec3::Zero());
    angular[1] = Vec3(normal(rng), normal(rng), normal(rng)).normalized() * (kOldTurnLimit / h);
    largest = std::max(largest, rule.measure(h, angular, inertias, inverses, arms, arms).drift_error);
  }
  std::printf("largest error of a 0.05 rad turn: %.4f of the body's tolerance\n", largest);
  EXPECT_LE(largest, 1.1);
  // And the sampled maximum is not far below the true one either way: some random axis comes within
  // 20 % of it (3000 random axes over 3000 bodies; a loose check that the tolerance is not inflated).
  EXPECT_GT(largest, 0.8);
}

TEST(StepSizeRule, ShortcutForSlowBodiesNeverHidesAnError) {
  // accepts() skips the error estimate of a body turning less than sqrt(quiet_turn_squared) per step;
  // there the estimate must be within the body's tolerance for every axis of turn and every body.
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  double closest = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Model model = free_body(random_moments(rng));
    const StepSizeRule rule(model);
    const double quiet = rule.quiet_turn_squared(1);
    ASSERT_TRUE(std::isfinite(quiet) && quiet > 0);
    const State start = rest_state(model);
    const Mat3 inertia = world_inertia(model, start, 1);
    const double h = 1e-3;
    std::vector<Vec3> angular(2, Vec3::Zero()), arms(2, Vec3::Zero());
    angular[1] = Vec3(normal(rng), normal(rng), normal(rng)).normalized() * (std::sqrt(quiet) / h);
    const std::vector<Mat3> inertias{Mat3::Identity(), inertia}, inverses{Mat3::Identity(), inertia.inverse()};
    const StepSizeMeasures m = rule.measure(h, angular, inertias, inverses, arms, arms);
    closest = std::max(closest, m.drift_error);
    // The bound behind the shortcut is rigorous for the O(h^3) term; 1 + 1e-12 for rounding.
    ASSERT_LE(m.drift_error, 1.0 + 1e-12) << "moments " << model.principal_moments[1].transpose();
  }
  std::printf("largest error at the shortcut's limit: %.3f of the tolerance\n", closest);
}

TEST(StepSizeRule, AnchorsTurningFastHalveTheStepEvenWhenTheDriftIsExact) {
  // A body with equal principal moments has an exact drift (w' = 0) at any rate; what limits its step is
  // the turn of its joint anchor, here 0.1 m off its centre along body x.
  Model model = free_body(Vec3(1e-4, 1e-4, 1e-4));
  model.joint_in_child[1] = Vec3(0.1, 0, 0);
  const StepSizeRule rule(model);
  const double h = 1e-3;
  const std::vector<Mat3> inertias(2, 1e-4 * Mat3::Identity()), inverses(2, 1e4 * Mat3::Identity());
  std::vector<Vec3> angular(2, Vec3::Zero()), child_arm(2, Vec3(0.1, 0, 0)), parent_arm(2, Vec3::Zero());
  // 150 rad/s about the anchor's own line: the anchor does not turn; 0.15 rad per step is within kMaxTurn.
  angular[1] = Vec3(150, 0, 0);
  EXPECT_TRUE(rule.accepts(h, angular, inertias, inverses, child_arm, parent_arm));
  // The same rate about a perpendicular axis turns the anchor 0.15 rad, 1.5 times kMaxAnchorTurn.
  angular[1] = Vec3(0, 150, 0);
  EXPECT_FALSE(rule.accepts(h, angular, inertias, inverses, child_arm, parent_arm));
  EXPECT_NEAR(rule.measure(h, angular, inertias, inverses, child_arm, parent_arm).anchor_turn, 1.5, 1e-12);
  // Half that rate is within it.
  angular[1] = Vec3(0, 75, 0);
  EXPECT_TRUE(rule.accepts(h, angular, inertias, inverses, child_arm, parent_arm));
  // Faster than kMaxTurn (0.2 rad per step), even about the anchor's line, and non-finite: refused.
  angular[1] = Vec3(250, 0, 0);
  EXPECT_FALSE(rule.accepts(h, angular, inertias, inverses, child_arm, parent_arm));
  angular[1] = Vec3(NAN, 0, 0);
  EXPECT_FALSE(rule.accepts(h, angular, inertias, inverses, child_arm, parent_arm));
}

// Runs the free body `model` from `start` for `seconds` at the model's step with the rule, and at a 32
// times smaller fixed step as the reference, comparing them after every full step.
struct RunComparison {
  double mass_error = 0;         // largest orientation error in the rule's measure sqrt(d^T I d / (tr I / 2)), rad
  double orientation_error = 0;  // largest orientation error |d|, rad
  double energy_error = 0;       // largest kinetic-energy difference over the initial kinetic energy
  double energy_factor = 0;      // largest 2 |w x L| / (w.L) along the reference (1/rad), see below
  long long halvings = 0;        // of the run with the rule
  long long steps = 0;
};
RunComparison compare_with_reference(const Model& model, const State& start, double seconds) {
  Simulation run(model, start), reference(model, start);
  const double h = model.timestep;
  reference.set_timestep(h / 32);
  const double kinetic = kinetic_energy(model, start);
  RunComparison out;
  out.steps = std::llround(seconds / h);
  for (long long k = 0; k < out.steps; ++k) {
    EXPECT_TRUE(run.step());
    for (int j = 0; j < 32; ++j) EXPECT_TRUE(reference.step());
    const Vec3 d = rotation_between(run.state().orientation[1], reference.state().orientation[1]);
    const Mat3 inertia = world_inertia(model, reference.state(), 1);
    out.orientation_error = std::max(out.orientation_error, d.norm());
    out.mass_error = std::max(out.mass_error, std::sqrt(d.dot(inertia * d) / (0.5 * inertia.trace())));
    out.energy_error = std::max(
        out.energy_error, std::abs(kinetic_energy(model, run.state()) - kinetic_energy(model, reference.state())) / kinetic);
    const Vec3 w = reference.state().angular[1], momentum = inertia * w;
    out.energy_factor = std::max(out.energy_factor, 2 * w.cross(momentum).norm() / w.dot(momentum));
  }
  out.halvings = run.subdivisions();
  // The reference is a fixed step: the rule never halves it.
  EXPECT_EQ(reference.subdivisions(), 0);
  return out;
}

// The bounds of a run, from the rule: every (sub)step errs by at most the body's tolerance in the rule's
// measure, and the motion below is periodic and stable (no separatrix nearby), so the errors add at
// most linearly: mass_error <= substeps x tolerance. The drift conserves L exactly, so the kinetic energy
// L.I^-1 L / 2 differs from the reference's only through the orientation: by d.(w x L) to first order,
// relatively at most |d| 2 |w x L| / (w.L); 1.2 times that allows for the second-order term (|d| is a few
// 1e-3 rad here).
void expect_within_bounds(const RunComparison& r, double tolerance, long long substeps) {
  EXPECT_LT(r.mass_error, substeps * tolerance);
  EXPECT_LT(r.energy_error, 1.2 * r.orientation_error * r.energy_factor);
}

TEST(StepSizeRule, ThinFastSpinnerKeepsItsStepAndStaysAccurate) {
  // The bar spinning at 100 rad/s about its axis of least inertia (0.1 rad per 1 ms step: twice what the
  // old |w| rule allowed, which halved every step) with a tumble of 2 rad/s, free, for 0.5 s.
  const Model model = free_body(kBarMoments);
  const RunComparison r = compare_with_reference(model, spinning(model, Vec3(100, 2, -1)), 0.5);
  const double tolerance = StepSizeRule(model).drift_tolerance(1);
  std::printf("spinner: %lld halvings in %lld steps, error %.3e rad in the rule's measure (bound %.3e), %.3e rad "
              "in all, energy %.3e (bound %.3e)\n",
              r.halvings, r.steps, r.mass_error, r.steps * tolerance, r.orientation_error, r.energy_error,
              1.2 * r.orientation_error * r.energy_factor);
  EXPECT_EQ(r.halvings, 0);
  expect_within_bounds(r, tolerance, r.steps);
}

TEST(StepSizeRule, GenericFastTumblerIsHalvedAndStaysAccurate) {
  // A 1 : 2 : 3 body tumbling at 100 rad/s about a generic axis: 0.1 rad per 1 ms step, whose drift error
  // is about 8 times the tolerance (the old rule's error at 0.05 rad); half steps are within it.
  const Model model = free_body(kGenericMoments);
  const RunComparison r = compare_with_reference(model, spinning(model, Vec3(70, 50, -50)), 0.5);
  const double tolerance = StepSizeRule(model).drift_tolerance(1);
  std::printf("tumbler: %lld halvings in %lld steps, error %.3e rad in the rule's measure (bound %.3e), %.3e rad "
              "in all, energy %.3e (bound %.3e)\n",
              r.halvings, r.steps, r.mass_error, (r.steps + r.halvings) * tolerance, r.orientation_error,
              r.energy_error, 1.2 * r.orientation_error * r.energy_factor);
  // Every step halved at least once (0.1 rad is over the limit; some half steps are too, as the axis of
  // turn moves in the body); each halving adds one substep.
  EXPECT_GE(r.halvings, r.steps);
  expect_within_bounds(r, tolerance, r.steps + r.halvings);
}

TEST(StepSizeRule, AStepStartsAsDeepAsTheLastOneHadToGo) {
  // The 1 : 2 : 3 body tumbling at 300 rad/s (0.3 rad per 1 ms step) needs its steps divided several
  // times. Trying the whole step and every coarser division first, each rejected, costs as many rejected
  // attempts per step as the first step shows (2^d - 1 for a uniform depth d). Starting where the last
  // step had to go leaves only the occasional try one level coarser (every fifth step: 2^(d-1)
  // rejections, a quarter to a half of 2^d - 1 for d >= 2, so under a quarter of the old count over
  // 99 steps means that most steps reject nothing).
  const Model model = free_body(kGenericMoments);
  Simulation sim(model, spinning(model, Vec3(210, 150, -150)));
  ASSERT_TRUE(sim.step());
  const long long first = sim.rejected_substeps();
  const long long first_halvings = sim.subdivisions();
  ASSERT_GE(first, 3) << "the step should need at least two halvings";
  for (int k = 0; k < 99; ++k) ASSERT_TRUE(sim.step());
  const long long later = sim.rejected_substeps() - first;
  std::printf("tumbler at 300 rad/s: %lld rejected in the first step, %lld in the next 99 (%lld halvings)\n",
              first, later, sim.subdivisions() - first_halvings);
  EXPECT_LT(later, 99 * first / 4);
  // Still as finely divided as the motion needs: at least as many substeps per step as the first had.
  EXPECT_GE(sim.subdivisions() - first_halvings, 99 * first_halvings * 3 / 4);
}

}  // namespace
}  // namespace aloft
