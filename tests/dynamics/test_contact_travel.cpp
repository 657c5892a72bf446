// The bound on how much deeper a contact's pieces can get in one step (src/dynamics/contact_travel.hpp),
// against the step's own drift: two boxes (a plate and a small piece resting on or hovering over its
// face), random poses, velocities and spins up to what Simulation lets a step take, each moved exactly
// as the drift moves bodies, and their overlap measured after.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

#include "dynamics/contact_travel.hpp"

namespace aloft {
namespace {

constexpr double kStep = 1e-3;  // s

// exp(theta / 2) q: q turned by the rotation vector theta (rad, world).
Quat turned(const Vec3& theta, const Quat& q) {
  const double angle = theta.norm();
  if (angle == 0) return q;
  return (Quat(Eigen::AngleAxisd(angle, theta / angle)) * q).normalized();
}

// A box body: half extents (principal frame), mass properties, pose and velocities.
struct Box {
  Vec3 half;
  Vec3 moments;  // principal moments (kg m^2), of a solid box of 0.01 kg
  Vec3 position;
  Quat orientation;
  Vec3 velocity = Vec3::Zero(), angular = Vec3::Zero();

  Mat3 inertia() const {
    const Mat3 r = orientation.toRotationMatrix();
    return r * moments.asDiagonal() * r.transpose();
  }
  std::array<Vec3, 8> corners() const {
    std::array<Vec3, 8> c;
    const Mat3 r = orientation.toRotationMatrix();
    for (int k = 0; k < 8; ++k)
      c[k] = position +
             r * Vec3(k & 1 ? half.x() : -half.x(), k & 2 ? half.y() : -half.y(), k & 4 ? half.z() : -half.z());
    return c;
  }
  // The drift of Simulation (rattle's step 2): x' = x + h v; q' = exp(h w_m) q, w_m = I(q_m)^-1 I(q) w at
  // the half-way orientation q_m = exp(h w / 2) q.
  Box drifted(double h) const {
    Box next = *this;
    next.position = position + h * velocity;
    const Quat half_way = turned(0.5 * h * angular, orientation);
    const Mat3 rm = half_way.toRotationMatrix();
    const Mat3 midpoint_inverse_inertia = rm * moments.cwiseInverse().asDiagonal() * rm.transpose();
    next.orientation = turned(h * (midpoint_inverse_inertia * (inertia() * angular)), orientation);
    return next;
  }
  ContactSide side() const {
    ContactSide s;
    s.position = position;
    s.orientation = orientation;
    s.velocity = velocity;
    s.angular = angular;
    const Mat3 i = inertia();
    s.precession = i.inverse() * angular.cross(i * angular);
    s.reach = half.norm();
    s.near_low = -half;
    s.near_high = half;
    return s;
  }
};

Vec3 box_moments(const Vec3& half, double mass) {
  const Vec3 s = half.cwiseProduct(half);
  return mass / 3.0 * Vec3(s.y() + s.z(), s.x() + s.z(), s.x() + s.y());
}

// How far the two boxes overlap along the direction u (m; negative: apart by that much along u).
double overlap_along(const Box& a, const Box& b, const Vec3& u) {
  double low_a = INFINITY, high_b = -INFINITY;
  for (const Vec3& c : a.corners()) low_a = std::min(low_a, c.dot(u));
  for (const Vec3& c : b.corners()) high_b = std::max(high_b, c.dot(u));
  return high_b - low_a;
}

// A small box `a` (a sliver of plate or a bar) with its lowest corner, along the face normal n of the
// plate `b`, at signed distance `gap` from the face, above a point of the face: the contact between
// them, as the detector reports one (normal from b to a, point midway, distance the gap).
struct Scene {
  Box a, b;
  Contact contact;
};

Scene make_scene(std::mt19937& rng, double gap) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto random_orientation = [&] {
    return Quat(unit(rng), unit(rng), unit(rng), unit(rng)).normalized();
  };
  Scene s;
  Box& b = s.b;
  b.half = Vec3(0.04 + 0.02 * unit(rng), 0.001, 0.03 + 0.02 * unit(rng));  // a 2 mm plate
  b.moments = box_moments(b.half, 0.02);
  b.orientation = random_orientation();
  b.position = Vec3(0.1 * unit(rng), 1 + 0.1 * unit(rng), 0.1 * unit(rng));
  Box& a = s.a;
  a.half = Vec3(0.002 + 0.018 * (0.5 + 0.5 * unit(rng)), 0.0005 + 0.0015 * (0.5 + 0.5 * unit(rng)),
                0.002 + 0.018 * (0.5 + 0.5 * unit(rng)));
  a.moments = box_moments(a.half, 0.005);
  a.orientation = random_orientation();
  const Mat3 rb = b.orientation.toRotationMatrix();
  const Vec3 n = rb.col(1);  // b's face normal, from b towards a
  const Vec3 on_face = b.position + rb * Vec3(0.5 * b.half.x() * unit(rng), b.half.y(), 0.5 * b.half.z() * unit(rng));
  // Place a so that its lowest corner along n is at on_face + gap n.
  a.position = Vec3::Zero();
  double lowest = INFINITY;
  Vec3 lowest_corner = Vec3::Zero();
  for (const Vec3& c : a.corners())
    if (c.dot(n) < lowest) lowest = c.dot(n), lowest_corner = c;
  a.position = on_face + gap * n - lowest_corner;
  s.contact.a = 1;
  s.contact.b = 2;
  s.contact.normal = n;
  s.contact.distance = gap;
  s.contact.point = on_face + 0.5 * gap * n;
  return s;
}

// Random velocities: centres of mass up to `speed` (m/s), spins up to `spin` (rad/s), in random
// directions.
void set_random_motion(std::mt19937& rng, Box& box, double speed, double spin) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0), fraction(0.0, 1.0);
  const auto direction = [&] {
    Vec3 d;
    do d = Vec3(unit(rng), unit(rng), unit(rng));
    while (d.squaredNorm() > 1 || d.squaredNorm() < 1e-6);
    return d.normalized();
  };
  box.velocity = speed * fraction(rng) * direction();
  box.angular = spin * fraction(rng) * direction();
}

// After the drift, the pieces' overlap: the smaller of the overlaps along b's face normal and along a's
// side of the contact plane, each turned with its body (both bound the penetration depth from above).
double overlap_after(const Scene& s, double h) {
  const Box a = s.a.drifted(h), b = s.b.drifted(h);
  const Vec3 n_b = (b.orientation * s.b.orientation.conjugate()) * s.contact.normal;
  const Vec3 n_a = (a.orientation * s.a.orientation.conjugate()) * s.contact.normal;
  return std::min(overlap_along(a, b, n_b), overlap_along(a, b, n_a));
}

// 20000 random scenes, a moving at up to 2 m/s and spinning at up to `spin_a` (rad/s), b (fixed in every
// fourth) at up to 1 m/s and `spin_b`: the overlap after the drift never exceeds the bound. Returns how
// many trials deepened (by more than 1 micrometre) and the largest deepening over its bound.
struct BoundProbe {
  int deepened = 0;
  double tightest = 0;
};
BoundProbe probe_bound(unsigned seed, double spin_a, double spin_b) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> gap(-3e-4, 6e-4);
  BoundProbe probe;
  double worst_excess = -INFINITY;
  for (int trial = 0; trial < 20000; ++trial) {
    Scene s = make_scene(rng, gap(rng));
    set_random_motion(rng, s.a, 2.0, spin_a);
    set_random_motion(rng, s.b, trial % 4 == 0 ? 0.0 : 1.0, trial % 4 == 0 ? 0.0 : spin_b);  // b sometimes fixed
    const double before = overlap_along(s.a, s.b, s.contact.normal);
    EXPECT_NEAR(before, -s.contact.distance, 1e-12) << "the scene's gap, trial " << trial;
    if (!(std::abs(before + s.contact.distance) <= 1e-12)) break;  // one failure told is enough
    const double bound = contact_deepening_bound(s.contact, s.a.side(), s.b.side(), kStep, true);
    const double after = overlap_after(s, kStep);
    // The claim: no deeper than max(0, -d) + bound. Rounding: positions of order 1 m, 1e-15 m.
    const double excess = after - (std::max(0.0, -s.contact.distance) + bound);
    EXPECT_LE(excess, 1e-12) << "trial " << trial << ": overlap " << after << " m after, distance "
                             << s.contact.distance << " m before, bound " << bound << " m";
    if (!(excess <= 1e-12)) break;
    worst_excess = std::max(worst_excess, excess);
    if (after > std::max(0.0, -s.contact.distance) + 1e-6) {
      ++probe.deepened;
      probe.tightest = std::max(probe.tightest, (after - std::max(0.0, -s.contact.distance)) / bound);
    }
  }
  std::printf("spins up to %g and %g rad/s: deepened %d of 20000; largest deepening / bound %.3f; closest "
              "approach to the bound %.3g m\n", spin_a, spin_b, probe.deepened, probe.tightest, worst_excess);
  return probe;
}

TEST(ContactTravel, BoundsTheOverlapAfterTheDrift) {
  // Speeds up to 2 m/s and spins up to 50 rad/s: Simulation lets no component in contact turn more than
  // kOldTurnLimit = 0.05 rad in a step of 1 ms, save about an axis its near part lies along (below);
  // knocked pieces of the generated mobiles move at up to 1.5 m/s. Gaps from 0.3 mm of overlap to 0.6 mm
  // apart (the detection margin and the penetration seen).
  const BoundProbe probe = probe_bound(5, 50.0, 30.0);
  // The test must probe the bound, not pass far below it: many trials deepen, and the deepest comes near
  // the bound (the approach, the gap and the turn are taken to first order exactly; the curvature
  // allowance is generous, not loose). Measured: 7923 trials deepen, the largest by 1.000 of the bound.
  EXPECT_GT(probe.deepened, 2000);
  EXPECT_GT(probe.tightest, 0.9);
}

TEST(ContactTravel, BoundsTheOverlapAfterTheDriftOfTheFastestTurnAStepTakes) {
  // A component in contact may turn faster than kOldTurnLimit when its near part turns little (a wire
  // spinning about its own axis: Simulation::contacts_turn_slowly_enough); the step-size rule still holds
  // every body to kMaxTurn = 0.2 rad per step, 200 rad/s at 1 ms. The bound must hold up to there too,
  // where its second-order allowances are 16 times what they are at 50 rad/s. Measured: 8897 trials
  // deepen, the largest by 0.999 of the bound.
  const BoundProbe probe = probe_bound(6, 200.0, 200.0);
  EXPECT_GT(probe.deepened, 2000);
  EXPECT_GT(probe.tightest, 0.9);
}

TEST(ContactTravel, ATranslationCountsOnlyItsApproach) {
  // No turns: the bound is the approach alone, exactly what the drift does; a slide along the face
  // (1 m/s, 1 mm in the step) counts nothing.
  std::mt19937 rng(11);
  for (const double gap : {-2e-4, 0.0, 3e-4}) {
    Scene s = make_scene(rng, gap);
    const Mat3 rb = s.b.orientation.toRotationMatrix();
    s.a.velocity = 1.0 * rb.col(0) - 0.4 * s.contact.normal;  // sliding, approaching at 0.4 m/s
    const double bound = contact_deepening_bound(s.contact, s.a.side(), s.b.side(), kStep, true);
    EXPECT_NEAR(bound, std::max(0.0, 4e-4 - std::max(gap, 0.0)), 1e-15) << "gap " << gap;
    EXPECT_NEAR(overlap_after(s, kStep), -gap + 4e-4, 1e-12) << "gap " << gap;
    s.a.velocity = 1.0 * rb.col(0);
    // Zero but for the rounding of n . v (1 m/s along a tangent).
    EXPECT_NEAR(contact_deepening_bound(s.contact, s.a.side(), s.b.side(), kStep, true), 0.0, 1e-15);
  }
}

TEST(ContactTravel, ASpinAboutTheNormalCountsOnlyItsCurvature) {
  // A small plate lying flat on the face, spinning about the face normal at 40 rad/s: its corners
  // travel 0.4-0.8 mm in the step, along the face. None of that is towards the face: the bound is the
  // curvature allowance alone, a tenth of kMaxContactTravel (0.5 mm) or less.
  std::mt19937 rng(3);
  Scene s = make_scene(rng, 0.0);
  const Mat3 rb = s.b.orientation.toRotationMatrix();
  s.a.orientation = s.b.orientation;  // a's thin axis along n: flat on b's face
  s.a.half = Vec3(0.015, 0.001, 0.01);
  s.a.moments = box_moments(s.a.half, 0.005);
  s.a.position = s.contact.point + s.a.half.y() * s.contact.normal + 0.004 * rb.col(0);
  s.a.angular = 40.0 * s.contact.normal;
  const double bound = contact_deepening_bound(s.contact, s.a.side(), s.b.side(), kStep, true);
  EXPECT_LT(bound, 5e-5);
  EXPECT_LE(overlap_after(s, kStep), bound + 1e-12);
}

}  // namespace
}  // namespace aloft
