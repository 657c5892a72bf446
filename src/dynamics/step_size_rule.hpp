#pragma once
// When a step of length h is short enough: the rule Simulation::rattle() checks after the first half
// kick (and before collision detection), halving the step where it fails.
//
// The step's drift turns each body as a free rigid body at constant world angular momentum L = I w by
// the implicit midpoint rule (see simulation.cpp). That rule is exact for a constant angular velocity,
// so how fast a body turns is not what limits h: what does is
//
//  1. the drift's local error, the rotation e (rad, world) between the drift's new orientation and the
//     free body's exact one after h (drift_error() below: its leading term, O(h^3)), measured by how far
//     it moves the body's mass: the RMS displacement over the RMS distance of the mass from the centre,
//     sqrt(e^T I e / (tr I / 2)) (rad; <= |e|, since no principal moment exceeds the sum of the other
//     two). It must stay below what the old rule ("no body turns more than kOldTurnLimit = 0.05 rad in a
//     step") accepted for the same body at its limit, turning 0.05 rad about its worst axis: so no step
//     is less accurate than the old rule allowed that body to be. For a body of moments 1 : 2 : 3 that is
//     8.9e-6 rad, for a 1 : 30 : 31 bar 3.3e-5 rad, for a sphere zero (its drift is exact; the tolerance
//     has a floor, kMinDriftError, for rounding).
//  2. the turn of each joint anchor in the step, h |w x a| / |a| (rad) for every anchor a of a body with
//     angular velocity w: the joint impulses are found by Newton's method with the Jacobian of the step's
//     start, whose lever arms are off by that angle at the end of the step, and contacts are predicted
//     along straight lines. The Jacobian's lever arms are off by that angle at the step's end, so each
//     Newton correction leaves roughly that fraction of the joint gap: kMaxAnchorTurn = 0.1 rad still
//     closes a 1e-4 m gap (what the warm start leaves) to the 1e-9 m tolerance in 5 of the 8 corrections
//     allowed. (The old rule held anchors to 0.05 rad; on the generated mobiles, whose light bars hang from
//     points 2-3 cm off their axis, 0.05 was what halved most steps, while 0.1 needed no more Newton
//     corrections per step: docs/performance.md, "Step-size rule".)
//  3. the whole turn h |w| (rad), below kMaxTurn: it keeps the O(h^3) term a good estimate of the error
//     (measured against an RK4 integration: within 6 % for a 1 : 2 : 3 body turning 0.18 rad, 8 % for the
//     bar below at 0.19 rad, 17 % for a near-symmetric plate, moments 1 : 1.1 : 2.1, at 0.16 rad) and bounds the collision detector's speculative margins, h |w| times a
//     component's reach.
//
// A thin bar spinning fast about its axis of least inertia (the light bars of generated mobiles, flung by
// a breeze) has a small error in 1 for its turn, so it keeps a longer step than the old |w| rule gave it.

#include <vector>

#include "aloft/math.hpp"
#include "aloft/model.hpp"

namespace aloft {

// The rule's limits, see the top of this file. kOldTurnLimit (rad per step) sets the drift-error tolerance
// of each body; kMinDriftError (rad) is a floor for it, for bodies with nearly equal moments whose
// computed error is mostly rounding (1e-9 rad moves a point 1 m away by 1 nm, the joints' tolerance).
inline constexpr double kOldTurnLimit = 0.05;
inline constexpr double kMinDriftError = 1e-9;
inline constexpr double kMaxAnchorTurn = 0.1;   // rad per step
inline constexpr double kMaxTurn = 0.2;         // rad per step

// Leading term of the local error of one drift of length h (s): the rotation vector (rad, world) that
// takes the free body's exact orientation after h to the midpoint drift's, for angular velocity `angular`
// (rad/s, world) and world inertia `inertia` (kg m^2) at the step's start (inverse_inertia its inverse).
// With L = I w conserved, w' = I^-1 (L x w) and, from d(I w')/dt = L x w', the exact rotation vector is
// (Magnus) h w + h^2/2 w' + h^3/6 w'' - h^3/12 w x w'; the drift's, whose midpoint orientation is off by
// -h^2/8 w', is h w + h^2/2 w' + h^3/8 w'' - h^3/8 (w' x w - I^-1 (w' x L)). Their difference is
//   e = h^3 [ (w x w') / 6 + I^-1 ( w x (L x w) / 24 - (L x w') / 6 ) ] + O(h^4).
Vec3 drift_error(const Vec3& angular, const Mat3& inertia, const Mat3& inverse_inertia, double h);

// The worst of each of the rule's measures over all moving bodies, as fractions of their limits
// (a step is accepted when all three are <= 1), and the bodies where they occur.
struct StepSizeMeasures {
  double drift_error = 0;  // measure 1 / the body's drift_tolerance()
  double anchor_turn = 0;  // measure 2 / kMaxAnchorTurn
  double turn = 0;         // measure 3 / kMaxTurn
  int drift_error_body = 0, anchor_turn_body = 0, turn_body = 0;
};

class StepSizeRule {
 public:
  explicit StepSizeRule(const Model& model);

  // Whether a step of h (s) is short enough for the angular velocities `angular` (rad/s, world, per
  // body; index 0 is the fixed hook and is ignored), at the pose whose world inertia, inverse inertia
  // and joint lever arms (joint i: child_arm[i] from body i's centre, parent_arm[i] from its parent's,
  // world, m) are given. False for non-finite angular velocities too.
  bool accepts(double h, const std::vector<Vec3>& angular, const std::vector<Mat3>& inertia,
               const std::vector<Mat3>& inverse_inertia, const std::vector<Vec3>& child_arm,
               const std::vector<Vec3>& parent_arm) const;

  // accepts() for body i alone (its angular velocity, world inertia and inverse), for a caller's own pass
  // over the bodies: the step's half kick checks each body as it kicks it, while its data are at hand,
  // instead of a pass of the rule's own over all of them. accepts() is true exactly when this is for
  // every moving body.
  [[gnu::always_inline]] bool accepts_body(int i, double h, const Vec3& angular, const Mat3& inertia,
                                           const Mat3& inverse_inertia, const std::vector<Vec3>& child_arm,
                                           const std::vector<Vec3>& parent_arm) const {
    const double turn2 = h * h * angular.squaredNorm();
    if (!(turn2 <= kMaxTurn * kMaxTurn)) return false;  // also a NaN
    // The anchors and the drift error only past their thresholds (see slow_checks).
    if (turn2 > kMaxAnchorTurn * kMaxAnchorTurn || turn2 > quiet_turn_squared_[i])
      return slow_checks(i, h, turn2, angular, inertia, inverse_inertia, child_arm, parent_arm);
    return true;
  }

  // The same measures in full (no early exit), for tests and diagnostics.
  StepSizeMeasures measure(double h, const std::vector<Vec3>& angular, const std::vector<Mat3>& inertia,
                           const std::vector<Mat3>& inverse_inertia, const std::vector<Vec3>& child_arm,
                           const std::vector<Vec3>& parent_arm) const;

  // Body i's tolerance for measure 1 (rad): what the old rule accepted for it.
  double drift_tolerance(int body) const { return drift_tolerance_[body]; }

  // (h |w|)^2 (rad^2) below which body i's drift error is certainly within its tolerance, so accepts()
  // need not compute it (infinite for a body with equal principal moments, whose drift is exact).
  double quiet_turn_squared(int body) const { return quiet_turn_squared_[body]; }

 private:
  // accepts_body()'s checks of the anchors (when the body turns more than kMaxAnchorTurn) and of the
  // drift error (when it turns more than sqrt(quiet_turn_squared)); turn2 = (h |w|)^2.
  bool slow_checks(int i, double h, double turn2, const Vec3& angular, const Mat3& inertia,
                   const Mat3& inverse_inertia, const std::vector<Vec3>& child_arm,
                   const std::vector<Vec3>& parent_arm) const;
  // Body i's drift-error measure (rad) for the error e (rad, world).
  double error_measure(int body, const Vec3& e, const Mat3& inertia) const;

  std::vector<std::vector<int>> children_;  // per body: the joints whose parent arm is on it
  std::vector<double> half_trace_;          // per body: tr(I) / 2 (kg m^2), the same in every frame
  std::vector<double> drift_tolerance_;     // per body, see drift_tolerance()
  std::vector<double> quiet_turn_squared_;  // per body, see quiet_turn_squared()
  std::vector<double> child_arm_squared_;   // per joint: |child arm|^2 (m^2), the same in every frame
  std::vector<double> parent_arm_squared_;  // per joint: |parent arm|^2 (m^2)
};

}  // namespace aloft
