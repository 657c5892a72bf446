// Closed-form contacts: sphere-sphere, cylinder-sphere, cylinder-cylinder side to side; and the closest
// points of two segments (two wires' capsules). World frame, m.

#include <algorithm>
#include <cmath>

#include "collision/narrow_phase.hpp"

namespace aloft::internal {

namespace {

// Any unit vector perpendicular to v (v != 0), chosen deterministically.
Vec3 any_perpendicular(const Vec3& v) {
  const Vec3 other = std::abs(v.x()) < 0.9 * v.norm() ? Vec3::UnitX() : Vec3::UnitY();
  return v.cross(other).normalized();
}

}  // namespace

PieceContact sphere_sphere(const Vec3& ca, double ra, const Vec3& cb, double rb) {
  PieceContact c;
  const Vec3 d = ca - cb;
  const double len = d.norm();
  // Concentric spheres: any direction separates them equally; +y is the documented choice.
  c.normal = len > 0 ? Vec3(d / len) : Vec3::UnitY();
  c.distance = len - ra - rb;
  const Vec3 on_a = ca - ra * c.normal, on_b = cb + rb * c.normal;
  c.point = 0.5 * (on_a + on_b);
  return c;
}

PieceContact cylinder_sphere(const Vec3& from, const Vec3& to, double rc, const Vec3& center, double rs) {
  // Signed distance from the sphere's centre to the solid cylinder, with the outward unit normal n of
  // the cylinder at the closest (or, inside, the nearest boundary) point.
  const Vec3 axis = to - from;
  const double len = axis.norm();
  const Vec3 u = len > 0 ? Vec3(axis / len) : any_perpendicular(Vec3::UnitX());
  const Vec3 rel = center - from;
  const double t = rel.dot(u);            // along the axis, from `from`
  const Vec3 radial = rel - t * u;        // across the axis
  const double rho = radial.norm();
  const Vec3 out_radial = rho > 0 ? Vec3(radial / rho) : any_perpendicular(u);

  double signed_distance;
  Vec3 n;
  if (t >= 0 && t <= len && rho <= rc) {
    // Inside: the nearest of the side and the two end faces.
    signed_distance = -(rc - rho);
    n = out_radial;
    if (t < -signed_distance) signed_distance = -t, n = -u;
    if (len - t < -signed_distance) signed_distance = -(len - t), n = u;
  } else {
    const double tc = std::clamp(t, 0.0, len);
    const Vec3 closest = from + tc * u + std::min(rho, rc) * out_radial;
    const Vec3 d = center - closest;
    signed_distance = d.norm();
    n = d / signed_distance;  // > 0: the centre is outside
  }
  // Normal from b (the sphere) towards a (the cylinder) is -n.
  PieceContact c;
  c.normal = -n;
  c.distance = signed_distance - rs;
  const Vec3 on_cylinder = center - signed_distance * n, on_sphere = center - rs * n;
  c.point = 0.5 * (on_cylinder + on_sphere);
  return c;
}

bool cylinder_cylinder_sides(const Vec3& pa, const Vec3& qa, double ra, const Vec3& pb, const Vec3& qb,
                             double rb, PieceContact& out) {
  // Closest points of the two axis segments (Ericson, Real-Time Collision Detection 5.1.9), with the
  // parallel case handed to GJK.
  const Vec3 d1 = qa - pa, d2 = qb - pb, r = pa - pb;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const double c = d1.dot(r), b = d1.dot(d2);
  const double denom = a * e - b * b;           // |d1 x d2|^2 >= 0
  if (!(a > 0 && e > 0) || denom <= 1e-12 * a * e) return false;  // degenerate or (nearly) parallel
  const double s = (b * f - c * e) / denom;     // unclamped closest point on line a
  const double t = (b * s + f) / e;             // closest point on line b to it
  if (!(s > 0 && s < 1 && t > 0 && t < 1)) return false;
  const Vec3 on_a = pa + s * d1, on_b = pb + t * d2;
  Vec3 d = on_a - on_b;
  const double len = d.norm();
  // Crossing axes: the common normal of the two directions, turned to point from b's middle to a's.
  Vec3 n;
  if (len > 1e-12 * std::sqrt(a + e)) {
    n = d / len;
  } else {
    n = d1.cross(d2).normalized();
    if (n.dot((pa + 0.5 * d1) - (pb + 0.5 * d2)) < 0) n = -n;
  }
  out.normal = n;
  out.distance = len - ra - rb;
  out.point = 0.5 * ((on_a - ra * n) + (on_b + rb * n));
  return true;
}

SegmentClosest segment_segment(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  // Ericson, Real-Time Collision Detection 5.1.9: minimise |p0 + s d1 - (q0 + t d2)| over s, t in [0, 1],
  // the parameter of one segment clamped and the other's recomputed from it (and clamped in turn).
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (!(a > 0) && !(e > 0)) {
    // Both points.
  } else if (!(a > 0)) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (!(e > 0)) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;  // |d1 x d2|^2 >= 0; 0 when parallel: any s, take 0
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  SegmentClosest out;
  out.on_p = p0 + s * d1;
  out.on_q = q0 + t * d2;
  out.distance = (out.on_p - out.on_q).norm();
  return out;
}

}  // namespace aloft::internal
