#include "aloft/render/scene_mesh.hpp"

#include <cmath>
#include <limits>
#include <type_traits>
#include <variant>

namespace aloft::render {

namespace {

// Faces meeting at less than this angle share a smoothed normal; sharper edges stay creased.
constexpr double kCreaseCos = 0.8;  // cos(~37 degrees): wire and sphere facets (15-45 deg) smooth, box edges sharp

// Round shapes need fewer sides when thin: a wire is a few pixels wide on screen.
int segments_for(const Shape& shape) {
  if (std::holds_alternative<Wire>(shape)) return 10;
  return 28;
}

Shape drawable(const Shape& shape) {
  if (const Wire* w = std::get_if<Wire>(&shape); w && w->radius < kMinDrawnWireRadius) {
    Wire thick = *w;
    thick.radius = kMinDrawnWireRadius;
    return thick;
  }
  return shape;
}

// Appends `mesh` as flat triangles with crease-aware vertex normals.
void append_with_normals(const TriangleMesh& mesh, std::vector<float>& out) {
  const std::size_t nt = mesh.triangles.size();
  std::vector<Vec3> face_normal(nt);
  std::vector<double> face_area(nt);
  std::vector<std::vector<int>> faces_at(mesh.vertices.size());
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3 n = (mesh.vertices[tri[1]] - mesh.vertices[tri[0]]).cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]]);
    face_area[t] = n.norm();
    face_normal[t] = face_area[t] > 0 ? Vec3(n / face_area[t]) : Vec3::UnitY();
    for (int v : tri) faces_at[v].push_back(static_cast<int>(t));
  }
  for (std::size_t t = 0; t < nt; ++t) {
    for (int v : mesh.triangles[t]) {
      Vec3 n = Vec3::Zero();
      for (int f : faces_at[v])
        if (face_normal[f].dot(face_normal[t]) > kCreaseCos) n += face_area[f] * face_normal[f];
      n = n.norm() > 0 ? Vec3(n.normalized()) : face_normal[t];
      const Vec3& p = mesh.vertices[v];
      for (double x : {p.x(), p.y(), p.z(), n.x(), n.y(), n.z()}) out.push_back(static_cast<float>(x));
    }
  }
}

// Möller-Trumbore ray-triangle intersection: distance along the ray, or +inf.
double ray_triangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-14) return std::numeric_limits<double>::infinity();
  const double inv = 1 / det;
  const Vec3 s = o - a;
  const double u = s.dot(p) * inv;
  if (u < 0 || u > 1) return std::numeric_limits<double>::infinity();
  const Vec3 q = s.cross(e1);
  const double v = d.dot(q) * inv;
  if (v < 0 || u + v > 1) return std::numeric_limits<double>::infinity();
  const double t = e2.dot(q) * inv;
  return t > 0 ? t : std::numeric_limits<double>::infinity();
}

}  // namespace

SceneMesh build_scene_mesh(const Model& model) {
  SceneMesh scene;
  scene.components.resize(model.count);
  scene.fixed_min_y = std::numeric_limits<double>::infinity();
  scene.hook = model.rest_position.empty() ? Vec3::Zero() : model.rest_position[0];
  for (int i = 0; i < model.count; ++i) {
    ComponentMesh& cm = scene.components[i];
    const Eigen::Matrix3d r = model.rest_orientation[i].toRotationMatrix();
    for (const BodyShape& bs : model.shapes[i]) {
      const TriangleMesh mesh = shape_mesh(drawable(bs.shape), segments_for(bs.shape));
      append_with_normals(mesh, cm.vertices);
      const int base = static_cast<int>(cm.triangles.vertices.size());
      for (const Vec3& v : mesh.vertices) {
        cm.triangles.vertices.push_back(v);
        const Vec3 w = model.rest_position[i] + r * v;
        scene.rest_bounds.add(w);
        if (i == 0) scene.fixed_min_y = std::min(scene.fixed_min_y, w.y());
        scene.reach = std::max(scene.reach, std::hypot(w.x() - scene.hook.x(), w.z() - scene.hook.z()));
      }
      for (const auto& t : mesh.triangles) cm.triangles.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    }
  }
  return scene;
}

std::optional<PickHit> pick(const SceneMesh& scene, const State& state, const Vec3& origin, const Vec3& direction) {
  std::optional<PickHit> best;
  for (std::size_t i = 1; i < scene.components.size() && i < state.position.size(); ++i) {
    // Into the body frame: p_body = R^T (p_world - x).
    const Eigen::Matrix3d rt = state.orientation[i].toRotationMatrix().transpose();
    const Vec3 o = rt * (origin - state.position[i]);
    const Vec3 d = rt * direction;
    const TriangleMesh& m = scene.components[i].triangles;
    for (const auto& t : m.triangles) {
      const double hit = ray_triangle(o, d, m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]);
      if (std::isfinite(hit) && (!best || hit < best->distance)) {
        best = PickHit{static_cast<int>(i), hit, origin + hit * direction, o + hit * d};
      }
    }
  }
  return best;
}

}  // namespace aloft::render
