// The box around the part of a convex piece within a distance of another (see near_part.hpp).

#include "collision/near_part.hpp"

#include <algorithm>
#include <cmath>

namespace aloft::internal {

namespace {

// Rounding allowance (m) on every radius and slab: the sets must enclose what they stand for even
// where a point lies on their boundary.
constexpr double kSlack = 1e-9;

// The t for which p0 + t d lies within `radius` of c (an interval of the whole line); false when none.
bool line_in_ball(const Vec3& p0, const Vec3& d, const Vec3& c, double radius, double& t0, double& t1) {
  const Vec3 f = p0 - c;
  const double a = d.squaredNorm(), b = f.dot(d), cc = f.squaredNorm() - radius * radius;
  if (!(a > 0)) {
    if (cc > 0) return false;
    t0 = -INFINITY, t1 = INFINITY;
    return true;
  }
  const double discriminant = b * b - a * cc;
  if (discriminant < 0) return false;
  const double root = std::sqrt(discriminant);
  t0 = (-b - root) / a, t1 = (-b + root) / a;
  return true;
}

// The t for which p0 + t d lies within `radius` of the axis line through s0 along u and between the
// planes through s0 and s0 + u square to it (the side of a finite cylinder); false when none.
bool line_in_cylinder_side(const Vec3& p0, const Vec3& d, const Vec3& s0, const Vec3& u, double radius, double& t0,
                           double& t1) {
  const double u2 = u.squaredNorm();
  if (!(u2 > 0)) return false;
  const Vec3 f = p0 - s0;
  const Vec3 d_across = d - u * (d.dot(u) / u2), f_across = f - u * (f.dot(u) / u2);
  if (!line_in_ball(f_across, d_across, Vec3::Zero(), radius, t0, t1)) return false;
  // Between the end planes: 0 <= (f + t d) . u <= |u|^2.
  const double start = f.dot(u), rate = d.dot(u);
  if (rate == 0) return start >= 0 && start <= u2;
  double e0 = -start / rate, e1 = (u2 - start) / rate;
  if (e0 > e1) std::swap(e0, e1);
  t0 = std::max(t0, e0), t1 = std::min(t1, e1);
  return t0 <= t1;
}

// Narrows [t0, t1] (parameters along p0 + t d, coordinates of the frame `axis` and the extents are in) to
// where the point lies in the slab low - grow <= axis . p <= high + grow. False when that leaves nothing.
bool clip_to_slab(const Vec3& p0, const Vec3& d, const Vec3& axis, double low, double high, double grow, double& t0,
                  double& t1) {
  const double start = axis.dot(p0), rate = axis.dot(d);
  low -= grow + kSlack, high += grow + kSlack;
  if (rate == 0) return start >= low && start <= high && t0 <= t1;
  double e0 = (low - start) / rate, e1 = (high - start) / rate;
  if (e0 > e1) std::swap(e0, e1);
  t0 = std::max(t0, e0), t1 = std::min(t1, e1);
  return t0 <= t1;
}

// Narrows the box [low, high] to a box around its intersection with the half-space m . p <= c (box
// coordinates). False when the intersection is empty.
bool cut_box(const Vec3& m, double c, Vec3& low, Vec3& high) {
  double least = 0;  // the least value of m . p over the box
  for (int i = 0; i < 3; ++i) least += std::min(m[i] * low[i], m[i] * high[i]);
  if (least > c) return false;
  const Vec3 low0 = low, high0 = high;
  for (int i = 0; i < 3; ++i) {
    if (m[i] == 0) continue;
    const double rest = least - std::min(m[i] * low0[i], m[i] * high0[i]);
    const double limit = (c - rest) / m[i];
    if (m[i] > 0) high[i] = std::min(high[i], limit);
    else low[i] = std::max(low[i], limit);
  }
  return true;
}

bool box_empty(const Vec3& low, const Vec3& high) {
  return !(low.x() <= high.x() && low.y() <= high.y() && low.z() <= high.z());
}

// The interval of t in [t0, t1] for which p0 + t (p1 - p0) (world) lies within `grow` of the polytope or
// sphere z: inside z's enclosing ball and, for a polytope, inside each of its slabs, all grown by `grow`.
bool clip_segment_near_solid(const Vec3& p0, const Vec3& p1, const ConvexPiece& z, const Pose& pose_z, double grow,
                             double& t0, double& t1) {
  double b0, b1;
  const bool sphere = z.kind == ConvexPiece::Kind::Sphere;
  const Vec3 center = pose_z.to_world(sphere ? z.a : z.bound_center);
  const double radius = (sphere ? z.radius : z.bound_radius) + grow + kSlack;
  if (!line_in_ball(p0, p1 - p0, center, radius, b0, b1)) return false;
  t0 = std::max(t0, b0), t1 = std::min(t1, b1);
  if (t0 > t1) return false;
  if (z.kind != ConvexPiece::Kind::Polytope) return true;
  // Slabs in z's body frame.
  const Mat3 to_body = pose_z.rotation.transpose();
  const Vec3 q0 = to_body * (p0 - pose_z.position), q1 = to_body * (p1 - pose_z.position);
  for (std::size_t k = 0; k < z.axes.size(); ++k)
    if (!clip_to_slab(q0, q1 - q0, z.axes[k], z.axis_low[k], z.axis_high[k], grow, t0, t1)) return false;
  return true;
}

}  // namespace

bool clip_segment_to_capsule(const Vec3& p0, const Vec3& p1, const Vec3& s0, const Vec3& s1, double radius,
                             double& t0, double& t1) {
  const Vec3 d = p1 - p0;
  double lo = INFINITY, hi = -INFINITY, a, b;
  // A capsule is the union of its two end balls and the side of its cylinder; the line meets each in an
  // interval and, the capsule being convex, their union is one interval.
  if (line_in_ball(p0, d, s0, radius, a, b)) lo = std::min(lo, a), hi = std::max(hi, b);
  if (line_in_ball(p0, d, s1, radius, a, b)) lo = std::min(lo, a), hi = std::max(hi, b);
  if (line_in_cylinder_side(p0, d, s0, s1 - s0, radius, a, b)) lo = std::min(lo, a), hi = std::max(hi, b);
  t0 = std::max(lo, 0.0), t1 = std::min(hi, 1.0);
  return t0 <= t1;
}

void near_part_box(const ConvexPiece& x, const Pose& pose_x, const ConvexPiece& y, const Pose& pose_y, double rho,
                   Vec3& low, Vec3& high) {
  using Kind = ConvexPiece::Kind;
  low = x.box_low, high = x.box_high;
  if (x.kind == Kind::Cylinder) {
    // The part of x's axis within rho + x's radius of y.
    const Vec3 p0 = pose_x.to_world(x.a), p1 = pose_x.to_world(x.b);
    const double grow = rho + x.radius;
    double t0 = 0, t1 = 1;
    const bool near = y.kind == Kind::Cylinder
                          ? clip_segment_to_capsule(p0, p1, pose_y.to_world(y.a), pose_y.to_world(y.b),
                                                    y.radius + grow + kSlack, t0, t1)
                          : clip_segment_near_solid(p0, p1, y, pose_y, grow, t0, t1);
    if (!near) return;  // (rounding: the pair was found within rho) keep the whole box
    const Vec3 e0 = x.a + t0 * (x.b - x.a), e1 = x.a + t1 * (x.b - x.a);
    const Vec3 r = Vec3::Constant(x.radius + kSlack);
    low = low.cwiseMax(e0.cwiseMin(e1) - r), high = high.cwiseMin(e0.cwiseMax(e1) + r);
    if (box_empty(low, high)) low = x.box_low, high = x.box_high;
    return;
  }
  // x a sphere or a polytope: cut its box by the sets enclosing N(y), expressed in x's body frame.
  const Mat3 to_x = pose_x.rotation.transpose();
  const auto in_x = [&](const Vec3& world) { return Vec3(to_x * (world - pose_x.position)); };
  Vec3 s0, s1;  // y's core (a segment, or a point) and the radius about it, world
  double radius;
  if (y.kind == Kind::Cylinder) {
    s0 = pose_y.to_world(y.a), s1 = pose_y.to_world(y.b);
    double t0 = 0, t1 = 1;
    if (clip_segment_near_solid(s0, s1, x, pose_x, rho + y.radius, t0, t1)) {
      const Vec3 c0 = s0 + t0 * (s1 - s0), c1 = s0 + t1 * (s1 - s0);
      s0 = c0, s1 = c1;
    }
    radius = y.radius + rho;
  } else if (y.kind == Kind::Sphere) {
    s0 = s1 = pose_y.to_world(y.a);
    radius = y.radius + rho;
  } else {
    s0 = s1 = pose_y.to_world(y.bound_center);
    radius = y.bound_radius + rho;
  }
  const Vec3 q0 = in_x(s0), q1 = in_x(s1), r = Vec3::Constant(radius + kSlack);
  Vec3 l = low.cwiseMax(q0.cwiseMin(q1) - r), h = high.cwiseMin(q0.cwiseMax(q1) + r);
  if (box_empty(l, h)) return;
  if (y.kind == Kind::Polytope) {
    // y's slabs: lo - rho <= a . (y body coordinates) <= hi + rho, with y body coordinates
    // R_y^T (p_x + R_x p - p_y) for p in x's body frame.
    const Mat3 x_to_y = pose_y.rotation.transpose() * pose_x.rotation;
    const Vec3 offset = pose_y.rotation.transpose() * (pose_x.position - pose_y.position);
    for (std::size_t k = 0; k < y.axes.size(); ++k) {
      const Vec3 m = x_to_y.transpose() * y.axes[k];
      const double c0 = y.axes[k].dot(offset);
      if (!cut_box(m, y.axis_high[k] + rho + kSlack - c0, l, h) ||
          !cut_box(-m, -(y.axis_low[k] - rho - kSlack - c0), l, h))
        return;  // (rounding) keep the whole box
    }
  }
  if (box_empty(l, h)) return;
  low = l, high = h;
}

}  // namespace aloft::internal
