// closed_mesh_problem(): whether a triangle mesh bounds a solid, in O(n) expected time (edges are
// counted in a hash map) so that meshes of 100k triangles are checked instantly.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "aloft/geometry.hpp"

namespace aloft {
namespace {

// The triangles using one undirected edge. "forward" means the triangle runs along the edge from its
// lower-numbered vertex to its higher one.
struct EdgeUse {
  int count = 0;
  int first = -1, second = -1;  // the first two triangles using the edge
  bool first_forward = false, second_forward = false;
};

std::uint64_t edge_key(int a, int b) {
  const auto lo = static_cast<std::uint32_t>(std::min(a, b)), hi = static_cast<std::uint32_t>(std::max(a, b));
  return (static_cast<std::uint64_t>(lo) << 32) | hi;
}

}  // namespace

std::optional<std::string> closed_mesh_problem(const TriangleMesh& mesh) {
  const int nv = static_cast<int>(mesh.vertices.size());
  const int nt = static_cast<int>(mesh.triangles.size());
  if (nt == 0) return std::string("the mesh has no triangles");

  for (int v = 0; v < nv; ++v)
    if (!mesh.vertices[v].allFinite()) return "vertex " + std::to_string(v) + " has a non-finite coordinate";
  for (int t = 0; t < nt; ++t)
    for (int k : mesh.triangles[t])
      if (k < 0 || k >= nv)
        return "triangle " + std::to_string(t) + ": vertex index " + std::to_string(k) + " out of range (mesh has " +
               std::to_string(nv) + " vertices)";

  // Degenerate: twice the area |ab x ac| at most 1e-12 times the squared longest edge, i.e. the triangle's
  // height is below 1e-12 of its length: zero up to the rounding of the coordinates.
  for (int t = 0; t < nt; ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3 &a = mesh.vertices[tri[0]], &b = mesh.vertices[tri[1]], &c = mesh.vertices[tri[2]];
    const double longest2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    const double twice_area = (b - a).cross(c - a).norm();
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] || !(twice_area > 1e-12 * longest2))
      return "triangle " + std::to_string(t) + " is degenerate (zero area)";
  }

  std::unordered_map<std::uint64_t, EdgeUse> edges;
  edges.reserve(static_cast<size_t>(nt) * 3 / 2 + 1);
  for (int t = 0; t < nt; ++t) {
    const auto& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      EdgeUse& use = edges[edge_key(a, b)];
      if (use.count == 0) {
        use.first = t;
        use.first_forward = a < b;
      } else if (use.count == 1) {
        use.second = t;
        use.second_forward = a < b;
      }
      ++use.count;
    }
  }
  // Report the first problem in triangle order, so that the message does not depend on hashing.
  for (int t = 0; t < nt; ++t) {
    const auto& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const int a = std::min(tri[k], tri[(k + 1) % 3]), b = std::max(tri[k], tri[(k + 1) % 3]);
      const EdgeUse& use = edges.at(edge_key(a, b));
      const std::string edge = "edge between vertices " + std::to_string(a) + " and " + std::to_string(b);
      if (use.count == 1) return edge + " belongs to 1 triangle: the mesh is open";
      if (use.count > 2)
        return edge + " belongs to " + std::to_string(use.count) + " triangles: not a manifold surface";
      if (use.first_forward == use.second_forward)
        return "triangles " + std::to_string(use.first) + " and " + std::to_string(use.second) +
               " are oriented inconsistently (both run along the " + edge + " the same way)";
    }
  }

  // Volume by signed tetrahedra from the bounding box centre (exact for a closed surface, independent of
  // that point). Zero: |V| at most 1e-12 of the bounding box's diagonal cubed.
  Vec3 lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (const Vec3& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const Vec3 o = (lo + hi) / 2;
  double six_volume = 0;
  for (const auto& tri : mesh.triangles)
    six_volume += (mesh.vertices[tri[0]] - o).dot((mesh.vertices[tri[1]] - o).cross(mesh.vertices[tri[2]] - o));
  const double diagonal = (hi - lo).norm();
  if (!(std::abs(six_volume) / 6 > 1e-12 * diagonal * diagonal * diagonal))
    return std::string("the mesh encloses no volume");
  if (six_volume < 0)
    return std::string("the mesh is inside out: its volume is negative, its triangles run clockwise seen from outside");
  return std::nullopt;
}

}  // namespace aloft
