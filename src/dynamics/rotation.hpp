#pragma once
// Turning an orientation by a rotation vector, as the step's drift does (Simulation, rattle's step 2).

#include <cmath>

#include "aloft/math.hpp"

namespace aloft {

// exp(theta / 2) q, renormalised: the orientation q turned by the rotation vector `theta` (rad, world).
// Written out in scalars (the quaternion product vectorises poorly at this size).
[[gnu::always_inline]] inline Quat turned(const Vec3& theta, const Quat& q) {
  const double a2 = theta.squaredNorm();
  double c, s;
  if (a2 < 1e-4) {
    // Taylor series of cos(a/2) and sin(a/2)/a to a^4; the first neglected terms are below
    // a^6/46080 < 3e-17 for a < 1e-2.
    c = 1.0 - a2 / 8.0 + a2 * a2 / 384.0;
    s = 0.5 - a2 / 48.0 + a2 * a2 / 3840.0;
  } else {
    const double a = std::sqrt(a2);
    c = std::cos(0.5 * a);
    s = std::sin(0.5 * a) / a;
  }
  const double x = s * theta.x(), y = s * theta.y(), z = s * theta.z();
  // (c, v) (w, u) = (c w - v.u, c u + w v + v x u)
  const double rw = c * q.w() - (x * q.x() + y * q.y() + z * q.z());
  const double rx = c * q.x() + q.w() * x + (y * q.z() - z * q.y());
  const double ry = c * q.y() + q.w() * y + (z * q.x() - x * q.z());
  const double rz = c * q.z() + q.w() * z + (x * q.y() - y * q.x());
  // Both factors are unit to rounding, so |r|^2 = 1 + e with |e| ~ 1e-16: one Newton step for
  // 1/sqrt(1 + e), (3 - |r|^2) / 2, renormalises to O(e^2) ~ 1e-32 without a square root or a division.
  // (An orientation set from outside that is not unit, |e| >= 1e-8, is normalised exactly.)
  const double norm2 = rw * rw + rx * rx + ry * ry + rz * rz;
  const double inverse_norm = std::abs(norm2 - 1.0) < 1e-8 ? 0.5 * (3.0 - norm2) : 1.0 / std::sqrt(norm2);
  return Quat(rw * inverse_norm, rx * inverse_norm, ry * inverse_norm, rz * inverse_norm);
}

}  // namespace aloft
