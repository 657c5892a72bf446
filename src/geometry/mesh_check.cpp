// closed_mesh_problem() and check_closed_obj_mesh(): whether a triangle mesh bounds a solid, in O(n)
// expected time (edges are counted in a hash map) so that meshes of 100k triangles are checked instantly.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "aloft/error.hpp"
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

// The first thing that keeps a mesh from bounding a solid, as data: closed_mesh_problem and
// check_closed_obj_mesh each word it for their readers.
struct Defect {
  enum Kind { no_triangles, non_finite_vertex, index_out_of_range, degenerate, open_edge, non_manifold_edge,
              misoriented, no_volume, inside_out };
  Kind kind;
  int triangle = -1;  // the triangle concerned (misoriented: the first of the two)
  int other = -1;     // misoriented: the second triangle
  int index = -1;     // non_finite_vertex: the vertex; index_out_of_range: the index
  int a = -1, b = -1; // an edge's vertices, the lower first; misoriented: both triangles run from a to b
  int count = 0;      // non_manifold_edge: the number of triangles using the edge
};

std::optional<Defect> find_defect(const TriangleMesh& mesh) {
  const int nv = static_cast<int>(mesh.vertices.size());
  const int nt = static_cast<int>(mesh.triangles.size());
  if (nt == 0) return Defect{Defect::no_triangles};

  for (int v = 0; v < nv; ++v)
    if (!mesh.vertices[v].allFinite()) return Defect{Defect::non_finite_vertex, -1, -1, v};
  for (int t = 0; t < nt; ++t)
    for (int k : mesh.triangles[t])
      if (k < 0 || k >= nv) return Defect{Defect::index_out_of_range, t, -1, k};

  // Degenerate: twice the area |ab x ac| at most 1e-12 times the squared longest edge, i.e. the triangle's
  // height is below 1e-12 of its length: zero up to the rounding of the coordinates.
  for (int t = 0; t < nt; ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3 &a = mesh.vertices[tri[0]], &b = mesh.vertices[tri[1]], &c = mesh.vertices[tri[2]];
    const double longest2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    const double twice_area = (b - a).cross(c - a).norm();
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] || !(twice_area > 1e-12 * longest2))
      return Defect{Defect::degenerate, t};
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
      if (use.count == 1) return Defect{Defect::open_edge, t, -1, -1, a, b, 1};
      if (use.count > 2) return Defect{Defect::non_manifold_edge, t, -1, -1, a, b, use.count};
      if (use.first_forward == use.second_forward)
        return use.first_forward ? Defect{Defect::misoriented, use.first, use.second, -1, a, b}
                                 : Defect{Defect::misoriented, use.first, use.second, -1, b, a};
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
  if (!(std::abs(six_volume) / 6 > 1e-12 * diagonal * diagonal * diagonal)) return Defect{Defect::no_volume};
  if (six_volume < 0) return Defect{Defect::inside_out};
  return std::nullopt;
}

const char* const kNoVolume = "the mesh encloses no volume";
const char* const kInsideOut =
    "the mesh is inside out: its volume is negative, its triangles run clockwise seen from outside";

// Where triangle t's face is in the file (nowhere, 0:0, for a mesh built without places).
FacePlace place(const ObjMesh& obj, int t) {
  return t >= 0 && static_cast<size_t>(t) < obj.faces.size() ? obj.faces[t] : FacePlace{};
}

// "line 12", "lines 12 and 15", "lines 12, 15 and 20": the distinct lines of the faces of `triangles`, in order.
std::string line_list(const ObjMesh& obj, const std::vector<int>& triangles) {
  std::vector<int> lines;
  for (int t : triangles) lines.push_back(place(obj, t).line);
  std::sort(lines.begin(), lines.end());
  lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
  std::string out;
  for (size_t i = 0; i < lines.size(); ++i)
    out += (i == 0 ? "" : i + 1 == lines.size() ? " and " : ", ") + std::to_string(lines[i]);
  return (lines.size() == 1 ? "line " : "lines ") + out;
}

}  // namespace

std::optional<std::string> closed_mesh_problem(const TriangleMesh& mesh) {
  const std::optional<Defect> d = find_defect(mesh);
  if (!d) return std::nullopt;
  const std::string edge = "edge between vertices " + std::to_string(std::min(d->a, d->b)) + " and " +
                           std::to_string(std::max(d->a, d->b));
  switch (d->kind) {
    case Defect::no_triangles:
      return std::string("the mesh has no triangles");
    case Defect::non_finite_vertex:
      return "vertex " + std::to_string(d->index) + " has a non-finite coordinate";
    case Defect::index_out_of_range:
      return "triangle " + std::to_string(d->triangle) + ": vertex index " + std::to_string(d->index) +
             " out of range (mesh has " + std::to_string(mesh.vertices.size()) + " vertices)";
    case Defect::degenerate:
      return "triangle " + std::to_string(d->triangle) + " is degenerate (zero area)";
    case Defect::open_edge:
      return edge + " belongs to 1 triangle: the mesh is open";
    case Defect::non_manifold_edge:
      return edge + " belongs to " + std::to_string(d->count) + " triangles: not a manifold surface";
    case Defect::misoriented:
      return "triangles " + std::to_string(d->triangle) + " and " + std::to_string(d->other) +
             " are oriented inconsistently (both run along the " + edge + " the same way)";
    case Defect::no_volume:
      return std::string(kNoVolume);
    case Defect::inside_out:
      return std::string(kInsideOut);
  }
  return std::nullopt;  // not reached
}

void check_closed_obj_mesh(const ObjMesh& obj, const std::string& file) {
  const TriangleMesh& mesh = obj.mesh;
  const std::optional<Defect> d = find_defect(mesh);
  if (!d) return;
  const int nt = static_cast<int>(mesh.triangles.size());
  const auto error = [&file](const std::string& problem, FacePlace place = {}) {
    return InputError(file, SourcePlace{"", place.line, place.column}, problem);
  };
  // The vertices as OBJ numbers them, from 1 (negative indices in a face name the same vertices).
  const auto number = [](int v) { return std::to_string(v + 1); };
  const std::string edge = "the edge between vertices " + number(std::min(d->a, d->b)) + " and " +
                           number(std::max(d->a, d->b));
  switch (d->kind) {
    case Defect::no_triangles:
      throw error("file has no faces");
    case Defect::non_finite_vertex:
      throw error("vertex " + number(d->index) + " has a non-finite coordinate");
    case Defect::index_out_of_range:
      throw error("face index " + std::to_string(d->index + 1) + " out of range (" +
                      std::to_string(mesh.vertices.size()) + " vertices)",
                  place(obj, d->triangle));
    case Defect::degenerate: {
      const int t = d->triangle;
      const auto& tri = mesh.triangles[t];
      std::string why =
          "vertices " + number(tri[0]) + ", " + number(tri[1]) + " and " + number(tri[2]) + " lie on a line";
      for (int k = 0; k < 3; ++k) {
        const int u = tri[k], w = tri[(k + 1) % 3];
        if (u == w) why = "vertex " + number(u) + " appears twice";
        else if (mesh.vertices[u] == mesh.vertices[w])
          why = "vertices " + number(std::min(u, w)) + " and " + number(std::max(u, w)) + " are at the same point";
        else continue;
        break;
      }
      // A face of more than 3 corners was fanned into consecutive triangles with the same place.
      const auto same_face = [&](int u) {
        return u >= 0 && u < nt && place(obj, u).line == place(obj, t).line &&
               place(obj, u).column == place(obj, t).column;
      };
      if (same_face(t - 1) || same_face(t + 1))
        throw error("face has a zero-area triangle where it is fanned from its first corner: " + why, place(obj, t));
      throw error("face is degenerate (zero area): " + why, place(obj, t));
    }
    case Defect::open_edge:
      throw error(edge + " belongs to only one face (" + line_list(obj, {d->triangle}) +
                  "): the mesh is not closed");
    case Defect::non_manifold_edge: {
      std::vector<int> users;
      for (int t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k)
          if (std::min(mesh.triangles[t][k], mesh.triangles[t][(k + 1) % 3]) == std::min(d->a, d->b) &&
              std::max(mesh.triangles[t][k], mesh.triangles[t][(k + 1) % 3]) == std::max(d->a, d->b))
            users.push_back(t);
      throw error(edge + " is used by " + std::to_string(d->count) + " triangles (of the faces on " +
                  line_list(obj, users) + "): not a manifold surface");
    }
    case Defect::misoriented:
      throw error("the faces on " + line_list(obj, {d->triangle, d->other}) + " both run from vertex " +
                  number(d->a) + " to vertex " + number(d->b) +
                  ": they are oriented inconsistently (faces sharing an edge must run along it in opposite "
                  "directions)");
    case Defect::no_volume:
      throw error(kNoVolume);
    case Defect::inside_out:
      throw error(kInsideOut);
  }
}

}  // namespace aloft
