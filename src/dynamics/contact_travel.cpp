#include "dynamics/contact_travel.hpp"

#include <algorithm>
#include <cmath>

namespace aloft {

namespace {

// The largest value of (q - p) . k over the box [low, high] (principal frame of a body at `side`'s pose)
// and of |q - p|: both at a corner (a linear and a convex function of q). k and p in world coordinates.
struct BoxExtent {
  double along = 0;    // m times |k|
  double farthest = 0; // m
};

BoxExtent box_extent(const ContactSide& side, const Vec3& p, const Vec3& k) {
  const Quat to_body = side.orientation.conjugate();
  const Vec3 k_body = to_body * k;
  const Vec3 offset = to_body * (side.position - p);  // from p to the centre of mass, principal frame
  BoxExtent e;
  e.along = side.near_low.cwiseProduct(k_body).cwiseMax(side.near_high.cwiseProduct(k_body)).sum() + offset.dot(k_body);
  e.farthest = (side.near_low + offset).cwiseAbs().cwiseMax((side.near_high + offset).cwiseAbs()).norm();
  return e;
}

}  // namespace

double contact_deepening_bound(const Contact& contact, const ContactSide& a, const ContactSide& b, double h,
                               bool approach) {
  const Vec3& p = contact.point;
  const Vec3& n = contact.normal;
  const Vec3 relative_velocity =
      (a.velocity + a.angular.cross(p - a.position)) - (b.velocity + b.angular.cross(p - b.position));
  // Seen from b's frame (a's points past b's plane) and from a's (b's points past a's plane): the turn,
  // the larger of -(q - p) . (n x (w_a - w_b)) h over the moving side's box, and the frame's share of the
  // curvature allowance (see the header); the smaller of the two bounds holds.
  const Vec3 k = -h * n.cross(a.angular - b.angular);
  const BoxExtent on_a = box_extent(a, p, k), on_b = box_extent(b, p, k);
  const double precession_a = 0.5 * h * h * a.precession.norm(), precession_b = 0.5 * h * h * b.precession.norm();
  const double theta_a = h * a.angular.norm() + precession_a, theta_b = h * b.angular.norm() + precession_b;
  const double travel = h * relative_velocity.norm();
  const double in_b_frame = std::max(0.0, on_a.along) +
                            theta_b * (travel + (theta_a + 1.5 * theta_b) * on_a.farthest);
  const double in_a_frame = std::max(0.0, on_b.along) +
                            theta_a * (travel + (1.5 * theta_a + theta_b) * on_b.farthest);
  // Both frames: each body's arcs and precession.
  const double curvature = (precession_a + 0.5 * theta_a * theta_a) * a.reach +
                           (precession_b + 0.5 * theta_b * theta_b) * b.reach;
  // Every point of either piece starts at least the gap from the other's supporting plane, and moves
  // towards it by at most the approach at p (which may be negative: separating) plus the turn and the
  // curvature allowance: only what exceeds the gap sinks past the plane. Without the approach (before the
  // contact impulses, which let the contact close at most its gap), the approach is taken as the gap.
  const double gap = std::max(contact.distance, 0.0);
  const double closing = approach ? -h * relative_velocity.dot(n) : gap;
  return std::max(0.0, closing + std::min(in_b_frame, in_a_frame) + curvature - gap);
}

}  // namespace aloft
