#pragma once
// The gyroscopic torque -w x (I w) over one step, treated with the implicit midpoint rule.
//
// Explicit evaluation of -w x I w at the start of a step makes a thin spinning plate gain energy step
// after step. The implicit midpoint rule applied to Euler's free-body equation,
//     I (w' - w) = -h w_m x (I w_m),   w_m = (w + w') / 2       (body frame),
// conserves both the kinetic energy and |I w| exactly, for any step. We take one Newton step on it
// from w' = w (the equation is quadratic, so the error is O((h|w|)^3) relative) and hand the constrained
// solve the torque -w_m x I w_m it implies, rotated to world axes. For an unconstrained body this is the
// implicit midpoint rule; with joints it is a consistent, energy-neutral treatment of the term.

#include "aloft/math.hpp"

namespace aloft {

// World-frame gyroscopic torque (N m) for a body with world angular velocity `w` (rad/s), principal
// moments `moments` (kg m^2) and orientation `q` (body -> world), over a step of `h` seconds.
Vec3 midpoint_gyroscopic_torque(const Quat& q, const Vec3& moments, const Vec3& w, double h);

}  // namespace aloft
