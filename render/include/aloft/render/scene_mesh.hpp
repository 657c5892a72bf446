#pragma once
// The mobile as triangles for drawing and picking, built once per model on the CPU (no GL here):
// one mesh per component in its body frame, with normals that are smooth across gentle bends and
// sharp at creases (the edges of plates and boxes).

#include <optional>
#include <vector>

#include "aloft/geometry.hpp"
#include "aloft/model.hpp"
#include "aloft/state.hpp"

namespace aloft::render {

struct ComponentMesh {
  // Interleaved vertices: position (body frame, m) then unit normal (body frame), 6 floats each;
  // three consecutive vertices per triangle, counter-clockwise seen from outside.
  std::vector<float> vertices;
  // The same triangles for picking (body frame, m).
  TriangleMesh triangles;
  int vertex_count() const { return static_cast<int>(vertices.size() / 6); }
};

struct SceneMesh {
  std::vector<ComponentMesh> components;   // indexed like the model's components
  Bounds rest_bounds;                      // of every shape at the rest pose, world, m
  Vec3 hook = Vec3::Zero();                // the fixed component's centre, world, m
  double fixed_min_y = 0;                  // lowest point of the fixed component (a stand's foot), m
  double reach = 0;                        // largest horizontal distance of any shape point from the
                                           // hook's vertical line, m: how far the mobile can sweep
};

// Wires thinner than this are drawn at this radius (m) so a thread stays visible at a few metres on a
// 720-line image (one pixel is about 4 mm there); the physics keeps the true radius.
inline constexpr double kMinDrawnWireRadius = 0.0012;

SceneMesh build_scene_mesh(const Model& model);

// The closest component hit by a ray (origin and unit direction, world), ignoring the fixed one.
struct PickHit {
  int component = -1;
  double distance = 0;      // m along the ray
  Vec3 point_world;         // m
  Vec3 point_body;          // the same point in the component's body frame, m
};
std::optional<PickHit> pick(const SceneMesh& scene, const State& state, const Vec3& origin, const Vec3& direction);

}  // namespace aloft::render
