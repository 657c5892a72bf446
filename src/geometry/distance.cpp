// Distance (m) from a world point to a solid shape (0 on or inside it), and world axis-aligned bounds.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <limits>
#include <variant>

#include "aloft/geometry.hpp"
#include "common/overloaded.hpp"

namespace aloft {
namespace {

constexpr double kPi = std::numbers::pi;

using internal::Overloaded;

// Distance from p to the closed segment [a, b] in the plane.
double segment_distance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

// Distance from p to the region bounded by a simple polygon (0 inside), by the crossing-number rule.
double polygon_region_distance(const std::vector<Vec2>& pts, const Vec2& p) {
  const size_t n = pts.size();
  bool inside = false;
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2 &a = pts[j], &b = pts[i];
    best = std::min(best, segment_distance(p, a, b));
    // Half-open rule on y so that a vertex on the ray is counted once.
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const double x = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
      if (p.x() < x) inside = !inside;
    }
  }
  return inside ? 0.0 : best;
}

// Closest point to p on triangle (a, b, c): by the Voronoi region of p among the triangle's vertices,
// edges and face, using barycentric coordinates.
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;  // edge ab
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;  // edge ac
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);  // bc
  const double denom = va + vb + vc;
  if (!(denom != 0)) return a;  // degenerate triangle whose edges were all rejected: any vertex will do
  return a + ab * (vb / denom) + ac * (vc / denom);
}

// Signed solid angle (sr) of triangle (a, b, c) seen from p (Van Oosterom & Strackee 1983); positive
// when the triangle is counter-clockwise seen from p.
double solid_angle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 x = a - p, y = b - p, z = c - p;
  const double lx = x.norm(), ly = y.norm(), lz = z.norm();
  const double num = x.dot(y.cross(z));
  const double den = lx * ly * lz + x.dot(y) * lz + x.dot(z) * ly + y.dot(z) * lx;
  return 2 * std::atan2(num, den);
}

double mesh_distance(const TriangleMesh& m, const Vec3& p) {
  const int nv = static_cast<int>(m.vertices.size());
  auto valid = [nv](const std::array<int, 3>& t) {
    return t[0] >= 0 && t[0] < nv && t[1] >= 0 && t[1] < nv && t[2] >= 0 && t[2] < nv;
  };
  double best2 = std::numeric_limits<double>::infinity();
  for (const auto& t : m.triangles) {
    if (!valid(t)) continue;
    const Vec3 q = closest_on_triangle(p, m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]);
    best2 = std::min(best2, (q - p).squaredNorm());
  }
  if (best2 == 0) return 0;
  // Inside a closed surface the triangles' solid angles add up to +-4 pi (the winding number is +-1;
  // -1 for an inside-out mesh), outside to 0.
  double total = 0;
  for (const auto& t : m.triangles)
    if (valid(t)) total += solid_angle(p, m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]);
  if (std::abs(total) > 2 * kPi) return 0;
  return std::sqrt(best2);
}

}  // namespace

double distance_to_shape(const Shape& shape, const Vec3& point) {
  return std::visit(
      Overloaded{
          [&](const Sphere& s) { return std::max(0.0, (point - s.center).norm() - s.radius); },
          [&](const Wire& w) {
            // A solid cylinder is a disc times a segment: the distance combines the radial and the
            // axial excess orthogonally.
            const Vec3 axis = w.to - w.from;
            const double length = axis.norm();
            const Vec3 rel = point - (w.from + w.to) / 2;
            // Zero length leaves no axis: measure to the ball of the wire's radius instead.
            if (!(length > 0)) return std::max(0.0, rel.norm() - w.radius);
            const Vec3 d = axis / length;
            const double along = rel.dot(d);
            const double radial = (rel - along * d).norm();
            const double da = std::max(0.0, std::abs(along) - length / 2);
            const double dr = std::max(0.0, radial - w.radius);
            return std::hypot(da, dr);
          },
          [&](const Box& b) {
            const Vec3 local = b.rotation.transpose() * (point - b.center);
            return (local.cwiseAbs() - b.size / 2).cwiseMax(0.0).norm();
          },
          [&](const Plate& p) {
            // A plate is the polygon times [-thickness/2, thickness/2] along the normal.
            const Vec3 rel = point - p.origin;
            const Vec2 uv(rel.dot(p.u_axis), rel.dot(p.v_axis));
            const double dh = std::max(0.0, std::abs(rel.dot(p.normal())) - p.thickness / 2);
            if (p.points.size() < 3) return std::numeric_limits<double>::infinity();
            return std::hypot(polygon_region_distance(p.points, uv), dh);
          },
          [&](const Mesh& m) { return mesh_distance(m.mesh, point); },
      },
      shape);
}

Bounds shape_bounds(const Shape& shape) {
  Bounds bounds;
  std::visit(Overloaded{
                 [&](const Sphere& s) {
                   bounds.add(s.center - Vec3::Constant(s.radius));
                   bounds.add(s.center + Vec3::Constant(s.radius));
                 },
                 [&](const Wire& w) {
                   // The end discs' extent along world axis i is r sqrt(1 - d_i^2), d the unit axis.
                   const Vec3 axis = w.to - w.from;
                   const double length = axis.norm();
                   Vec3 extent = Vec3::Constant(w.radius);
                   if (length > 0) {
                     const Vec3 d = axis / length;
                     for (int i = 0; i < 3; ++i) extent[i] = w.radius * std::sqrt(std::max(0.0, 1 - d[i] * d[i]));
                   }
                   for (const Vec3& end : {w.from, w.to}) {
                     bounds.add(end - extent);
                     bounds.add(end + extent);
                   }
                 },
                 [&](const Box& b) {
                   const Vec3 extent = b.rotation.cwiseAbs() * (b.size / 2);
                   bounds.add(b.center - extent);
                   bounds.add(b.center + extent);
                 },
                 [&](const Plate& p) {
                   const Vec3 half = p.normal() * (p.thickness / 2);
                   for (const Vec2& q : p.points) {
                     bounds.add(p.to_world(q) - half);
                     bounds.add(p.to_world(q) + half);
                   }
                 },
                 [&](const Mesh& m) {
                   for (const Vec3& v : m.mesh.vertices) bounds.add(v);
                 },
             },
             shape);
  return bounds;
}

}  // namespace aloft
