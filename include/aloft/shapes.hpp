#pragma once
// The geometric primitives a mobile is built from, as the artist places them: in world coordinates at
// the designed rest pose (metres, y up). A component is a union of these, all of one rigid body.

#include <array>
#include <string>
#include <variant>
#include <vector>

#include "aloft/math.hpp"

namespace aloft {

// A closed, consistently oriented triangle mesh (counter-clockwise seen from outside).
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

struct Sphere {
  Vec3 center = Vec3::Zero();
  double radius = 0;  // m, > 0
};

// A straight wire: a solid cylinder (flat ends) between two points.
struct Wire {
  Vec3 from = Vec3::Zero();
  Vec3 to = Vec3::Zero();
  double radius = 0;  // m, > 0
};

struct Box {
  Vec3 center = Vec3::Zero();
  Vec3 size = Vec3::Zero();            // full edge lengths along the box's own axes, m, > 0
  Mat3 rotation = Mat3::Identity();    // box axes -> world
};

// A flat sheet: a simple polygon (convex or concave, either winding) in a plane, extruded
// symmetrically by `thickness` along the plane's normal.
struct Plate {
  std::vector<Vec2> points;            // polygon vertices in plane coordinates (u, v), m
  Vec3 origin = Vec3::Zero();          // world point of plane coordinates (0, 0)
  Vec3 u_axis = Vec3::UnitX();         // unit, world
  Vec3 v_axis = Vec3::UnitY();         // unit, world, orthogonal to u_axis; normal = u x v
  double thickness = 0;                // m, > 0

  Vec3 to_world(const Vec2& p) const { return origin + p.x() * u_axis + p.y() * v_axis; }
  Vec3 normal() const { return u_axis.cross(v_axis); }
};

// A closed triangle mesh read from an OBJ file, already placed in world coordinates.
struct Mesh {
  std::string file;                    // as written in the mobile file (relative to it)
  TriangleMesh mesh;                   // world coordinates
  std::string opened;                  // the path it was read from: `file` resolved against the mobile file's directory
};

using Shape = std::variant<Sphere, Wire, Box, Plate, Mesh>;

// "sphere", "wire", "box", "plate" or "mesh".
const char* shape_kind(const Shape& shape);

}  // namespace aloft
