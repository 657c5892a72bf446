// Closed, outward-oriented (counter-clockwise seen from outside) triangle meshes of every shape, in world
// coordinates (m); and shape_kind().

#include <algorithm>
#include <cmath>
#include <numbers>
#include <variant>

#include "aloft/geometry.hpp"
#include "common/overloaded.hpp"

namespace aloft {
namespace {

constexpr double kPi = std::numbers::pi;

using internal::Overloaded;

// UV sphere with the poles on the world y axis: `sectors` meridians, `rings` latitude bands. All vertices
// lie on the sphere, so the polyhedron is inscribed.
TriangleMesh sphere_mesh(const Sphere& s, int segments) {
  const int sectors = std::max(3, segments);
  const int rings = std::max(2, segments / 2);
  TriangleMesh m;
  m.vertices.reserve(2 + (rings - 1) * sectors);
  m.triangles.reserve(2 * sectors * (rings - 1));
  m.vertices.push_back(s.center + Vec3(0, s.radius, 0));  // north pole, index 0
  for (int i = 1; i < rings; ++i) {
    const double theta = kPi * i / rings;  // from the north pole
    for (int j = 0; j < sectors; ++j) {
      const double phi = 2 * kPi * j / sectors;
      m.vertices.push_back(s.center +
                           s.radius * Vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)));
    }
  }
  const int south = static_cast<int>(m.vertices.size());
  m.vertices.push_back(s.center - Vec3(0, s.radius, 0));
  auto ring = [&](int i, int j) { return 1 + (i - 1) * sectors + (j % sectors); };  // ring i in 1..rings-1
  // Increasing phi turns from +x towards +z, i.e. clockwise seen from +y: the north fan goes j+1 -> j.
  for (int j = 0; j < sectors; ++j) m.triangles.push_back({0, ring(1, j + 1), ring(1, j)});
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < sectors; ++j) {
      const int a0 = ring(i, j), a1 = ring(i, j + 1), b0 = ring(i + 1, j), b1 = ring(i + 1, j + 1);
      m.triangles.push_back({a0, a1, b1});
      m.triangles.push_back({a0, b1, b0});
    }
  for (int j = 0; j < sectors; ++j) m.triangles.push_back({south, ring(rings - 1, j), ring(rings - 1, j + 1)});
  return m;
}

// Regular prism with `segments` sides inscribed in the wire's cylinder, capped by fans around the end
// centres.
TriangleMesh wire_mesh(const Wire& w, int segments) {
  const int n = std::max(3, segments);
  const Vec3 axis = w.to - w.from;
  const double length = axis.norm();
  const Vec3 d = length > 0 ? Vec3(axis / length) : Vec3::UnitY();
  // e1, e2 perpendicular to d with e1 x e2 = d; e1 from the world axis least aligned with d.
  Vec3 ref = Vec3::Zero();
  int least = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(d[i]) < std::abs(d[least])) least = i;
  ref[least] = 1;
  const Vec3 e1 = (ref - ref.dot(d) * d).normalized();
  const Vec3 e2 = d.cross(e1);

  TriangleMesh m;
  m.vertices.reserve(2 * n + 2);
  m.triangles.reserve(4 * n);
  for (int j = 0; j < n; ++j) {
    const double phi = 2 * kPi * j / n;
    const Vec3 radial = w.radius * (std::cos(phi) * e1 + std::sin(phi) * e2);
    m.vertices.push_back(w.from + radial);  // bottom ring point j: index 2 j
    m.vertices.push_back(w.to + radial);    // top ring point j: index 2 j + 1
  }
  const int bottom_center = 2 * n, top_center = 2 * n + 1;
  m.vertices.push_back(w.from);
  m.vertices.push_back(w.to);
  auto B = [&](int j) { return 2 * (j % n); };
  auto T = [&](int j) { return 2 * (j % n) + 1; };
  // Increasing phi is counter-clockwise seen from +d (e1 x e2 = d).
  for (int j = 0; j < n; ++j) {
    m.triangles.push_back({top_center, T(j), T(j + 1)});
    m.triangles.push_back({bottom_center, B(j + 1), B(j)});
    m.triangles.push_back({B(j), B(j + 1), T(j + 1)});
    m.triangles.push_back({B(j), T(j + 1), T(j)});
  }
  return m;
}

TriangleMesh box_mesh(const Box& b) {
  TriangleMesh m;
  m.vertices.reserve(8);
  // Corner k has local coordinates (+-size/2) with bit 0, 1, 2 of k selecting + along x, y, z.
  for (int k = 0; k < 8; ++k) {
    const Vec3 local((k & 1 ? 0.5 : -0.5) * b.size.x(), (k & 2 ? 0.5 : -0.5) * b.size.y(),
                     (k & 4 ? 0.5 : -0.5) * b.size.z());
    m.vertices.push_back(b.center + b.rotation * local);
  }
  // Faces -x, +x, -y, +y, -z, +z as quads counter-clockwise seen from outside.
  static constexpr int kQuads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  const bool mirrored = b.rotation.determinant() < 0;  // a reflection turns the faces inside out
  m.triangles.reserve(12);
  for (const auto& q : kQuads) {
    if (mirrored) {
      m.triangles.push_back({q[0], q[2], q[1]});
      m.triangles.push_back({q[0], q[3], q[2]});
    } else {
      m.triangles.push_back({q[0], q[1], q[2]});
      m.triangles.push_back({q[0], q[2], q[3]});
    }
  }
  return m;
}

// The polygon extruded by +-thickness/2 along normal = u x v: vertex i is the bottom copy of point i,
// vertex n + i its top copy.
TriangleMesh plate_mesh(const Plate& p) {
  const int n = static_cast<int>(p.points.size());
  TriangleMesh m;
  if (n < 3) return m;
  const Vec3 half = p.normal() * (p.thickness / 2);
  m.vertices.reserve(2 * n);
  for (const Vec2& q : p.points) m.vertices.push_back(p.to_world(q) - half);
  for (const Vec2& q : p.points) m.vertices.push_back(p.to_world(q) + half);

  const auto caps = triangulate_polygon(p.points);  // counter-clockwise in (u, v), i.e. seen from +normal
  m.triangles.reserve(2 * caps.size() + 2 * n);
  for (const auto& t : caps) {
    m.triangles.push_back({n + t[0], n + t[1], n + t[2]});  // top, facing +normal
    m.triangles.push_back({t[2], t[1], t[0]});              // bottom, facing -normal
  }
  // Side quads along each edge a -> b of the counter-clockwise boundary: (a, b, top b, top a) faces out.
  // The winding is decided as in triangulate_polygon: by the sign of the fan sum of signed areas.
  double polygon_twice_area = 0;
  for (int i = 1; i + 1 < n; ++i) {
    const Vec2 a = p.points[i] - p.points[0], b = p.points[i + 1] - p.points[0];
    polygon_twice_area += a.x() * b.y() - a.y() * b.x();
  }
  const bool ccw = polygon_twice_area >= 0;
  for (int i = 0; i < n; ++i) {
    const int a = ccw ? i : (i + 1) % n;
    const int b = ccw ? (i + 1) % n : i;
    m.triangles.push_back({a, b, n + b});
    m.triangles.push_back({a, n + b, n + a});
  }
  return m;
}

}  // namespace

const char* shape_kind(const Shape& shape) {
  return std::visit(Overloaded{
                        [](const Sphere&) { return "sphere"; },
                        [](const Wire&) { return "wire"; },
                        [](const Box&) { return "box"; },
                        [](const Plate&) { return "plate"; },
                        [](const Mesh&) { return "mesh"; },
                    },
                    shape);
}

TriangleMesh shape_mesh(const Shape& shape, int segments) {
  return std::visit(Overloaded{
                        [&](const Sphere& s) { return sphere_mesh(s, segments); },
                        [&](const Wire& w) { return wire_mesh(w, segments); },
                        [](const Box& b) { return box_mesh(b); },
                        [](const Plate& p) { return plate_mesh(p); },
                        [](const Mesh& m) { return m.mesh; },
                    },
                    shape);
}

}  // namespace aloft
