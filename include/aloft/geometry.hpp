#pragma once
// Geometry of shapes: mass properties (Mirtich's polyhedral integrals, closed forms as cross-checks),
// triangle meshes of every shape, point distances, and mesh validation.

#include <optional>
#include <string>

#include "aloft/shapes.hpp"

namespace aloft {

// Mass properties of a uniform solid of density 1 kg/m^3 (so mass == volume).
struct MassProperties {
  double volume = 0;                      // m^3
  Vec3 center = Vec3::Zero();             // centre of mass, world, m
  Mat3 inertia = Mat3::Zero();            // inertia tensor about `center`, world axes, kg m^2 per (kg/m^3)

  // Mass properties of this solid at `density` (kg/m^3): volume unchanged, inertia scaled.
  MassProperties scaled_inertia(double density) const;
};

// Combine solids given with *absolute* inertias (already multiplied by their densities): the result's
// `volume` holds the total mass, `center` the combined centre of mass, `inertia` the parallel-axis sum.
// Moments are summed about the first part's centre, not the world origin: a part far from the origin
// (a 0.1 mm ball 1.8 m up) would otherwise lose its own inertia to round-off when shifted back.
struct MassAccumulator {
  int parts = 0;
  double mass = 0;
  Vec3 reference = Vec3::Zero();          // the first part's centre (world, m)
  Vec3 first_moment = Vec3::Zero();       // sum m_i (c_i - reference)
  Mat3 second_moment = Mat3::Zero();      // sum of inertias about the reference
  void add(double mass, const Vec3& center, const Mat3& inertia_about_center);
  Vec3 center() const;                    // requires mass > 0
  Mat3 inertia_about_center() const;      // requires mass > 0
};

// Mirtich (1996), "Fast and accurate computation of polyhedral mass properties": divergence theorem ->
// face integrals -> projection integrals. Exact for a closed, consistently oriented polyhedron
// (outward, counter-clockwise faces). A mesh wound inside-out gives a negative volume.
MassProperties polyhedron_mass_properties(const TriangleMesh& mesh);

// Closed forms (unit density), used for the simple shapes and as independent checks of Mirtich.
MassProperties sphere_mass_properties(const Sphere& s);
MassProperties wire_mass_properties(const Wire& w);     // solid cylinder
MassProperties box_mass_properties(const Box& b);

// Exact mass properties of any shape at unit density: closed forms for sphere, wire and box,
// Mirtich's integrals for plates (extruded polygons) and meshes.
MassProperties shape_mass_properties(const Shape& shape);

// A closed, outward-oriented triangle mesh of the shape. `segments` is the number of sides used for
// round things (circles of spheres and wires); plates and meshes are exact whatever it is.
TriangleMesh shape_mesh(const Shape& shape, int segments = 24);

// Distance (m) from a world point to the solid shape: 0 on or inside it.
double distance_to_shape(const Shape& shape, const Vec3& point);

// Axis-aligned bounds of the shape (world, m).
struct Bounds {
  Vec3 min = Vec3::Constant(1e300);
  Vec3 max = Vec3::Constant(-1e300);
  void add(const Vec3& p) { min = min.cwiseMin(p); max = max.cwiseMax(p); }
};
Bounds shape_bounds(const Shape& shape);

// Why a mesh is not a valid closed solid, or nothing when it is: no triangles, a degenerate
// (zero-area) triangle, an index out of range, an edge not shared by exactly two triangles (open or
// non-manifold), inconsistent orientation, or zero volume.
std::optional<std::string> closed_mesh_problem(const TriangleMesh& mesh);

// Why a plate polygon is not usable, or nothing: fewer than 3 points, repeated points, zero area,
// self-intersecting edges.
std::optional<std::string> polygon_problem(const std::vector<Vec2>& points);

// Triangulate a simple polygon (either winding, convex or concave) by ear clipping. Returns index
// triples into `points`, counter-clockwise in the (u, v) plane.
std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<Vec2>& points);

// Where a triangle read from an OBJ file came from: the 1-based line and column of the face ("f ...")
// it was fanned from.
struct FacePlace {
  int line = 0;
  int column = 0;
};

// A mesh read from an OBJ file and its triangles' places in it (faces[t] for mesh.triangles[t]), so
// that a problem found in the whole mesh can point into the file.
struct ObjMesh {
  TriangleMesh mesh;
  std::vector<FacePlace> faces;
};

// Read a Wavefront OBJ file (vertices and faces; faces with more than 3 vertices are fanned; other
// statements ignored). Throws InputError naming the OBJ file and line on malformed input or a missing
// file. Does not check closure: call check_closed_obj_mesh.
ObjMesh read_obj(const std::string& path);

// closed_mesh_problem's checks on a mesh read from `file`, worded for its author: throws
// InputError(file, ...) naming vertices by OBJ's 1-based numbers and faces by their lines (a single
// degenerate face by its line and column in the error's place).
void check_closed_obj_mesh(const ObjMesh& obj, const std::string& file);

}  // namespace aloft
