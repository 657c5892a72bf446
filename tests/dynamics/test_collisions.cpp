// Collisions inside the simulation: no tunnelling through a thin plate, a knock passed on within its step,
// pieces meeting from both sides held to what a step allows, resting contact without jitter or sinking,
// energy that never grows and that the contacts account for, the Steel Fish shaken hard, and a crowded
// generated mobile in a breeze.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "aloft/collision.hpp"
#include "aloft/generate.hpp"
#include "aloft/model.hpp"
#include "aloft/simulation.hpp"
#include "aloft/spec.hpp"
#include "support/leaning_balls.hpp"
#include "support/presets.hpp"
#include "support/shaking.hpp"

namespace aloft {
namespace {

Model model_from(const std::string& json) { return compile(parse_mobile_text(json)); }

// A 20 mm steel ball on a 0.5 m thread from the hook, and beside it a 2 mm steel pane hanging on its
// own thread, its near face 29 mm to the right of the ball. (A pane on the hook itself would not do:
// a component and its parent never collide, as in the paper.) Damping off: energy can only leave
// through the collision.
const char* const kBallAndPane = R"({
  "name": "ball and pane", "contact": {"restitution": 0.5, "friction": 0.3},
  "components": [
    {"name": "hook", "fixed": true, "shapes": [{"wire": {"from": [-0.01, 1, 0], "to": [0.06, 1, 0], "radius": 0.003}}]},
    {"name": "ball", "parent": "hook", "joint": [0, 1, 0], "shapes": [
      {"wire": {"from": [0, 1, 0], "to": [0, 0.52, 0], "radius": 0.001}},
      {"sphere": {"center": [0, 0.5, 0], "radius": 0.02}}]},
    {"name": "pane", "parent": "hook", "joint": [0.05, 1, 0], "shapes": [
      {"wire": {"from": [0.05, 1, 0], "to": [0.05, 0.6, 0], "radius": 0.0005}},
      {"plate": {"plane": {"origin": [0.05, 0.5, 0], "u": [0, 0, 1], "v": [0, 1, 0]}, "thickness": 0.002,
                 "points": [[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]]}}]}]})";

// Swing the ball at the pane: angular velocity about z giving the ball's centre `speed` m/s along +x.
Simulation& swing(Simulation& sim, double speed) {
  State& s = sim.mutable_state();
  const Vec3 pivot(0, 1, 0);
  const double omega = speed / 0.5;
  s.angular[1] = Vec3(0, 0, omega);
  s.velocity[1] = s.angular[1].cross(s.position[1] - pivot);
  return sim;
}

// How far (m) the ball reaches into the pane: ball radius + half the pane's thickness minus the distance
// of the ball's centre from the pane's mid-plane, measured on the side the ball starts on. Negative while
// apart; 0.042 m once the ball is wholly through.
double overlap_with_pane(const Model& model, const State& s) {
  const Plate& pane = std::get<Plate>(model.shapes[2][1].shape);
  const Sphere& ball = std::get<Sphere>(model.shapes[1][1].shape);
  const Vec3 normal = s.orientation[2] * pane.normal();  // -x at rest: towards the ball
  const Vec3 mid_plane_point = s.position[2] + s.orientation[2] * pane.origin;
  const Vec3 centre = s.position[1] + s.orientation[1] * ball.center;
  return ball.radius + 0.5 * pane.thickness - normal.dot(centre - mid_plane_point);
}

TEST(Collisions, FastBallDoesNotTunnelThroughAThinPlate) {
  const Model model = model_from(kBallAndPane);
  Simulation sim(model);
  swing(sim, 5.0);
  double furthest = -1, energy_before = kinetic_energy(model, sim.state()) + potential_energy(model, sim.state());
  double energy_max = energy_before;
  bool knocked = false;
  for (int step = 0; step < 300; ++step) {  // 0.3 s: the ball reaches the pane after ~6 ms
    ASSERT_TRUE(sim.step()) << sim.failure()->message;
    // The knock happens in the first 10 ms; afterwards the pane swings and turns away and the distance
    // to its (unbounded) mid-plane no longer measures an overlap.
    if (step < 50) furthest = std::max(furthest, overlap_with_pane(model, sim.state()));
    energy_max = std::max(energy_max, kinetic_energy(model, sim.state()) + potential_energy(model, sim.state()));
    knocked = knocked || sim.state().velocity[2].x() > 1.0;  // the pane was sent flying
  }
  EXPECT_TRUE(knocked);
  // At 5 m/s a 1 ms step moves the ball 5 mm, more than the pane is thick. The speculative contact stops
  // it before it touches (it may bounce up to one step's travel early), and overlap is bounded by the
  // contact's penetration slop (0.05 mm) plus the second-order drift of one step (g h^2 ~ 0.01 mm).
  EXPECT_LT(furthest, 1e-4) << "the ball went " << furthest * 1e3 << " mm into the pane";
  // And over the whole run, as the detector measures it (ball, threads and pane all included).
  EXPECT_LT(sim.collision_statistics().deepest, 1e-4);
  // The collision (e = 0.5) only removes energy; the integrator's own error is ~1e-6 of the energy.
  EXPECT_LT(energy_max - energy_before, 1e-5 * std::abs(energy_before) + 1e-6);
  EXPECT_GT(sim.collision_statistics().impulses, 0);
}

TEST(Collisions, WithCollisionsOffTheBallPassesThrough) {
  // The same swing with collisions off: the test above can fail.
  const Model model = model_from(kBallAndPane);
  Simulation sim(model);
  sim.set_collisions(false);
  swing(sim, 5.0);
  double furthest = -1;
  for (int step = 0; step < 100; ++step) {
    ASSERT_TRUE(sim.step());
    furthest = std::max(furthest, overlap_with_pane(model, sim.state()));
  }
  EXPECT_GT(furthest, 0.042);  // wholly through
}

// A row of 20 mm balls on 0.5 m threads from the hook at the given x (m), in a row along x.
std::string ball_row(const std::vector<double>& x) {
  std::string json = R"({"name": "row", "contact": {"restitution": 0.5, "friction": 0.3}, "components": [
    {"name": "hook", "fixed": true, "shapes": [{"wire": {"from": [-0.03, 1, 0], "to": [0.6, 1, 0], "radius": 0.003}}]})";
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::string at = std::to_string(x[i]);
    json += R"(, {"name": "ball )" + std::to_string(i + 1) + R"(", "parent": "hook", "joint": [)" + at + R"(, 1, 0],
      "shapes": [{"wire": {"from": [)" + at + R"(, 1, 0], "to": [)" + at + R"(, 0.52, 0], "radius": 0.0005}},
                 {"sphere": {"center": [)" + at + R"(, 0.5, 0], "radius": 0.02}}]})";
  }
  return json + "]}";
}

// The first ball knocks the second at 2 m/s, which in the same 1 ms step would carry it 1.5 mm into the
// third, 0.3 mm away and at rest. At the step's start that pair is apart and not closing, so the first
// solve leaves it out; its impulses then send the second ball towards the third, and the pair must be
// solved with the rest in the same step (Simulation::kick_and_collide looks at the list again). Until
// 2026-12-06 it was not, as long as the detector's list was the same: the step's motion check then
// halved the step 5 times, and a substep still began with the balls 0.44 mm deep. (On generated-1023
// after the breeze a thread went 0.62 mm into its neighbour that way, past the thread's 0.5 mm radius.)
// With more balls in the row, each solve's impulses close the next pair, which the solve before left
// out, so the step looks and solves again until none closes, up to kMaxSolvesPerLook (4) solves: 5 balls.
// Until the fourth session of 2026-12-06 it solved twice at most: with 4 and 5 balls the step was halved
// 5 times and a substep began 0.25 mm deep.
TEST(Collisions, AKnockIsPassedOnWithinTheStep) {
  for (int balls = 3; balls <= 5; ++balls) {
    // A Newton's cradle with gaps: the first ball 10.3 mm from the second, swung at it; the others 0.3
    // mm apart, far enough apart at rest not to be pruned as touching (0.1 mm) and near enough to be in
    // the detector's list at every step (its margin is 0.5 mm).
    std::vector<double> x = {-0.01};
    for (int i = 1; i < balls; ++i) x.push_back(0.0403 * i);
    const Model model = model_from(ball_row(x));
    Simulation sim(model);
    sim.set_damping(DampingSpec{});
    {
      State& s = sim.mutable_state();
      const Vec3 pivot(-0.01, 1, 0);
      s.angular[1] = Vec3(0, 0, 2.0 / 0.5);  // the first ball's centre at 2 m/s along +x
      s.velocity[1] = s.angular[1].cross(s.position[1] - pivot);
    }
    double last_speed = 0;  // m/s, the last ball's fastest
    const double energy_before = kinetic_energy(model, sim.state()) + potential_energy(model, sim.state());
    for (int step = 0; step < 30; ++step) {  // the knock comes after about 5 ms
      ASSERT_TRUE(sim.step()) << sim.failure()->message;
      last_speed = std::max(last_speed, sim.state().velocity[balls].x());
    }
    const double lost = energy_before - kinetic_energy(model, sim.state()) - potential_energy(model, sim.state());
    // The knock went on to the last ball. Equal balls with e = 0.5 pass on (1 + e) / 2 = 3/4 of the
    // speed at each knock: 2 (3/4)^(balls - 1) m/s. Measured 1.09, 0.81, 0.60 m/s for 3 to 5 balls, 3-6 %
    // below that (the balls swing on threads, not along a line); 20 % allowed ...
    EXPECT_GT(last_speed, 0.8 * 2.0 * std::pow(0.75, balls - 1)) << balls << " balls";
    // ... with no (sub)step starting deeper than the contacts' penetration slop (0.05 mm) ...
    EXPECT_LT(sim.collision_statistics().deepest, 5e-5) << balls << " balls";
    // ... and no step divided for it: solved in the step, the balls move no faster than the step allows.
    EXPECT_EQ(sim.subdivisions(), 0) << balls << " balls";
    // Without air damping only the knocks take energy out, and the counter, each solve weighed with all
    // the earlier solves' changes, says how much: measured within 2.3e-7 of it, relatively (0.324, 0.389,
    // 0.426 J lost); with the third and later solves weighed without the changes before the second,
    // 0.149 and 0.054 J were counted for 4 and 5 balls.
    EXPECT_NEAR(sim.collision_statistics().energy_removed, lost, 1e-5 * lost) << balls << " balls";
  }
}

// Ten balls in a row, the two at the ends swung at the others at the same speed: 10.3 mm from the end
// ones, the eight in the middle 0.3 mm apart. Each solve of a step passes both knocks on to the next pair
// (the test above), but the middle pair closes only after the fourth, the most a step makes
// (kMaxSolvesPerLook): within the step, its balls come towards each other with nothing between
// them. The step's motion check must then hold what the step does to the pair to what it allows any
// pair: apart at the step's start, at most kMaxContactTravel (0.5 mm; for these balls less than
// kDeepeningPerHalfWidth of their radius) deep at its end. Until 2026-12-06 it held each ball alone to
// that travel, which let the two come twice as far: in a build that does so again, at 1.4-1.6 m/s the
// middle pair began the next step 0.54-0.66 mm deep; now those steps are halved, and the deepest over
// the speeds below is 0.48 mm (at 1.3 m/s). (Six balls showed the same while a step solved twice at most.)
TEST(Collisions, PiecesComingTogetherFromBothSidesGetNoDeeperThanAStepAllows) {
  std::vector<double> x = {0.0};
  for (int i = 0; i < 8; ++i) x.push_back(0.0503 + 0.0403 * i);
  x.push_back(x.back() + 0.0503);
  const Model model = model_from(ball_row(x));
  const int last = static_cast<int>(x.size());
  for (int twentieths = 10; twentieths <= 40; ++twentieths) {  // 0.5 to 2 m/s
    const double speed = 0.05 * twentieths;
    Simulation sim(model);
    State& s = sim.mutable_state();
    for (const int i : {1, last}) {
      const double along = i == 1 ? speed : -speed;  // m/s, the ball's centre along x
      s.angular[i] = Vec3(0, 0, along / 0.5);
      s.velocity[i] = s.angular[i].cross(s.position[i] - Vec3(x[i - 1], 1, 0));
    }
    for (int step = 0; step < 40; ++step) ASSERT_TRUE(sim.step()) << sim.failure()->message;  // knocks at 5-20 ms
    EXPECT_GT(sim.collision_statistics().impulses, 0);
    EXPECT_LT(sim.collision_statistics().deepest, 5e-4) << "at " << speed << " m/s";
  }
}

// A row of four balls 0.3 mm apart and a fifth further off, 0.8 to 1.6 mm: at rest it is beyond the
// detector's reach from the fourth (their margins, 0.25 mm each plus what they move in a step), so the
// step's first look does not list the pair, nor does the look after the first solve, when only the
// second ball moves. The third solve sends the fourth ball off at 0.84-1.69 m/s, as far in mm in the step:
// the pieces must be looked at again after every solve, not only the first, for the pair to be solved in
// the step. (With the solves repeated on the first solve's list alone, which d19b7a4 did for one
// session, the fourth ball went up to 0.82 mm into the fifth, at 4 m/s, with no step divided: the step's
// motion check holds only the listed pairs. Before that, with two solves at most, the steps were halved
// up to 18 times and a substep still began 0.25 mm deep.)
TEST(Collisions, AKnockPassedOnIsLookedAtAgain) {
  for (const double gap : {0.8e-3, 1.2e-3, 1.6e-3}) {  // m, between the fourth ball and the fifth
    std::vector<double> x = {-0.01, 0.0403, 0.0806, 0.1209};
    x.push_back(x.back() + 0.04 + gap);
    const Model model = model_from(ball_row(x));
    for (const double speed : {2.0, 3.0, 4.0}) {  // m/s, the first ball's centre
      Simulation sim(model);
      State& s = sim.mutable_state();
      s.angular[1] = Vec3(0, 0, speed / 0.5);
      s.velocity[1] = s.angular[1].cross(s.position[1] - Vec3(-0.01, 1, 0));
      for (int step = 0; step < 30; ++step) ASSERT_TRUE(sim.step()) << sim.failure()->message;
      char where[64];
      std::snprintf(where, sizeof where, "a gap of %.1f mm, %.0f m/s", gap * 1e3, speed);
      // The knock reached the fifth ball: 3/4 of the speed passed on at each knock (e = 0.5), 20 % allowed
      // as in AKnockIsPassedOnWithinTheStep (measured 0.59, 0.89, 1.18 m/s) ...
      EXPECT_GT(sim.state().velocity[5].x(), 0.8 * speed * std::pow(0.75, 4)) << where;
      // ... with no (sub)step starting deeper than the penetration slop (0.05 mm), and none divided.
      EXPECT_LT(sim.collision_statistics().deepest, 5e-5) << where;
      EXPECT_EQ(sim.subdivisions(), 0) << where;
    }
  }
}

TEST(Collisions, RestingContactNeitherJittersNorSinks) {
  const Model model = model_from(test::kLeaningBalls);
  Simulation sim(model);
  auto centre = [&](const State& s, int i) {
    return Vec3(s.position[i] + s.orientation[i] * std::get<Sphere>(model.shapes[i][1].shape).center);
  };
  ASSERT_TRUE(sim.advance(6.0));  // the knock and the bounces die out (damping 0.5/s, e = 0.3)
  double deepest = 0, moved = 0, lowest_gap = 1, highest_gap = -1;
  const Vec3 left = centre(sim.state(), 1), right = centre(sim.state(), 2);
  const double removed_before = sim.collision_statistics().energy_removed;
  for (int step = 0; step < 1000; ++step) {
    ASSERT_TRUE(sim.step());
    const State& s = sim.state();
    const double gap = (centre(s, 1) - centre(s, 2)).norm() - 0.06;
    lowest_gap = std::min(lowest_gap, gap);
    highest_gap = std::max(highest_gap, gap);
    deepest = std::max(deepest, -gap);
    moved = std::max({moved, (centre(s, 1) - left).norm(), (centre(s, 2) - right).norm()});
  }
  const double removed = sim.collision_statistics().energy_removed - removed_before;
  std::printf("leaning balls: gap from %.3g to %.3g mm, moved at most %.3g mm in 1 s, energy taken out %.3g J\n",
              lowest_gap * 1e3, highest_gap * 1e3, moved * 1e3, removed);
  // Leaning, not hovering apart: in contact within the 0.05 mm penetration slop ...
  EXPECT_LT(highest_gap, 5e-5);
  // ... not sinking: the overlap stays at the slop's scale (0.05 mm, plus one step of gravity) ...
  EXPECT_LT(deepest, 1e-4);
  // ... and not jittering or creeping: over a whole second neither ball moves by 1 micrometre, a
  // thousandth of anything visible. (The velocities at step boundaries carry half a step of gravity,
  // g sin(1.15 deg) h / 2 = 0.1 mm/s, that the next step's contact impulse removes before anything moves.)
  EXPECT_LT(moved, 1e-6);
  EXPECT_LT(highest_gap - lowest_gap, 1e-5);
  // Holding them there takes no energy out of them (CollisionStatistics::energy_removed): measured 4.3e-9
  // J over the second. Weighed at the half-kicked velocities, as until 2026-12-06, each step's impulse
  // took out the half kick's approach, m (g sin(1.15 deg) h)^2 / 2 with the pair's reduced mass: 3.4e-5 J.
  EXPECT_LT(std::abs(removed), 1e-6);
}

// Two 5 cm balls on 0.5 m threads, e = 1 and mu = 10: A swings into B, they trade speeds (the first knock),
// and 0.7 s later swing back into each other. In the step before that second knock the balls are met as a
// speculative contact, slowed from 1.14 to 0.93 m/s to close their gap within the step. Until 2026-12-07
// that slowing counted as a pair pressed together at 1.14 m/s, and a pressed pair bounces only when it
// approaches faster than twice that: the knock came out plastic, both balls stopped and the contacts took
// out all 2.7 J. What a speculative contact stops is the approach less what it may close (0.21 m/s).
TEST(Collisions, AKnockMetFirstAsASpeculativeContactStillBounces) {
  const Model model = model_from(R"({"name": "two balls", "contact": {"restitution": 1, "friction": 10},
    "components": [
      {"name": "hook", "fixed": true, "shapes": [{"wire": {"from": [-0.5, 2, 0], "to": [0.5, 2, 0], "radius": 0.005}}]},
      {"name": "A", "parent": "hook", "joint": [-0.051, 2, 0], "shapes": [
        {"wire": {"from": [-0.051, 2, 0], "to": [-0.276, 1.6102885682970025, 0], "radius": 0.001}},
        {"sphere": {"center": [-0.301, 1.5669872981077806, 0], "radius": 0.05}}]},
      {"name": "B", "parent": "hook", "joint": [0.051, 2, 0], "shapes": [
        {"wire": {"from": [0.051, 2, 0], "to": [0.051, 1.55, 0], "radius": 0.001}},
        {"sphere": {"center": [0.051, 1.5, 0], "radius": 0.05}}]}]})");
  Simulation sim(model);
  sim.set_damping(DampingSpec{});
  const auto closing = [&] { return sim.state().velocity[1].x() - sim.state().velocity[2].x(); };  // m/s
  ASSERT_TRUE(sim.advance(1.07));  // after the first knock, before the second (at 1.08 s)
  const double before = closing();
  ASSERT_GT(before, 1.0);  // they approach at 1.14 m/s
  ASSERT_TRUE(sim.advance(0.03));
  const double after = closing();
  std::printf("second knock: approach %.3f m/s, then %.3f m/s\n", before, after);
  // Parting, not stopped. Not at the full 1.14 m/s of e = 1: the speculative step's slowing is not given
  // back (docs/architecture.md, "Known limits"); measured 0.93 m/s.
  EXPECT_LT(after, -0.5 * before);
}

// The leaning balls pressed together by a steady force of `times` their weight each (as a strong wind
// presses a light plate on a wire, or a tangle's joints press one light piece on another): between two
// steps they approach at 2 `times` g h, faster than the bounce threshold (2 g h). Until 2026-12-06 each
// step that stopped them bounced them (e = 0.3), and the force brought them back a step or two later:
// over a second the gap went from 0 to 0.013, 0.056 and 0.19 mm at 1.5, 3 and 10 weights, and at 3 and
// 10 they were stopped in only 602 of the 1000 steps. Now they rest. Knocked hard, the pair still bounces.
// The press acts along the line of the balls' centres, as the pieces' own weight or a joint presses them.
// A press along a fixed direction (x, as until 2026-12-07) makes the pair unstable: once the balls are
// off the x axis by +-dz, the contact's normal turns by dz / r and pushes them further aside with F dz / r,
// against the threads' m g dz / L (r = 30 mm, L = 0.5 m): unstable above r / L = 0.06 weights, so they
// roll round each other as real balls would. That held only while rounding left z exactly 0; a change in
// the last bits of the inertia (1e-16 relative) set them rolling, from 6e-10 m at t = 1.1 s to 30 mm at
// 2.1 s (an e-folding time of 55 ms).
TEST(Collisions, PiecesPressedHardTogetherRestWithoutBouncing) {
  const Model model = model_from(test::kLeaningBalls);
  auto centre = [&](const State& s, int i) {
    return Vec3(s.position[i] + s.orientation[i] * std::get<Sphere>(model.shapes[i][1].shape).center);
  };
  for (const double times : {1.5, 3.0, 10.0}) {
    Simulation sim(model);
    const auto pressed_step = [&] {
      const Vec3 towards = (centre(sim.state(), 2) - centre(sim.state(), 1)).normalized();
      sim.loads().force[1] = times * model.mass[1] * 9.81 * towards;
      sim.loads().force[2] = -times * model.mass[2] * 9.81 * towards;
      return sim.step();
    };
    for (int step = 0; step < 6000; ++step)  // 6 s: the first knock's bounces die out (damping 0.5/s)
      ASSERT_TRUE(pressed_step());
    const long long impulses_before = sim.collision_statistics().impulses;
    double lowest_gap = 1, highest_gap = -1;
    for (int step = 0; step < 1000; ++step) {
      ASSERT_TRUE(pressed_step());
      const double gap = (centre(sim.state(), 1) - centre(sim.state(), 2)).norm() - 0.06;
      lowest_gap = std::min(lowest_gap, gap);
      highest_gap = std::max(highest_gap, gap);
    }
    const long long impulses = sim.collision_statistics().impulses - impulses_before;
    std::printf("pressed at %g weights: gap from %.3g to %.3g mm, stopped in %lld of 1000 steps\n", times,
                lowest_gap * 1e3, highest_gap * 1e3, impulses);
    // Stopped in every step, in contact within the penetration slop (0.05 mm), and still: the gap
    // varies by less than a micrometre (measured 1e-15 m).
    EXPECT_EQ(impulses, 1000) << times << " weights";
    EXPECT_GT(lowest_gap, -5e-5) << times << " weights";
    EXPECT_LT(highest_gap, 5e-5) << times << " weights";
    EXPECT_LT(highest_gap - lowest_gap, 1e-6) << times << " weights";

    // The left ball knocked towards the right one at 0.5 m/s (about its thread's joint, about z): a knock
    // 8 times faster than the pressing's approach between two steps at 3 weights (2 * 3 g h). With
    // e = 0.3 the balls part at about 0.3 * 0.5 m/s; stopped without the bounce they would not part.
    State& s = sim.mutable_state();
    const Vec3 pivot(-0.02, 1, 0);
    const Vec3 arm = centre(s, 1) - pivot;
    const Vec3 towards = (centre(s, 2) - centre(s, 1)).normalized();
    s.angular[1] = arm.cross(0.5 * towards) / arm.squaredNorm();
    s.velocity[1] = s.angular[1].cross(s.position[1] - pivot);
    ASSERT_TRUE(pressed_step());
    const auto speed_of = [&](int i) {  // the ball's centre's velocity, m/s
      const State& now = sim.state();
      return Vec3(now.velocity[i] + now.angular[i].cross(centre(now, i) - now.position[i]));
    };
    const double parting = (speed_of(2) - speed_of(1)).dot(towards);
    std::printf("  knocked at 0.5 m/s: parting at %.3g m/s\n", parting);
    // The pressing (2 times g h, up to 0.2 m/s at 10 weights) takes back part of the parting in the step.
    EXPECT_GT(parting, 0.05) << times << " weights";
  }
}

TEST(Collisions, SteelFishShakenHardStaysWholeAndNeverGainsEnergyWhenLeftAlone) {
  const Model model = test::load_preset("steel-fish", BalanceMode::Mass);  // no air damping
  Simulation sim(model);
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  const double weight = 9.81 * model.balance.total_mass;
  double worst_gain = 0, worst_left_overlap = 0, worst_relative_overlap = 0;
  // The work the shaking does (J: each step's force on each component times its centre's displacement),
  // for the energy the contacts may have taken out.
  double shaking_work = 0;
  std::vector<Vec3> shaken_from(model.count);
  const double energy_at_start = kinetic_energy(model, sim.state()) + potential_energy(model, sim.state());
  // 10 minutes of simulated time in cycles of 2 s: shaken hard for 1 s, as if the hook were jerked about
  // (a uniform random acceleration of 0.5 g rms per axis, a new one every 50 ms: the arms swing
  // through half a turn and knock into each other), then left alone for 1 s. One minute under the
  // sanitizers (ten times slower).
#ifdef ALOFT_SANITIZED
  const int cycles = 30;
#else
  const int cycles = 300;
#endif
  CollisionDetector detector(model);
  std::vector<Contact> contacts, earlier;
  for (int cycle = 0; cycle < cycles; ++cycle) {
    for (int step = 0; step < 1000; ++step) {  // shaken for 1 s
      test::shake(model, sim, rng, g, step);
      for (int i = 1; i < model.count; ++i) shaken_from[i] = sim.state().position[i];
      ASSERT_TRUE(sim.step()) << sim.failure()->message;
      for (int i = 1; i < model.count; ++i) shaking_work += sim.loads().force[i].dot(sim.state().position[i] - shaken_from[i]);
      for (const Contact& c : sim.contacts()) worst_relative_overlap = std::max(worst_relative_overlap, -c.distance / c.thinnest);
    }
    sim.loads().clear();
    const double kinetic = kinetic_energy(model, sim.state());
    // Growth, not the integrator's oscillation: the energy of a single step differs from the one the
    // symplectic step conserves by O((h w)^2) of the kinetic energy, w the fastest spin, and oscillates
    // about it without a trend. With arms spun at tens of rad/s that reached 1.85 times the allowance
    // below within a second with no contact at all (seed 7, cycle 59, after the joint-impulse guess of
    // 2026-11-25), so a comparison of the first and last step's energies failed on 1 of 13 seeds of this
    // shaking both before and after that change (docs/performance.md, "2026-11-25, later"). Compared
    // instead: the mean energy over the first and the last quarter of the second (worst over 13 seeds:
    // 0.60 of the allowance before the change, 0.37 after). A gain from contacts (a bounce, the overlap
    // push) stays in the energy and shows in the later mean.
    const int steps = static_cast<int>(std::lround(1.0 / sim.timestep()));
    const int window = steps / 4;
    double start = 0, end = 0;  // mean energies over the first and the last window (J)
    for (int step = 0; step < steps; ++step) {
      ASSERT_TRUE(sim.step()) << sim.failure()->message;
      const double energy = kinetic_energy(model, sim.state()) + potential_energy(model, sim.state());
      if (step < window) start += energy / window;
      if (step >= steps - window) end += energy / window;
      if (step == steps - 21) detector.find_contacts(sim.state(), 0.0, 1e-3, earlier);
    }
    // Allowed: the integrator's error (1e-4 of the kinetic energy; the conservation test measures far
    // less without contacts) and the lift of the overlap correction, which may raise a piece by its
    // overlap (< 0.1 mm) against gravity.
    const double allowed = 1e-4 * kinetic + weight * 1e-4;
    worst_gain = std::max(worst_gain, (end - start) / allowed);
    // Joints together (the core's bound, 1e-6 m).
    ASSERT_LT(max_joint_separation(model, sim.state()), 1e-6) << "cycle " << cycle;
    // Nothing stays inside anything: after a second left alone (no damping: the arms still swing and
    // knock), every pair is apart or touching within a tenth of the 2.5 mm sheet. Transient overlaps
    // beyond the 0.05 mm slop are removed at 80 % per step, so one that lasts is a piece stuck inside:
    // a pair's overlap counts as the lesser of now and 20 ms before, so that a knock at this very step
    // does not (seed 6 of this shaking met one 0.24 mm deep that had been 0.045 mm 20 ms before).
    detector.find_contacts(sim.state(), 0.0, 1e-3, contacts);
    for (const Contact& c : contacts) {
      double before = 0;
      for (const Contact& e : earlier)
        if (e.a == c.a && e.b == c.b) before = std::max(before, -e.distance);
      worst_left_overlap = std::max(worst_left_overlap, std::min(-c.distance, before));
    }
  }
  const CollisionStatistics& stats = sim.collision_statistics();
  EXPECT_GT(stats.impulses, 100) << "the shaking should make the pieces knock";
  // The contact law's counts agree with each other: every impulse is at a contact some solve was for,
  // every solve sweeps at least once, and a (sub)step makes at most two solves (the second when the look
  // after the impulses finds other contacts).
  EXPECT_GE(stats.law_contacts, stats.impulses);
  EXPECT_GE(stats.law_sweeps, stats.law_solves);
  EXPECT_LE(stats.law_solves, 2 * stats.steps_with_contacts);
  EXPECT_GT(stats.law_solves, 0);
  EXPECT_LT(worst_left_overlap, 2.5e-4);
  // Nothing gets through anything, even while knocked about: no contact, at the start of any (sub)step,
  // is deeper than the thinnest sheet (1.5 mm; measured 0.58 mm, 0.48-0.61 mm over 24 seeds of this
  // shaking, against 0.29-0.51 mm while every step whose pieces in contact moved too fast for the bounds
  // was halved; docs/collisions.md, "Checking the motion itself"). It was 4-16 mm while GJK's distance
  // estimate, too high where it stopped at its iteration limit, could hide a wire's approach to a plate
  // (gjk_contact.cpp): a wire then went 7 mm into a 1.5 mm plate; and 0.8-2.6 mm while EPA's wrong face
  // on two sheets crossing edge to edge went uncorrected (no edge-edge axes): an arm's plate touching a
  // fish by 0.0074 mm came out 2.57 mm deep, and the push along that wrong normal drove a wire into it.
  EXPECT_LT(stats.deepest, 1.5e-3);
  // Nor past the middle of the thinnest piece near it, where the narrow phase would read the overlap
  // from the far side and the push would drive it through: at the start of every step, no contact's
  // overlap reaches the smallest half-width of its pair's pieces (Contact::thinnest). Measured 0.53 of
  // it, 0.49-0.72 over 24 seeds (0.23-0.50 with the halving); 2.1 and 1.36 times it before two narrow
  // phase errors on a wire's end were fixed (2026-12-02: a wire's support along its axis, GJK's normal).
  EXPECT_LT(worst_relative_overlap, 1.0);
  // The same at the start of every substep too (CollisionStatistics::deepest_relative).
  EXPECT_LT(stats.deepest_relative, 1.0);
  // Left alone, the energy never grows by more than allowed above.
  EXPECT_LT(worst_gain, 1.0);
  // What the contacts took out is what the shaking put in less what the mobile kept: no damping here, so
  // nothing else takes energy out. Allowed: 1 % of the work, for the overlap push's lift and the
  // integrator's error (measured 0.1 %: 708.0 J against 708.7). Weighed at the half-kicked velocities
  // instead of the steps' start velocities, as until 2026-12-06 (see Collisions.EnergyTakenOutIsTheEnergyLost),
  // it read 1.4 % more, 719 J against 709. And before then the contact law could return impulses of 1e10 N s
  // along its collision matrix's null space, and their round-off alone counted 6.8e5 J taken out in one
  // step, 1000 times all the shaking did (ContactLaw.APolishThatThrowsTheImpulsesOutOfScaleIsRefused).
  const double kept = kinetic_energy(model, sim.state()) + potential_energy(model, sim.state()) - energy_at_start;
  EXPECT_NEAR(stats.energy_removed, shaking_work - kept, 0.01 * shaking_work);
  std::printf("steel fish shaken %d s: %lld contact impulses (%lld sliding), deepest transient overlap %.3g mm, "
              "deepest after a second left alone %.3g mm, energy removed %.3g J, worst gain when left alone "
              "%.3g of the allowance\n",
              2 * cycles, stats.impulses, stats.sliding, stats.deepest * 1e3, worst_left_overlap * 1e3,
              stats.energy_removed, worst_gain);
  std::printf("  the shaking's work %.4g J, kept by the mobile %.4g J\n", shaking_work, kept);
  std::printf("  deepest overlap at a step's start %.3f of the thinnest half-width near it (%.3f at a substep's)\n",
              worst_relative_overlap, stats.deepest_relative);
}

// A thread (0.4 m of 1 mm steel wire) hanging from the hook beside a second one, 0.5 mm apart: spun about
// its own (vertical) axis at 150 rad/s, it turns 0.15 rad in a 1 ms step, three times kOldTurnLimit, but
// its near part, the length of thread beside the other, turns in place: the pair's contact is the same
// at the step's end. With `bar`, a 10 cm crossbar at the spinner's foot, and the other thread beside the
// crossbar's end instead: the same spin sweeps that end past the thread at 7.5 m/s, and the step must be
// shortened (Simulation::contacts_turn_slowly_enough).
std::string spinning_thread(bool bar) {
  // The other thread's axis: its surface 0.5 mm from the spinning thread's, or 1 mm from the crossbar's end.
  const std::string x = bar ? "0.0515" : "0.0015";
  std::string json = R"({"name": "spinning thread", "contact": {"restitution": 0.5, "friction": 0.3},
  "components": [
    {"name": "hook", "fixed": true, "shapes": [{"wire": {"from": [-0.01, 1, 0], "to": [0.06, 1, 0], "radius": 0.003}}]},
    {"name": "spinner", "parent": "hook", "joint": [0, 1, 0], "shapes": [
      {"wire": {"from": [0, 1, 0], "to": [0, 0.6, 0], "radius": 0.0005}})";
  if (bar) json += R"(, {"wire": {"from": [-0.05, 0.6, 0], "to": [0.05, 0.6, 0], "radius": 0.0005}})";
  json += R"(]},
    {"name": "other", "parent": "hook", "joint": [X, 1, 0], "shapes": [
      {"wire": {"from": [X, 1, 0], "to": [X, 0.55, 0], "radius": 0.0005}}]}]})";
  for (std::size_t at = json.find('X'); at != std::string::npos; at = json.find('X')) json.replace(at, 1, x);
  return json;
}

// The energy counter against the energy itself: a generated mobile of 127 components (generator seed 2)
// set knocking by the bench's breeze for 0.3 s, then left alone for 3 s without air damping, so that
// only the contacts take energy out. What CollisionStatistics::energy_removed says they took is what the
// mobile lost, to within what the integrator and the overlap pushes change on their own. Weighed at the
// half-kicked velocities, as until 2026-12-06, the counter read 0.0678 J against 0.0549 J lost (23 %
// more): every piece resting on another counted m (g h)^2 / 2 per step that it never lost (see
// ContactResponse::resolve).
TEST(Collisions, EnergyTakenOutIsTheEnergyLost) {
  GenerateOptions options;
  options.components = 127;
  options.seed = 2;
  options.total_mass = 1.0;
  MobileSpec spec = parse_mobile_text(generate_mobile(options), "generated-127.json");
  spec.damping = DampingSpec{};
  const Model model = compile(spec);
  Simulation sim(model);
  ASSERT_TRUE(sim.collisions());
  set_breeze(model, sim.loads());
  ASSERT_TRUE(sim.advance(0.3)) << sim.failure()->message;
  sim.loads().clear();
  const double start = kinetic_energy(model, sim.state()) + potential_energy(model, sim.state());
  const double removed_before = sim.collision_statistics().energy_removed;
  const long long impulses_before = sim.collision_statistics().impulses;
  ASSERT_TRUE(sim.advance(3.0)) << sim.failure()->message;
  const double lost = start - (kinetic_energy(model, sim.state()) + potential_energy(model, sim.state()));
  const double removed = sim.collision_statistics().energy_removed - removed_before;
  std::printf("generated-127 left alone 3 s: %lld contact impulses, energy lost %.5g J, taken out by the "
              "contacts %.5g J\n",
              sim.collision_statistics().impulses - impulses_before, lost, removed);
  EXPECT_GT(sim.collision_statistics().impulses - impulses_before, 1000) << "the pieces should keep knocking";
  EXPECT_GT(lost, 0.02) << "the knocks should take a good part of the energy out";
  // Allowed: 5 % of what was lost (2.7 mJ), 2.5 times the integrator's own drift on this mobile over the
  // same span with collisions off (1.1 mJ). Measured 0.16 %: 0.05483 J taken out, 0.05492 J lost.
  EXPECT_NEAR(removed, lost, 0.05 * lost);
}

TEST(Collisions, AThreadSpinningAboutItsOwnAxisBesideAnotherKeepsItsStep) {
  for (const bool bar : {false, true}) {
    const Model model = model_from(spinning_thread(bar));
    Simulation sim(model);
    sim.mutable_state().angular[1] = Vec3(0, 150, 0);  // rad/s, about the thread's axis (a principal axis)
    for (int step = 0; step < 20; ++step) ASSERT_TRUE(sim.step()) << sim.failure()->message;
    const StepStatistics& stats = sim.step_statistics();
    const double spin = sim.state().angular[1].y();
    std::printf("%s: %lld (sub)steps taken for 20 steps, %lld rejected for a pair in contact turning too fast; "
                "spin %.3f rad/s, deepest overlap %.3g mm\n",
                bar ? "crossbar" : "thread", stats.accepted, stats.rejected_contact_turn, spin,
                sim.collision_statistics().deepest * 1e3);
    // The pair is within the detection margin (the spin's sweep, h |w| times the spinner's reach, widens
    // it), so the rule is asked.
    EXPECT_GT(sim.collision_statistics().steps_with_contacts, 0) << (bar ? "crossbar" : "thread");
    if (bar) {
      // The crossbar's end turns across itself: the steps it passes the other thread in are divided (to
      // 0.25 ms, where it turns 0.0375 rad; measured: 46 (sub)steps for the 20 steps, 5 rejected).
      EXPECT_GT(stats.rejected_contact_turn, 0);
      EXPECT_GT(stats.accepted, 20);
    } else {
      // Every step taken whole: the thread's spin moves its surface by 0.075 mm per step, its axis not at all.
      EXPECT_EQ(stats.rejected_contact_turn, 0);
      EXPECT_EQ(stats.accepted, 20);
    }
    // Nothing touched: no overlap, and the spin kept (a spin about a principal axis, no impulse).
    EXPECT_EQ(sim.collision_statistics().deepest, 0.0);
    EXPECT_NEAR(spin, 150.0, 1e-6);
  }
}

// A crowded mobile: the generated 1023-component one (seed 1), set knocking by `aloft bench`'s breeze
// (0.2 g on every component for 0.3 s), then left alone. Its light bars (15-25 mg) hang between plates
// that touch their siblings, so contacts close loops through the joints (parent, child, contact,
// sibling). It stopped at t = 0.6 s ("the joints could not be closed even with the step divided 256
// times"): the warm start of the joint impulses carried a force round such a loop that the contacts
// cancelled every step, the extrapolation doubled it, and its kick was rejected at every step length.
// Now it must run on: 0.7 s, every step taken, joints together, and no energy gained once left alone.
// (0.6 s in a release build, 9 s under AddressSanitizer and UBSan, which run it too since 2026-12-06: it
// is the suite's one look at a 1023-component tangle with the sanitizers on.)
TEST(Collisions, CrowdedGeneratedMobileInABreezeKeepsGoing) {
  GenerateOptions options;
  options.components = 1023;
  const Model model = compile(parse_mobile_text(generate_mobile(options), "generated-1023.json"));
  Simulation sim(model);
  ASSERT_TRUE(sim.collisions());
  set_breeze(model, sim.loads());
  ASSERT_TRUE(sim.advance(0.3)) << sim.failure()->message;
  sim.loads().clear();
  const double kinetic = kinetic_energy(model, sim.state());
  const double start = kinetic + potential_energy(model, sim.state());
  ASSERT_TRUE(sim.advance(0.4)) << sim.failure()->message;
  const double end = kinetic_energy(model, sim.state()) + potential_energy(model, sim.state());
  EXPECT_GT(sim.collision_statistics().impulses, 1000) << "the breeze should make the pieces knock";
  // Nothing reached past the middle of the thinnest piece near it (see the Steel Fish above).
  EXPECT_LT(sim.collision_statistics().deepest_relative, 1.0);
  // Joints together (the core's bound).
  EXPECT_LT(max_joint_separation(model, sim.state()), 1e-6);
  // Left alone (the file's light air damping and the contacts only take energy out): the same allowance as
  // the Steel Fish's above, the integrator's error (1e-4 of the kinetic energy) and the lift of the
  // overlap correction (1e-4 m times the weight).
  EXPECT_LT(end - start, 1e-4 * kinetic + 9.81 * model.balance.total_mass * 1e-4);
}

}  // namespace
}  // namespace aloft
