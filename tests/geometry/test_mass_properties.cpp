// Mass properties: Mirtich's polyhedral integrals against closed forms and against independent
// decompositions, convergence of tessellations, invariance under rigid motions, parallel axis sums.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "aloft/geometry.hpp"

namespace aloft {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Compares mass properties entry by entry with a relative tolerance `rel`: the volume relative to itself,
// the centre relative to the larger of its distance from the origin and the solid's size (cbrt V), every
// inertia entry relative to the largest entry (off-diagonal entries may be exactly 0).
void expect_same(const MassProperties& got, const MassProperties& want, double rel, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_NEAR(got.volume, want.volume, rel * std::abs(want.volume));
  const double length = std::max(want.center.norm(), std::cbrt(std::abs(want.volume)));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(got.center[i], want.center[i], rel * length) << "centre " << i;
  const double scale = want.inertia.cwiseAbs().maxCoeff();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(got.inertia(i, j), want.inertia(i, j), rel * scale) << "I" << i << j;
}

Mat3 rotation(double angle, const Vec3& axis) { return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix(); }

// Independent exact mass properties of a closed triangle mesh: signed tetrahedra (origin, a, b, c), each
// with the closed-form second moment integral over the tetrahedron of x x^T = V/20 (sum_k v_k v_k^T + s s^T),
// s = sum of its 4 vertices (the canonical covariance of Tonon 2004 / Blow & Binstock 2004).
MassProperties tetrahedra_mass_properties(const TriangleMesh& m) {
  double volume = 0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  for (const auto& t : m.triangles) {
    const Vec3 &a = m.vertices[t[0]], &b = m.vertices[t[1]], &c = m.vertices[t[2]];
    const double v = a.dot(b.cross(c)) / 6;
    const Vec3 s = a + b + c;
    volume += v;
    first += v * s / 4;
    second += v / 20 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  MassProperties mp;
  mp.volume = volume;
  mp.center = first / volume;
  const Mat3 centered = second - volume * mp.center * mp.center.transpose();
  mp.inertia = centered.trace() * Mat3::Identity() - centered;
  return mp;
}

// Independent exact mass properties of a plate: the polygon's area moments from signed triangles
// (0, p_i, p_i+1), integral over a triangle of x x^T = A/12 (sum_k v_k v_k^T + s s^T), extruded over
// h in [-t/2, t/2] (which adds integral h^2 = A t^3 / 12 along the normal and no cross terms).
MassProperties plate_by_triangles(const Plate& p) {
  double area = 0;
  Vec2 first = Vec2::Zero();
  Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
  const size_t n = p.points.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec2 &a = p.points[i], &b = p.points[(i + 1) % n];
    const double tri = (a.x() * b.y() - a.y() * b.x()) / 2;
    area += tri;
    first += tri * (a + b) / 3;
    second += tri / 12 * (a * a.transpose() + b * b.transpose() + (a + b) * (a + b).transpose());
  }
  if (area < 0) {  // clockwise polygon: every signed term flips
    area = -area;
    first = -first;
    second = -second;
  }
  const double t = p.thickness;
  const Vec2 c2 = first / area;
  Mat3 local = Mat3::Zero();  // second moments about the centre in (u, v, n)
  local.topLeftCorner<2, 2>() = t * (second - area * c2 * c2.transpose());
  local(2, 2) = area * t * t * t / 12;
  Mat3 R;
  R << p.u_axis, p.v_axis, p.normal();
  const Mat3 world = R * local * R.transpose();
  MassProperties mp;
  mp.volume = area * t;
  mp.center = p.to_world(c2);
  mp.inertia = world.trace() * Mat3::Identity() - world;
  return mp;
}

// A concave fish-like outline (counter-clockwise), with a notched tail.
std::vector<Vec2> fish_outline() {
  return {{0, 0},      {0.8, -0.45}, {2, -0.55},  {3, -0.3},   {3.5, -0.05}, {4.3, -0.6},
          {4.1, 0.02}, {4.3, 0.6},   {3.5, 0.05}, {3, 0.3},    {2, 0.55},    {0.8, 0.45}};
}

Plate tilted_plate(std::vector<Vec2> points, double thickness) {
  Plate p;
  p.points = std::move(points);
  const Mat3 R = rotation(0.9, Vec3(0.3, -1, 0.4));
  p.origin = Vec3(1.5, 2.0, -0.7);
  p.u_axis = R.col(0);
  p.v_axis = R.col(1);
  p.thickness = thickness;
  return p;
}

// Exact mass properties of a right prism over a regular N-gon of circumradius r and length L along unit d,
// centred at c. The polygon: N triangles from the centre with apex angle 2 pi / N, so
//   A = N/2 r^2 sin(2 pi / N),
//   polar moment J = integral |x|^2 dA = A r^2 (2 + cos(2 pi / N)) / 6
// (for a triangle (0, a, b): integral |x|^2 = A/6 (|a|^2 + |b|^2 + a.b), here |a| = |b| = r, a.b = r^2 cos).
// A regular N-gon (N >= 3) has an isotropic second moment, so integral x^2 = integral y^2 = J/2. Then
//   I_axial = L J,  I_transverse = L J/2 + A L^3/12.
MassProperties regular_prism(int n, double r, const Vec3& from, const Vec3& to) {
  const double L = (to - from).norm();
  const Vec3 d = (to - from) / L;
  const double theta = 2 * kPi / n;
  const double area = n / 2.0 * r * r * std::sin(theta);
  const double polar = area * r * r * (2 + std::cos(theta)) / 6;
  MassProperties mp;
  mp.volume = area * L;
  mp.center = (from + to) / 2;
  const double axial = L * polar, transverse = L * polar / 2 + area * L * L * L / 12;
  mp.inertia = transverse * (Mat3::Identity() - d * d.transpose()) + axial * d * d.transpose();
  return mp;
}

// Largest relative error of volume and inertia entries between a and the reference b.
double relative_error(const MassProperties& a, const MassProperties& b) {
  const double scale = b.inertia.cwiseAbs().maxCoeff();
  return std::max(std::abs(a.volume - b.volume) / b.volume, (a.inertia - b.inertia).cwiseAbs().maxCoeff() / scale);
}

TEST(MassProperties, BoxMeshMatchesClosedForm) {
  // 1e-9: both sides are exact formulas for the same solid, evaluated in double precision over 12
  // triangles (a few hundred operations each); rounding errors are ~1e-15 relative.
  Box axis_aligned;
  axis_aligned.size = Vec3(1, 2, 3);
  expect_same(polyhedron_mass_properties(shape_mesh(axis_aligned)), box_mass_properties(axis_aligned), 1e-9,
              "axis-aligned box");

  Box moved;
  moved.size = Vec3(0.3, 1.7, 0.05);
  moved.center = Vec3(3, -2, 5);
  moved.rotation = rotation(0.7, Vec3(1, 2, 3));
  const MassProperties closed = box_mass_properties(moved);
  // The rotated box has a full inertia tensor: the comparison covers the off-diagonal terms.
  EXPECT_GT(std::abs(closed.inertia(0, 1)), 0.01 * closed.inertia.cwiseAbs().maxCoeff());
  expect_same(polyhedron_mass_properties(shape_mesh(moved)), closed, 1e-9, "rotated, translated box");
}

TEST(MassProperties, RegularPrismMatchesExactPolygonPrism) {
  // 1e-9: Mirtich's sums and the prism's closed form are both exact for this polyhedron; the only
  // differences are rounding (~1e-15 per operation, over at most a few thousand operations for N = 100).
  const Vec3 from(0.1, 0.2, -0.3), to(0.5, 1.1, 0.2);
  for (int n : {3, 4, 5, 7, 12, 24, 100}) {
    Wire w;
    w.from = from;
    w.to = to;
    w.radius = 0.07;
    expect_same(polyhedron_mass_properties(shape_mesh(w, n)), regular_prism(n, w.radius, from, to), 1e-9,
                "N = " + std::to_string(n));
  }
}

TEST(MassProperties, RegularPrismConvergesToCylinderAtSecondOrder) {
  // The prism's area is A_N = pi r^2 (1 - x^2/6 + O(x^4)), x = 2 pi / N, and likewise its moments: the
  // error falls as N^-2, so doubling N divides it by 4 (1 + O(N^-2)). From N = 16 the O(N^-2) correction
  // is below 1%, so each ratio must lie within 4 +- 0.1.
  Wire w;
  w.from = Vec3(-0.2, 0.3, 0.1);
  w.to = Vec3(0.4, -0.5, 0.9);
  w.radius = 0.05;
  const MassProperties cylinder = wire_mass_properties(w);
  double previous = relative_error(polyhedron_mass_properties(shape_mesh(w, 16)), cylinder);
  for (int n : {32, 64, 128, 256}) {
    const double error = relative_error(polyhedron_mass_properties(shape_mesh(w, n)), cylinder);
    EXPECT_NEAR(previous / error, 4.0, 0.1) << "N = " << n;
    previous = error;
  }
  EXPECT_LT(previous, 1e-3);
}

TEST(MassProperties, TessellatedSphereMatchesTetrahedronDecomposition) {
  // 1e-9: Mirtich and the signed-tetrahedron sum are two exact methods for the same polyhedron; over a
  // few thousand triangles the rounding error stays ~1e-13 relative.
  for (int segments : {5, 12, 24, 64}) {
    Sphere s;
    s.center = Vec3(0.3, -1.2, 2.5);
    s.radius = 0.4;
    const TriangleMesh mesh = shape_mesh(s, segments);
    expect_same(polyhedron_mass_properties(mesh), tetrahedra_mass_properties(mesh), 1e-9,
                "segments = " + std::to_string(segments));
  }
}

TEST(MassProperties, TessellatedSphereConvergesAtSecondOrder) {
  // The closed form cannot be matched to 1e-9 by any mesh: the inscribed polyhedron misses a shell whose
  // thickness is ~ h^2 / (8 r) for edge length h, so its volume is short by O((h/r)^2); 1e-9 would need
  // h ~ 1e-4 r, some 10^9 triangles. What must hold is the rate: halving h (doubling `segments`, which
  // doubles both meridians and rings) divides the error by ~4. The O(h^4) correction makes the ratio
  // 4 (1 + O(h^2)): from 32 segments on it is within 4 +- 0.1 (measured: 3.96, 3.99, 4.00).
  Sphere s;
  s.center = Vec3(1, 2, 3);
  s.radius = 0.25;
  const MassProperties exact = sphere_mass_properties(s);
  double previous = relative_error(polyhedron_mass_properties(shape_mesh(s, 32)), exact);
  for (int segments : {64, 128, 256}) {
    const double error = relative_error(polyhedron_mass_properties(shape_mesh(s, segments)), exact);
    EXPECT_NEAR(previous / error, 4.0, 0.1) << "segments = " << segments;
    previous = error;
  }
  EXPECT_LT(previous, 1e-3);
}

TEST(MassProperties, InvariantUnderRigidMotions) {
  // 1e-9 relative: the moved mesh is the same solid; only the rounding of the moved coordinates
  // (|translation| <= 17 m, size ~4 m: ~1e-15 relative each) and of the sums differ.
  const TriangleMesh base = shape_mesh(tilted_plate(fish_outline(), 0.3));
  const MassProperties original = polyhedron_mass_properties(base);
  std::mt19937 rng(12345);
  std::normal_distribution<double> normal(0, 1);
  std::uniform_real_distribution<double> uniform(-10, 10);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 R = Quat(normal(rng), normal(rng), normal(rng), normal(rng)).normalized().toRotationMatrix();
    const Vec3 t(uniform(rng), uniform(rng), uniform(rng));
    TriangleMesh moved = base;
    for (Vec3& v : moved.vertices) v = R * v + t;
    MassProperties want;
    want.volume = original.volume;
    want.center = R * original.center + t;
    want.inertia = R * original.inertia * R.transpose();
    expect_same(polyhedron_mass_properties(moved), want, 1e-9, "trial " + std::to_string(trial));
  }
}

TEST(MassProperties, ConcavePlatesMatchIndependentDecomposition) {
  // An L: two rectangles [0,3]x[0,1] and [0,1]x[1,2], area 4, centroid (1.25, 0.75).
  const std::vector<Vec2> ell = {{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 2}, {0, 2}};
  for (bool reversed : {false, true}) {
    std::vector<Vec2> pts = ell;
    if (reversed) std::reverse(pts.begin(), pts.end());
    const Plate plate = tilted_plate(pts, 0.1);
    const MassProperties mp = shape_mass_properties(plate);
    SCOPED_TRACE(reversed ? "clockwise" : "counter-clockwise");
    // 1e-12: area x thickness is 0.4 exactly up to a few roundings.
    EXPECT_NEAR(mp.volume, 4 * 0.1, 1e-12);
    // 1e-12 m: the centroid in the mid-plane, rounding only (coordinates ~3 m).
    EXPECT_LT((mp.center - plate.to_world(Vec2(1.25, 0.75))).norm(), 1e-12);

    // The L as two boxes in the plate's frame, summed with the parallel axis theorem.
    Mat3 R;
    R << plate.u_axis, plate.v_axis, plate.normal();
    MassAccumulator acc;
    for (const auto& [centre, size] : {std::pair{Vec2(1.5, 0.5), Vec2(3, 1)}, std::pair{Vec2(0.5, 1.5), Vec2(1, 1)}}) {
      Box b;
      b.center = plate.to_world(centre);
      b.size = Vec3(size.x(), size.y(), 0.1);
      b.rotation = R;
      const MassProperties part = box_mass_properties(b);
      acc.add(part.volume, part.center, part.inertia);
    }
    MassProperties boxes;
    boxes.volume = acc.mass;
    boxes.center = acc.center();
    boxes.inertia = acc.inertia_about_center();
    // 1e-9: exact formulas on both sides (Mirtich over 4 + 2 + 6 faces, box closed forms plus parallel axis
    // sums), rounding ~1e-15 relative.
    expect_same(mp, boxes, 1e-9, "L plate vs two boxes");
    expect_same(mp, plate_by_triangles(plate), 1e-9, "L plate vs triangle fan");
  }

  const std::vector<Vec2> fish = fish_outline();
  ASSERT_FALSE(polygon_problem(fish).has_value());
  for (bool reversed : {false, true}) {
    std::vector<Vec2> pts = fish;
    if (reversed) std::reverse(pts.begin(), pts.end());
    const Plate plate = tilted_plate(pts, 0.02);
    const MassProperties mp = shape_mass_properties(plate);
    const MassProperties want = plate_by_triangles(plate);
    // 1e-9: as above, exact on both sides.
    expect_same(mp, want, 1e-9, reversed ? "fish, clockwise" : "fish, counter-clockwise");
    // The centre lies in the mid-plane (1e-12 m: rounding of coordinates ~4 m).
    EXPECT_NEAR((mp.center - plate.origin).dot(plate.normal()), 0, 1e-12);
  }
}

TEST(MassProperties, ShapeMeshMirtichEqualsShapeMassProperties) {
  // For shapes whose mesh is exact (box, plate, mesh) the mesh's integrals are the shape's; 1e-9 as for
  // any two exact evaluations of the same solid. For the plate this checks the ear-clipped caps against
  // the untriangulated polygon faces used by shape_mass_properties.
  Box box;
  box.center = Vec3(0.5, 1, -2);
  box.size = Vec3(0.2, 0.3, 0.4);
  box.rotation = rotation(2.1, Vec3(-1, 0.5, 0.2));
  const Plate plate = tilted_plate(fish_outline(), 0.05);
  Mesh mesh;
  mesh.mesh = shape_mesh(tilted_plate({{0, 0}, {2, 0}, {2, 2}, {1, 0.5}, {0, 2}}, 0.4));
  for (const Shape& shape : {Shape(box), Shape(plate), Shape(mesh)})
    expect_same(polyhedron_mass_properties(shape_mesh(shape)), shape_mass_properties(shape), 1e-9, shape_kind(shape));
}

TEST(MassProperties, ClosedFormsForSimpleShapes) {
  // Direct values of the textbook formulas; 1e-12 relative: a handful of roundings.
  Sphere s;
  s.center = Vec3(1, 2, 3);
  s.radius = 0.5;
  const MassProperties sp = shape_mass_properties(s);
  EXPECT_NEAR(sp.volume, 4.0 / 3.0 * kPi * 0.125, 1e-12);
  EXPECT_EQ(sp.center, s.center);
  EXPECT_NEAR(sp.inertia(1, 1), 0.4 * sp.volume * 0.25, 1e-12);
  EXPECT_EQ(sp.inertia(0, 1), 0);

  // A wire along x: axial inertia m r^2 / 2 about x, m (3 r^2 + L^2) / 12 about y and z.
  Wire w;
  w.from = Vec3(-1, 0, 0);
  w.to = Vec3(1, 0, 0);
  w.radius = 0.1;
  const MassProperties wp = shape_mass_properties(w);
  const double m = kPi * 0.01 * 2;
  EXPECT_NEAR(wp.volume, m, 1e-12 * m);
  EXPECT_NEAR(wp.inertia(0, 0), m * 0.01 / 2, 1e-12 * m);
  EXPECT_NEAR(wp.inertia(1, 1), m * (0.03 + 4) / 12, 1e-12 * m);
  EXPECT_NEAR(wp.inertia(2, 2), m * (0.03 + 4) / 12, 1e-12 * m);
  EXPECT_NEAR(wp.inertia(0, 1), 0, 1e-12 * m);
}

TEST(MassProperties, AccumulatorAppliesParallelAxisTheorem) {
  // Two halves of a box, at density 2.5, summed: the whole box at density 2.5. 1e-9: exact formulas.
  Box whole;
  whole.center = Vec3(1, -1, 2);
  whole.size = Vec3(2, 0.5, 0.8);
  whole.rotation = rotation(0.4, Vec3(0, 1, 1));
  const double density = 2.5;
  MassAccumulator acc;
  for (double side : {-1.0, 1.0}) {
    Box half = whole;
    half.size.x() = 1;
    half.center = whole.center + whole.rotation * Vec3(side * 0.5, 0, 0);
    const MassProperties part = box_mass_properties(half).scaled_inertia(density);
    acc.add(density * part.volume, part.center, part.inertia);
  }
  const MassProperties box = box_mass_properties(whole);
  MassProperties want = box.scaled_inertia(density);
  EXPECT_EQ(want.volume, box.volume);  // scaled_inertia keeps the volume
  want.volume = density * box.volume;
  MassProperties got;
  got.volume = acc.mass;
  got.center = acc.center();
  got.inertia = acc.inertia_about_center();
  expect_same(got, want, 1e-9, "two halves");
}

// A small part far from the world origin keeps its own inertia: the accumulator sums moments about its
// first part's centre. Summed about the origin, a 0.1 mm ball 1.8 m up lost its 2/5 m r^2 to round-off
// (m |c|^2 ~ 1e8 times larger), and a 1e-10 m ball got negative moments and a NaN at the first step.
TEST(MassProperties, AccumulatorKeepsTheInertiaOfSmallPartsFarFromTheOrigin) {
  for (const double radius : {1e-4, 1e-7, 1e-10}) {
    Sphere ball;
    ball.radius = radius;
    ball.center = Vec3(-0.5, 1.8, 700);
    const MassProperties mp = sphere_mass_properties(ball);
    MassAccumulator one;
    one.add(mp.volume, mp.center, mp.inertia);
    // One part: its offset from the reference is exactly 0, so its inertia comes back bit for bit.
    EXPECT_EQ(one.inertia_about_center(), mp.inertia) << radius;
    // Two balls a diameter apart: about their midpoint each adds m r^2, so 2 (2/5 + 1) m r^2 across the
    // line joining them and 2 (2/5) m r^2 along it. The offset 2r is known to |x| eps = 0.5 eps m, so to
    // 0.5 eps / (2r) relative, and its square twice that: 10 times that bound (about origin, the error was
    // m |c|^2 eps / (m r^2), 5e-3 at r = 1e-4 m).
    const double tolerance = 10 * 0.5 * std::numeric_limits<double>::epsilon() / radius;
    Sphere other = ball;
    other.center.x() += 2 * radius;
    MassAccumulator two;
    two.add(mp.volume, ball.center, mp.inertia);
    two.add(mp.volume, other.center, mp.inertia);
    const double m = mp.volume, r2 = radius * radius;
    const Vec3 want(2 * 0.4 * m * r2, 2 * 1.4 * m * r2, 2 * 1.4 * m * r2);
    const Mat3 got = two.inertia_about_center();
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got(k, k) / want[k], 1, tolerance) << radius << " axis " << k;
  }
}

TEST(MassProperties, InsideOutMeshHasNegativeVolume) {
  Box b;
  b.size = Vec3(1, 2, 3);
  TriangleMesh m = shape_mesh(b);
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  // 1e-12: 6 m^3 up to rounding.
  EXPECT_NEAR(polyhedron_mass_properties(m).volume, -6, 1e-12);
}

}  // namespace
}  // namespace aloft
