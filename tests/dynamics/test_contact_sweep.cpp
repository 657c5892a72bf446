// The sampled check of a contact's motion through a step (src/dynamics/contact_sweep.hpp): a bar (a
// 12 cm wire, 0.5 mm radius) moving and spinning beside a 2 mm pane, each motion checked by
// sweep_contact and scanned finely (200 poses through the step) for the overlap it really reaches.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "aloft/collision.hpp"
#include "aloft/model.hpp"
#include "aloft/spec.hpp"
#include "dynamics/contact_sweep.hpp"
#include "dynamics/rotation.hpp"

namespace aloft {
namespace {

constexpr double kStep = 1e-3;         // s
constexpr double kThinnest = 5e-4;     // m: the bar's radius (the pane is 1 mm on each side)
constexpr double kAllowed = 2.5e-4;    // m: half of it, what Simulation lets a step deepen

// The pane hangs in the plane x = 0.05 (its faces at x = 0.049 and 0.051), 0.2 m square about y = 0.5;
// the bar hangs from the hook far above it (joint_tolerance: the bar is a lone wire, with no thread), and
// is placed anywhere by the tests.
const char* const kBarAndPane = R"({
  "name": "bar and pane", "joint_tolerance": 0.5,
  "components": [
    {"name": "hook", "fixed": true, "shapes": [{"sphere": {"center": [0, 1.2, 0], "radius": 0.01}}]},
    {"name": "pane", "parent": "hook", "joint": [0.05, 1.19, 0], "shapes": [
      {"wire": {"from": [0.05, 1.19, 0], "to": [0.05, 0.6, 0], "radius": 0.0005}},
      {"plate": {"plane": {"origin": [0.05, 0.5, 0], "u": [0, 0, 1], "v": [0, 1, 0]}, "thickness": 0.002,
                 "points": [[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]]}}]},
    {"name": "bar", "parent": "hook", "joint": [-0.2, 1.19, 0], "shapes": [
      {"wire": {"from": [-0.26, 1.0, 0], "to": [-0.14, 1.0, 0], "radius": 0.0005}}]}]})";

struct Scene {
  Model model = compile(parse_mobile_text(kBarAndPane));
  CollisionDetector detector{model};
  int pane = -1, bar = -1;
  Scene() {
    for (int i = 0; i < model.count; ++i) {
      if (model.names[i] == "pane") pane = i;
      if (model.names[i] == "bar") bar = i;
    }
  }
};

// The bar's swept body: centre of mass at `position`, turned by `orientation`, moving at v, turning at w
// (constant over the step: the drift's w_m), its travel from its whole reach.
SweptBody bar_body(const Scene& s, const Vec3& position, const Quat& orientation, const Vec3& v, const Vec3& w) {
  SweptBody body;
  body.position = position;
  body.orientation = orientation;
  body.velocity = v;
  body.drift_angular = w;
  body.travel = kStep * (v.norm() + w.norm() * s.detector.reach(s.bar));
  return body;
}

SweptBody pane_body(const Scene& s) {
  SweptBody body;
  body.position = s.model.rest_position[s.pane];
  body.orientation = s.model.rest_orientation[s.pane];
  return body;  // at rest: moves nowhere
}

// The bar's overlap with the pane (m, > 0 overlapping) at time t into the step.
double overlap_at(const Scene& s, const SweptBody& bar, const SweptBody& pane, double t) {
  Vec3 xb, xp;
  Quat qb, qp;
  swept_pose(bar, t, xb, qb);
  swept_pose(pane, t, xp, qp);
  return -s.detector.signed_distance(s.bar, xb, qb, s.pane, xp, qp, 1e-3);
}

TEST(ContactSweep, TheLastSampleIsTheDriftsPose) {
  // x + h v and exp(h w_m) q: what drift_pass gives a body before any correction.
  SweptBody body;
  body.position = Vec3(0.1, 1.0, -0.2);
  body.orientation = Quat(0.3, -0.5, 0.7, 0.1).normalized();
  body.velocity = Vec3(0.4, -1.0, 2.0);
  body.drift_angular = Vec3(30, -20, 5);
  Vec3 x;
  Quat q;
  swept_pose(body, kStep, x, q);
  EXPECT_TRUE(x.isApprox(body.position + kStep * body.velocity, 1e-15));
  const Quat expected = turned(kStep * body.drift_angular, body.orientation);
  EXPECT_NEAR(std::abs(q.dot(expected)), 1.0, 1e-15);
  body.fixed = true;
  swept_pose(body, kStep, x, q);
  EXPECT_EQ(x, body.position);
}

TEST(ContactSweep, AWireDrivenThroughThePaneInOneStepIsCaught) {
  // The bar along z, 0.5 mm from the pane's near face, at 4 m/s along +x: in the step it passes right
  // through (its far side ends 0.5 mm beyond the far face). The poses at the start and the end both have
  // the pieces apart; the samples in between see the bar inside.
  Scene s;
  const Quat along_z(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()));
  const Vec3 start(0.049 - 0.0005 - 0.0005, 0.5, 0.0);
  const SweptBody bar = bar_body(s, start, along_z * s.model.rest_orientation[s.bar], Vec3(4.0, 0, 0), Vec3::Zero());
  const SweptBody pane = pane_body(s);
  ASSERT_LT(overlap_at(s, bar, pane, 0.0), 0.0);
  ASSERT_LT(overlap_at(s, bar, pane, kStep), 0.0) << "the end pose alone shows nothing";
  const SweepResult r = sweep_contact(s.detector, s.bar, bar, s.pane, pane, kStep, 0.0, kAllowed, kThinnest);
  EXPECT_FALSE(r.shallow);
  EXPECT_GT(r.deepest, kAllowed);
  // The same motion at a tenth of the speed stops short of the face: shallow, in one sample or a few.
  SweptBody slow = bar;
  slow.velocity = Vec3(0.4, 0, 0);
  slow.travel = kStep * 0.4;
  const SweepResult ok = sweep_contact(s.detector, s.bar, slow, s.pane, pane, kStep, 0.0, kAllowed, kThinnest);
  EXPECT_TRUE(ok.shallow);
  EXPECT_EQ(ok.deepest, 0.0);
}

TEST(ContactSweep, NeverAcceptsAMotionThatGetsPastTheThinnestMiddleOrEndsTooDeep) {
  // 2000 random motions of the bar near the pane's face or edge: at 0 to 6 m/s and 0 to 60 rad/s, touching
  // or up to 1 mm off or 0.2 mm in. Claims, against the fine scan: an accepted motion never overlaps by more
  // than the thinnest half-width at any scanned time (nothing reaches the bar's middle), and ends no deeper
  // than it started plus `allowed`; a motion whose end is too deep is never accepted. The narrow phase
  // measures overlaps to ~1e-9 m here (closed forms and exact polytope axes); 1e-8 m of slack.
  Scene s;
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0), sym(-1.0, 1.0);
  std::normal_distribution<double> g;
  const SweptBody pane = pane_body(s);
  int accepted = 0, rejected = 0, accepted_fast = 0, samples = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Quat orientation = Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
    // Place the bar so that its lowest point along -x is at the chosen gap from the near face, over the
    // face (most trials) or by the edge.
    const Mat3 r = orientation.toRotationMatrix();
    const Vec3 axis = r * (s.model.rest_orientation[s.bar].conjugate() * Vec3::UnitX());
    const double half = 0.06;
    const double reach_x = half * std::abs(axis.x()) + 0.0005 * std::sqrt(std::max(0.0, 1 - axis.x() * axis.x()));
    const double gap = -2e-4 + 1.2e-3 * u(rng);
    const double z = trial % 3 == 0 ? 0.1 + 0.01 * sym(rng) : 0.08 * sym(rng);
    const Vec3 position(0.049 - gap - reach_x, 0.5 + 0.05 * sym(rng), z);
    const Vec3 v = 6.0 * u(rng) * Vec3(g(rng), g(rng), g(rng)).normalized();
    const Vec3 w = 60.0 * u(rng) * Vec3(g(rng), g(rng), g(rng)).normalized();
    const SweptBody bar = bar_body(s, position, orientation, v, w);
    const double start = std::max(0.0, overlap_at(s, bar, pane, 0.0));
    const SweepResult result = sweep_contact(s.detector, s.bar, bar, s.pane, pane, kStep, start, kAllowed, kThinnest);
    double worst = 0;
    for (int k = 1; k <= 200; ++k) worst = std::max(worst, overlap_at(s, bar, pane, kStep * k / 200));
    const double end = overlap_at(s, bar, pane, kStep);
    samples += result.samples;
    if (result.shallow) {
      ++accepted;
      if (bar.travel > 5e-4) ++accepted_fast;
      ASSERT_LE(worst, kThinnest + 1e-8) << "trial " << trial << ": accepted, but " << worst << " m deep on the way";
      ASSERT_LE(end, start + kAllowed + 1e-8) << "trial " << trial;
    } else {
      ++rejected;
    }
    if (end > start + kAllowed + 1e-8) {
      ASSERT_FALSE(result.shallow) << "trial " << trial;
    }
  }
  // Both outcomes occur often, and fast motions (beyond Simulation's 0.5 mm travel limit) are accepted:
  // the check is what lets a step go on where the bounds alone would halve it.
  std::printf("%d accepted (%d travelling over 0.5 mm), %d rejected, %.1f samples per check\n", accepted,
              accepted_fast, rejected, static_cast<double>(samples) / 2000);
  EXPECT_GT(accepted, 500);
  EXPECT_GT(rejected, 300);
  EXPECT_GT(accepted_fast, 300);
}

}  // namespace
}  // namespace aloft
