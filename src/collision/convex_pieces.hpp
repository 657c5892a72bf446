#pragma once
// Convex pieces: what the narrow phase works on. Every shape of a component becomes one or more convex
// solids in the component's body (principal) frame:
//
//   sphere  -> one Sphere piece                     (closed forms)
//   wire    -> one Cylinder piece (flat ends)       (closed forms; GJK when an end is involved)
//   box     -> one Polytope (its 8 corners)         (GJK/EPA)
//   plate   -> one Polytope per convex part of the polygon (ear clipping, then Hertel-Mehlhorn merging
//              of triangles across diagonals while the union stays convex), each extruded by the
//              plate's thickness: the union of the parts is exactly the plate, concave or not.
//   mesh    -> star-shaped about its vertex centroid (the centroid strictly inside every face plane):
//              one tetrahedron per triangle to the centroid, whose union is exactly the solid;
//              otherwise a shell: one thin prism per triangle, extruded inwards by kShellThickness.
//              The shell finds every contact of the surface; it misses only a body wholly inside the
//              mesh, which speculative contacts prevent from ever happening.
//
// The convex hull of a concave plate or mesh is never used: it would report contacts in the notches.

#include <vector>

#include "aloft/model.hpp"

namespace aloft::internal {

struct ConvexPiece {
  enum class Kind { Sphere, Cylinder, Polytope };
  Kind kind = Kind::Sphere;
  int shape = 0;                   // index of the shape in Model::shapes[component]
  Vec3 a = Vec3::Zero();           // sphere: centre; cylinder: one end of the axis (body frame, m)
  Vec3 b = Vec3::Zero();           // cylinder: other end of the axis (body frame, m)
  double radius = 0;               // sphere, cylinder: m
  std::vector<Vec3> vertices;      // polytope: the piece is their convex hull (body frame, m)
  // Directions worth testing as a separating axis (body frame, unit, sign irrelevant): a polytope's face
  // normals, a cylinder's axis. The overlap test checks them besides EPA's answer (gjk_contact.cpp).
  std::vector<Vec3> axes;
  // A polytope's extent along each of its axes: axis_low[k] <= axes[k] . p <= axis_high[k] for every
  // point p of the piece (body frame, m; the slabs near_part.hpp cuts with). Empty for round pieces.
  std::vector<double> axis_low, axis_high;
  // The directions of the piece's edges (body frame, unit, sign irrelevant; a cylinder's axis). For two
  // polytopes, the separating axis is one of the face normals or the cross product of an edge direction
  // of each (the separating axis theorem), so with these the overlap test's candidates are complete.
  std::vector<Vec3> edges;
  // A plate's part is a prism: its vertices are mid-plane points p +- prism_half. support() then scans
  // the mid-plane points only (half the vertices): max over p, s of (p + s h).d = max p.d + |h.d|.
  std::vector<Vec3> prism_middle;  // body frame, m (empty: not a prism)
  Vec3 prism_half = Vec3::Zero();  // half the thickness along the plate's normal, body frame, m
  Vec3 bound_center = Vec3::Zero();  // a sphere enclosing the piece (body frame, m)
  double bound_radius = 0;
  Vec3 box_low = Vec3::Zero(), box_high = Vec3::Zero();  // a box enclosing it, body axes (body frame, m)
  double reach = 0;                  // m: largest distance from the centre of mass (body origin) to the piece
  // m: half the piece's smallest width (a sphere's or a wire's radius, half a plate's thickness): how deep
  // another piece can get into it before it is nearer the far side (Simulation's limit on how much deeper
  // pieces in contact may get in a step is a fraction of it).
  double half_width = 0;

  // The point of the piece farthest along `direction` (body frame; direction need not be unit).
  Vec3 support(const Vec3& direction) const;
  // The same for the piece's core: a sphere's centre, a cylinder's axis (the segment a-b), a polytope
  // itself. A round piece is its core grown by `radius` (a sphere exactly; a cylinder lies inside that
  // capsule), and the core's support is a point or a segment end, so GJK on cores ends in finitely many
  // steps where on a round support it only converges.
  Vec3 core_support(const Vec3& direction) const;
  // Largest distance (m) from `point` (body frame) to any point of the piece. Exact.
  double farthest_distance(const Vec3& point) const;
};

// The pieces of one component, with an enclosing sphere of all of them.
struct ComponentGeometry {
  std::vector<ConvexPiece> pieces;
  Vec3 bound_center = Vec3::Zero();  // body frame, m
  double bound_radius = 0;           // m; 0 with no pieces
  Vec3 box_center = Vec3::Zero();    // body-frame axis-aligned box enclosing all pieces: centre, m
  Vec3 box_half = Vec3::Zero();      // and half extents, m
  double reach = 0;                  // m: largest distance from the centre of mass (body origin) to the solid

  // Largest distance (m) from `point` (body frame) to any point of the component. 0 with no pieces.
  double farthest_distance(const Vec3& point) const;
};

// Inward thickness (m) of the per-triangle prisms of a mesh that is not star-shaped about its centroid.
inline constexpr double kShellThickness = 0.002;

ComponentGeometry build_component_geometry(const std::vector<BodyShape>& shapes);

// Convex parts of a simple polygon (either winding): index lists into `points`, counter-clockwise.
std::vector<std::vector<int>> convex_decomposition(const std::vector<Vec2>& points);

}  // namespace aloft::internal
