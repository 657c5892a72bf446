// closed_mesh_problem() on good meshes (every shape's mesh) and on each kind of broken mesh.

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "aloft/error.hpp"
#include "aloft/geometry.hpp"
#include "geometry/obj_reader.hpp"

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

// A unit cube as an OBJ file: vertices on lines 1-8 (vertex k+1 has bits 0, 1, 2 of k choosing +0.5 along
// x, y, z), quads on lines 9-14 (x-, x+, y-, y+, z-, z+), counter-clockwise seen from outside.
const std::string kCubeVertices =
    "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv -0.5 0.5 -0.5\nv 0.5 0.5 -0.5\n"
    "v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv -0.5 0.5 0.5\nv 0.5 0.5 0.5\n";
const std::string kCubeFacesButTop = "f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\n";
const std::string kCubeTop = "f 5 6 8 7\n";

// check_closed_obj_mesh on `text`: the InputError it throws (ADD_FAILURE if none).
InputError obj_error(const std::string& text, const std::string& file) {
  const ObjMesh obj = parse_obj_text(text, file);
  try {
    check_closed_obj_mesh(obj, file);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return InputError(file, {}, "");
}

TEST(ObjMeshCheck, GoodCubePasses) {
  EXPECT_NO_THROW(check_closed_obj_mesh(parse_obj_text(kCubeVertices + kCubeFacesButTop + kCubeTop, "c.obj"), "c.obj"));
}

// The open edge is named by OBJ's vertex numbers (from 1) and the line of the one face using it. Before,
// this read "edge between vertices 4 and 6 belongs to 1 triangle: the mesh is open", 0-based, no line.
TEST(ObjMeshCheck, OpenMeshNamesTheFaceAndOneBasedVertices) {
  const InputError e = obj_error(kCubeVertices + kCubeFacesButTop, "open.obj");
  // Triangle (1, 5, 7) of the x- face on line 9 is the first to use an edge of the missing top, 5-7.
  EXPECT_STREQ(e.what(), "open.obj: the edge between vertices 5 and 7 belongs to only one face (line 9): the mesh is "
                         "not closed");
  EXPECT_EQ(e.place().line, 0);  // a problem of the whole mesh: the face's line is in the words
}

// A degenerate face is reported at its own line and column, with the vertices as the file numbers them
// (before: "triangle 12 is degenerate (zero area)", an index after fanning).
TEST(ObjMeshCheck, DegenerateFaceIsReportedAtItsLine) {
  const std::string cube = kCubeVertices + kCubeFacesButTop + kCubeTop;  // 14 lines
  InputError e = obj_error(cube + "f 1 1 2\n", "deg.obj");
  EXPECT_STREQ(e.what(), "deg.obj:15:1: face is degenerate (zero area): vertex 1 appears twice");
  EXPECT_EQ(e.place().line, 15);
  EXPECT_EQ(e.place().column, 1);
  // Negative indices name the same vertices; the column is the 'f''s.
  e = obj_error(cube + "# c\n   f 2 -8 -8\n", "deg.obj");
  EXPECT_STREQ(e.what(), "deg.obj:16:4: face is degenerate (zero area): vertex 1 appears twice");
  // Three distinct vertices on a line: vertex 9 is the midpoint of vertices 1 and 2.
  const std::string mid = cube + "v 0 -0.5 -0.5\n";  // line 15
  e = obj_error(mid + "f 1 9 2\n", "line.obj");
  EXPECT_STREQ(e.what(), "line.obj:16:1: face is degenerate (zero area): vertices 1, 9 and 2 lie on a line");
  // Two vertices at one point (as in a mesh whose copies of a corner were not merged): vertex 10 is vertex 2's.
  e = obj_error(mid + "v 0.5 -0.5 -0.5\nf 1 2 10\n", "same.obj");
  EXPECT_STREQ(e.what(), "same.obj:17:1: face is degenerate (zero area): vertices 2 and 10 are at the same point");
  // In a quad, only the fan's triangle (1, 9, 2) is flat: the face itself has area, and the message says so.
  e = obj_error(mid + "f 1 9 2 4\n", "fan.obj");
  EXPECT_STREQ(e.what(),
               "fan.obj:16:1: face has a zero-area triangle where it is fanned from its first corner: vertices 1, 9 "
               "and 2 lie on a line");
}

TEST(ObjMeshCheck, NonManifoldEdgeNamesEveryFaceUsingIt) {
  // A fin on the cube's edge 1-5, which the faces on lines 9 (x-) and 11 (y-) share.
  const InputError e = obj_error(kCubeVertices + kCubeFacesButTop + kCubeTop + "v -2 -2 0\nf 1 5 9\n", "fin.obj");
  EXPECT_STREQ(e.what(), "fin.obj: the edge between vertices 1 and 5 is used by 3 triangles (of the faces on lines 9, "
                         "11 and 16): not a manifold surface");
}

TEST(ObjMeshCheck, InconsistentOrientationNamesBothFaces) {
  // The y+ face (line 12) turned over: "f 3 4 8 7" instead of "f 3 7 8 4". Its triangle (3, 8, 7) runs
  // from 7 to 3 like the x- face's (1, 7, 3).
  const std::string faces = "f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 4 8 7\nf 1 3 4 2\n" + kCubeTop;
  const InputError e = obj_error(kCubeVertices + faces, "flip.obj");
  EXPECT_STREQ(e.what(),
               "flip.obj: the faces on lines 9 and 12 both run from vertex 7 to vertex 3: they are oriented "
               "inconsistently (faces sharing an edge must run along it in opposite directions)");
}

TEST(ObjMeshCheck, WholeMeshProblemsAreWordedAsForAnyMesh) {
  // Every face turned over.
  const std::string inverted = "f 3 7 5 1\nf 6 8 4 2\nf 5 6 2 1\nf 4 8 7 3\nf 2 4 3 1\nf 7 8 6 5\n";
  EXPECT_STREQ(obj_error(kCubeVertices + inverted, "inv.obj").what(),
               "inv.obj: the mesh is inside out: its volume is negative, its triangles run clockwise seen from outside");
  EXPECT_STREQ(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 2\n", "flat.obj").what(),
               "flat.obj: the mesh encloses no volume");
}

}  // namespace
}  // namespace aloft
