// distance_to_shape() at known points for every shape, and shape_bounds().

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "aloft/geometry.hpp"

namespace aloft {
namespace {

// Distances below are exact formulas on coordinates of a few metres: rounding is ~1e-15 m, so 1e-12 m
// leaves a wide margin while still catching any wrong case (the errors it would cause are >= 1e-2 m).
constexpr double kTol = 1e-12;

const Mat3 kTilt = Eigen::AngleAxisd(0.8, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
const Vec3 kShift(1.5, -0.5, 2.0);

// Applies the rigid motion x -> kTilt x + kShift.
Vec3 moved(const Vec3& x) { return kTilt * x + kShift; }

TEST(Distance, Sphere) {
  Sphere s;
  s.center = Vec3(1, 2, 3);
  s.radius = 0.5;
  EXPECT_EQ(distance_to_shape(s, s.center), 0);
  EXPECT_EQ(distance_to_shape(s, Vec3(1, 2.2, 3.1)), 0);
  EXPECT_NEAR(distance_to_shape(s, Vec3(1, 2, 3.5)), 0, kTol);
  EXPECT_NEAR(distance_to_shape(s, Vec3(1, 2, 4)), 0.5, kTol);
  EXPECT_NEAR(distance_to_shape(s, Vec3(4, 6, 3)), 4.5, kTol);
}

TEST(Distance, WireIsAFiniteSolidCylinder) {
  // Along y from 0 to 2 with radius 0.5, then the same wire tilted and moved: distances are unchanged.
  for (bool tilted : {false, true}) {
    SCOPED_TRACE(tilted ? "tilted" : "along y");
    auto place = [&](const Vec3& x) { return tilted ? moved(x) : x; };
    Wire w;
    w.from = place(Vec3(0, 0, 0));
    w.to = place(Vec3(0, 2, 0));
    w.radius = 0.5;
    EXPECT_EQ(distance_to_shape(w, place(Vec3(0.1, 1, 0.1))), 0);  // inside
    EXPECT_EQ(distance_to_shape(w, place(Vec3(0.3, 1.99, -0.3))), 0);
    EXPECT_NEAR(distance_to_shape(w, place(Vec3(2, 1, 0))), 1.5, kTol);    // radially out
    EXPECT_NEAR(distance_to_shape(w, place(Vec3(0, 3, 0))), 1.0, kTol);    // beyond the top cap
    EXPECT_NEAR(distance_to_shape(w, place(Vec3(0.2, -1, 0.1))), 1.0, kTol);  // beyond the bottom cap
    EXPECT_NEAR(distance_to_shape(w, place(Vec3(0, 2.5, 1.5))), std::hypot(0.5, 1.0), kTol);  // off the rim
  }
}

TEST(Distance, RotatedBox) {
  Box b;
  b.center = Vec3(1, 1, 1);
  b.size = Vec3(2, 4, 6);
  b.rotation = kTilt;
  auto local = [&](const Vec3& x) { return Vec3(b.center + b.rotation * x); };
  EXPECT_EQ(distance_to_shape(b, local(Vec3(0.5, 1, -2))), 0);
  EXPECT_NEAR(distance_to_shape(b, local(Vec3(1, 2, 3))), 0, kTol);      // a corner
  EXPECT_NEAR(distance_to_shape(b, local(Vec3(3, 0, 0))), 2, kTol);      // along the box's x axis
  EXPECT_NEAR(distance_to_shape(b, local(Vec3(0, 0, -5))), 2, kTol);     // along -z
  EXPECT_NEAR(distance_to_shape(b, local(Vec3(2, 3, 4))), std::sqrt(3.0), kTol);  // off a corner
  EXPECT_NEAR(distance_to_shape(b, local(Vec3(0, 3, 4))), std::sqrt(2.0), kTol);  // off an edge
}

// The L [0,3]x[0,1] u [0,1]x[1,2], 0.2 thick, in a tilted plane.
Plate ell_plate() {
  Plate p;
  p.points = {{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 2}, {0, 2}};
  p.origin = kShift;
  p.u_axis = kTilt.col(0);
  p.v_axis = kTilt.col(1);
  p.thickness = 0.2;
  return p;
}

TEST(Distance, ConcavePlate) {
  const Plate p = ell_plate();
  auto at = [&](double u, double v, double h) { return Vec3(p.to_world(Vec2(u, v)) + h * p.normal()); };
  EXPECT_EQ(distance_to_shape(p, at(0.5, 1.5, 0)), 0);
  EXPECT_EQ(distance_to_shape(p, at(2.5, 0.5, -0.09)), 0);
  EXPECT_NEAR(distance_to_shape(p, at(0.5, 1.5, 0.6)), 0.5, kTol);    // above the face
  EXPECT_NEAR(distance_to_shape(p, at(2, 1.5, 0)), 0.5, kTol);        // in the notch: nearest is y = 1
  EXPECT_NEAR(distance_to_shape(p, at(2, 1.5, -0.35)), std::hypot(0.5, 0.25), kTol);
  EXPECT_NEAR(distance_to_shape(p, at(-1, -1, 0)), std::sqrt(2.0), kTol);  // off a corner
  EXPECT_NEAR(distance_to_shape(p, at(1.5, 1.2, 0.1)), 0.2, kTol);   // on the top face's level, outside
  // The reversed winding is the same solid.
  Plate r = p;
  std::reverse(r.points.begin(), r.points.end());
  EXPECT_NEAR(distance_to_shape(r, at(2, 1.5, -0.35)), std::hypot(0.5, 0.25), kTol);
  EXPECT_EQ(distance_to_shape(r, at(0.5, 1.5, 0)), 0);
}

TEST(Distance, MeshAgreesWithTheSolidItTessellates) {
  // A box mesh and an L plate mesh (concave) as Mesh shapes must give the exact distances of the box and
  // the plate, inside (0) and outside, at random points around them.
  Box b;
  b.center = Vec3(0.5, -1, 2);
  b.size = Vec3(1, 0.5, 2);
  b.rotation = kTilt;
  const Plate p = ell_plate();
  std::mt19937 rng(99);
  for (const Shape& solid : {Shape(b), Shape(p)}) {
    SCOPED_TRACE(shape_kind(solid));
    Mesh m;
    m.mesh = shape_mesh(solid);
    const Bounds bounds = shape_bounds(solid);
    const Vec3 centre = (bounds.min + bounds.max) / 2, half = (bounds.max - bounds.min) / 2 * 1.2;
    std::uniform_real_distribution<double> unit(-1, 1);
    int inside = 0;
    for (int i = 0; i < 2000; ++i) {
      const Vec3 q = centre + half.cwiseProduct(Vec3(unit(rng), unit(rng), unit(rng)));
      const double want = distance_to_shape(solid, q);
      if (want == 0) ++inside;
      EXPECT_NEAR(distance_to_shape(m, q), want, kTol) << q.transpose();
    }
    EXPECT_GT(inside, 20);  // the sample reached inside the solid
  }
}

TEST(Distance, MeshInsideIsZero) {
  Sphere s;
  s.radius = 1;
  Mesh m;
  m.mesh = shape_mesh(s, 16);
  EXPECT_EQ(distance_to_shape(m, Vec3(0.1, 0.2, -0.3)), 0);
  EXPECT_EQ(distance_to_shape(m, Vec3(0, 0, 0)), 0);
  // Straight above the north pole vertex (0, 1, 0).
  EXPECT_NEAR(distance_to_shape(m, Vec3(0, 3, 0)), 2, kTol);
}

TEST(Bounds, EveryShape) {
  Sphere s;
  s.center = Vec3(1, 2, 3);
  s.radius = 0.5;
  Bounds sb = shape_bounds(s);
  EXPECT_EQ(sb.min, Vec3(0.5, 1.5, 2.5));
  EXPECT_EQ(sb.max, Vec3(1.5, 2.5, 3.5));

  Wire straight;
  straight.to = Vec3(0, 2, 0);
  straight.radius = 0.5;
  Bounds wb = shape_bounds(straight);
  EXPECT_NEAR((wb.min - Vec3(-0.5, 0, -0.5)).norm(), 0, kTol);
  EXPECT_NEAR((wb.max - Vec3(0.5, 2, 0.5)).norm(), 0, kTol);

  // A tilted wire: its fine inscribed prism reaches the bounds to within r (1 - cos(pi / N)) ~ 3e-8 m for
  // N = 4096, r = 0.1, and never exceeds them beyond rounding (1e-12).
  Wire tilted;
  tilted.from = Vec3(0.1, 0.2, 0.3);
  tilted.to = Vec3(1.2, -0.4, 0.9);
  tilted.radius = 0.1;
  const Bounds tb = shape_bounds(tilted);
  Bounds mesh_bounds;
  for (const Vec3& v : shape_mesh(tilted, 4096).vertices) mesh_bounds.add(v);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(tb.min[i], mesh_bounds.min[i] + 1e-12);
    EXPECT_GE(tb.max[i], mesh_bounds.max[i] - 1e-12);
    EXPECT_NEAR(tb.min[i], mesh_bounds.min[i], 1e-7);
    EXPECT_NEAR(tb.max[i], mesh_bounds.max[i], 1e-7);
  }

  // Boxes and plates: the bounds are those of their exact meshes' vertices.
  Box b;
  b.center = Vec3(-1, 0, 1);
  b.size = Vec3(0.2, 0.4, 1.0);
  b.rotation = kTilt;
  for (const Shape& shape : {Shape(b), Shape(ell_plate())}) {
    SCOPED_TRACE(shape_kind(shape));
    Bounds want;
    for (const Vec3& v : shape_mesh(shape).vertices) want.add(v);
    const Bounds got = shape_bounds(shape);
    EXPECT_NEAR((got.min - want.min).norm(), 0, kTol);
    EXPECT_NEAR((got.max - want.max).norm(), 0, kTol);
    Mesh m;
    m.mesh = shape_mesh(shape);
    const Bounds mb = shape_bounds(m);
    EXPECT_EQ(mb.min, want.min);
    EXPECT_EQ(mb.max, want.max);
  }
}

}  // namespace
}  // namespace aloft
