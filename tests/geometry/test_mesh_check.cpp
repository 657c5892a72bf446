// closed_mesh_problem() on good meshes (every shape's mesh) and on each kind of broken mesh.

#include <gtest/gtest.h>

#include <limits>
#include <utility>
#include <vector>

#include "aloft/geometry.hpp"

namespace aloft {
namespace {

TriangleMesh unit_box_mesh() {
  Box b;
  b.size = Vec3(1, 1, 1);
  return shape_mesh(b);
}

void expect_problem(const TriangleMesh& m, const std::string& words) {
  const auto problem = closed_mesh_problem(m);
  ASSERT_TRUE(problem.has_value()) << "expected: " << words;
  EXPECT_NE(problem->find(words), std::string::npos) << *problem;
}

Plate plate(std::vector<Vec2> points) {
  Plate p;
  p.points = std::move(points);
  p.origin = Vec3(0.2, 1.0, -0.4);
  const Mat3 R = Eigen::AngleAxisd(1.1, Vec3(0.2, 0.9, -0.3).normalized()).toRotationMatrix();
  p.u_axis = R.col(0);
  p.v_axis = R.col(1);
  p.thickness = 0.01;
  return p;
}

TEST(MeshCheck, EveryShapeMeshIsClosedWithPositiveVolume) {
  std::vector<std::pair<Shape, int>> cases;
  Sphere s;
  s.center = Vec3(1, 2, 3);
  s.radius = 0.3;
  for (int segments : {3, 4, 7, 24, 65}) cases.emplace_back(s, segments);
  Wire w;
  w.from = Vec3(0, 0, 1);
  w.to = Vec3(0.3, -1, 0.2);
  w.radius = 0.01;
  for (int segments : {3, 8, 24}) cases.emplace_back(w, segments);
  Wire vertical;  // along an axis: the basis construction must still work
  vertical.to = Vec3(0, -2, 0);
  vertical.radius = 0.5;
  cases.emplace_back(vertical, 12);
  Box b;
  b.size = Vec3(0.1, 0.2, 0.3);
  b.rotation = Eigen::AngleAxisd(0.3, Vec3::UnitZ()).toRotationMatrix();
  cases.emplace_back(b, 24);
  Box mirrored = b;  // a reflection as "rotation" must not turn the mesh inside out
  mirrored.rotation.col(2) *= -1;
  cases.emplace_back(mirrored, 24);
  const std::vector<Vec2> ell = {{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 2}, {0, 2}};
  cases.emplace_back(plate(ell), 24);
  cases.emplace_back(plate({ell.rbegin(), ell.rend()}), 24);
  cases.emplace_back(plate({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 1}}), 24);  // collinear points
  Mesh m;
  m.mesh = shape_mesh(s, 10);
  cases.emplace_back(m, 24);

  for (const auto& [shape, segments] : cases) {
    SCOPED_TRACE(std::string(shape_kind(shape)) + " with " + std::to_string(segments) + " segments");
    const TriangleMesh mesh = shape_mesh(shape, segments);
    EXPECT_EQ(closed_mesh_problem(mesh), std::nullopt);
    const double volume = polyhedron_mass_properties(mesh).volume;
    EXPECT_GT(volume, 0);
    // Meshes of round shapes are inscribed, so never larger than the solid (1e-12: rounding only).
    EXPECT_LE(volume, shape_mass_properties(shape).volume * (1 + 1e-12));
  }
}

TEST(MeshCheck, OpenMesh) {
  TriangleMesh m = unit_box_mesh();
  m.triangles.erase(m.triangles.begin() + 5);
  expect_problem(m, "belongs to 1 triangle: the mesh is open");
}

TEST(MeshCheck, FlippedTriangle) {
  TriangleMesh m = unit_box_mesh();
  std::swap(m.triangles[7][0], m.triangles[7][1]);
  // Names the flipped triangle and the neighbour it disagrees with (triangle 2 shares the edge 3-7).
  expect_problem(m, "triangles 2 and 7 are oriented inconsistently");
}

TEST(MeshCheck, DegenerateTriangles) {
  TriangleMesh repeated = unit_box_mesh();
  repeated.triangles[3][2] = repeated.triangles[3][0];
  expect_problem(repeated, "triangle 3 is degenerate (zero area)");

  // Three distinct collinear vertices: vertex 8 is the midpoint of the edge from corner 0 to corner 1.
  TriangleMesh collinear = unit_box_mesh();
  collinear.vertices.push_back((collinear.vertices[0] + collinear.vertices[1]) / 2);
  collinear.triangles.insert(collinear.triangles.begin(), {0, 8, 1});
  expect_problem(collinear, "triangle 0 is degenerate (zero area)");
}

TEST(MeshCheck, IndexOutOfRange) {
  TriangleMesh m = unit_box_mesh();
  m.triangles[5][1] = 40;
  expect_problem(m, "triangle 5: vertex index 40 out of range (mesh has 8 vertices)");
  m.triangles[5][1] = -1;
  expect_problem(m, "vertex index -1 out of range");
}

TEST(MeshCheck, EmptyMesh) {
  expect_problem(TriangleMesh{}, "no triangles");
  TriangleMesh vertices_only;
  vertices_only.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  expect_problem(vertices_only, "no triangles");
}

TEST(MeshCheck, NonManifoldEdge) {
  // A fin: a third triangle on the box's edge between corners 0 and 4.
  TriangleMesh m = unit_box_mesh();
  m.vertices.push_back(Vec3(-2, -2, 0));
  m.triangles.push_back({0, 4, 8});
  expect_problem(m, "edge between vertices 0 and 4 belongs to 3 triangles: not a manifold surface");
}

TEST(MeshCheck, NoVolumeAndInsideOut) {
  TriangleMesh flat;
  flat.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  flat.triangles = {{0, 1, 2}, {0, 2, 1}};  // two faces of one triangle, back to back
  expect_problem(flat, "encloses no volume");

  TriangleMesh inverted = unit_box_mesh();
  for (auto& t : inverted.triangles) std::swap(t[1], t[2]);
  expect_problem(inverted, "inside out");
}

TEST(MeshCheck, NonFiniteVertex) {
  TriangleMesh m = unit_box_mesh();
  m.vertices[6].y() = std::numeric_limits<double>::infinity();
  expect_problem(m, "vertex 6 has a non-finite coordinate");
}

TEST(MeshCheck, LargeMesh) {
  // ~160k triangles: the edge map keeps this linear (a quadratic check would take minutes).
  Sphere s;
  s.radius = 1;
  const TriangleMesh m = shape_mesh(s, 400);
  ASSERT_GT(m.triangles.size(), 150000u);
  EXPECT_EQ(closed_mesh_problem(m), std::nullopt);
  TriangleMesh open = m;
  open.triangles.pop_back();
  expect_problem(open, "the mesh is open");
}

}  // namespace
}  // namespace aloft
