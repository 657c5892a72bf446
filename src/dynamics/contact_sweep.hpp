#pragma once
// A contact's motion through a step, checked by moving its two components as the step's drift will.
//
// contact_travel.hpp bounds from the velocities alone how much deeper a contact's pieces can get in a step,
// and Simulation also accepts a step whose pieces in contact travel little. Where both fail (a light bar a
// knock sent spinning at tens of rad/s against a plate), the step used to be halved; on a large mobile some
// pair is nearly always in that state, so every step of the whole mobile was (generated-1023 from the
// benchmarks' swinging state: 1.57 halvings per step). The bounds are conservative: most of the motion they
// count turns a piece past its neighbour, not into it. So such a contact is checked against the motion
// itself: its two components are moved as the drift moved them (x + t v, exp(t w_p) exp(t w_m) q, w_m
// the drift's midpoint angular velocity and v, w_p the velocity and the split impulse's turn that pushes
// overlaps apart: at t = h exactly the pose the step ends at) to k evenly spaced times through the step,
// and the pair's signed distance is measured there by the narrow phase
// (CollisionDetector::signed_distance).
//
// The step may go on when at no sample the pair overlaps by more than `start_overlap + allowed`: the end
// state the deepening bound allows, measured instead of bounded. For the measurement to mean that, no
// piece may pass its neighbour's middle between two samples (the narrow phase would then see the overlap
// from the far side, small or none). The points that can reach the other component within the step are
// the near parts of the pieces in contact (Contact::near_low_a ..., collision/near_part.hpp); between two
// samples each of them moves by at most travel / k relative to the other body, travel the sum of the two
// bodies' `travel` (the fastest point of each near box times h). With k = ceil(travel / (thinnest -
// start_overlap - allowed)) the overlap stays below `thinnest` (the thinnest piece's half-width) between
// samples: no piece reaches the middle of the thinnest one, and every sample's overlap is the true one.
//
// Motion that would need more than kMaxSweepSamples samples is not checked (the step is halved, as
// before). tests/dynamics/test_contact_sweep.cpp checks the sampled motion against the drift and the
// decisions against a fine scan of the motion.

#include "aloft/collision.hpp"
#include "aloft/math.hpp"

namespace aloft {

// One side of the contact: where it is at the start of the step and how the drift moves it.
struct SweptBody {
  bool fixed = false;                       // the hook: never moves
  Vec3 position = Vec3::Zero();             // centre of mass, world (m)
  Quat orientation = Quat::Identity();      // principal frame -> world
  Vec3 velocity = Vec3::Zero();             // m/s, world: the drift's, with the overlap push's
  Vec3 drift_angular = Vec3::Zero();        // rad/s, world: the drift's midpoint angular velocity w_m
  Vec3 push_angular = Vec3::Zero();         // rad/s, world: the overlap push's turn, after the drift's
  double travel = 0;                        // m: how far any point of the near part moves in the step
};

// Samples at most this many poses per contact and step: each is a narrow-phase measurement of the pair
// (about a microsecond per pair of pieces near each other); 32 cost less than a step of a mobile of a
// hundred components, which a halving costs the whole mobile.
inline constexpr int kMaxSweepSamples = 32;

struct SweepResult {
  bool shallow = false;  // sampled finely enough, and never deeper than allowed
  int samples = 0;       // poses measured (0: too fast to sample, or no room below the thinnest middle)
  double deepest = 0;    // m: the largest overlap measured at a sample (>= 0)
};

// The pose of `body` at time t (s) into the step.
void swept_pose(const SweptBody& body, double t, Vec3& position, Quat& orientation);

// Components a and b of a contact moving through a step of h seconds. start_overlap (m, >= 0): their
// largest overlap at the start of the step; allowed (m): how much deeper they may end up; thinnest (m):
// the smallest half-width of their pieces in contact (Contact::thinnest).
SweepResult sweep_contact(const CollisionDetector& detector, int a, const SweptBody& body_a, int b,
                          const SweptBody& body_b, double h, double start_overlap, double allowed, double thinnest);

}  // namespace aloft
