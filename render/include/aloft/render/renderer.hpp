#pragma once
// The gallery renderer: the mobile's components lit and shaded in their colours, on a floor in front of
// a wall that both receive its soft shadow (a shadow map from a warm spot light, filtered with PCF).
// Needs a current OpenGL 3.3 core (or ES 3.0) context. Draws into a FrameTarget (fast: the room is shaded
// once and reused while the camera rests; anti-aliasing only where the mobile is) or into whatever
// framebuffer is bound (everything shaded every time).

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "aloft/model.hpp"
#include "aloft/render/camera.hpp"
#include "aloft/render/frame_target.hpp"
#include "aloft/render/scene_mesh.hpp"
#include "aloft/state.hpp"

namespace aloft::render {

struct DrawOptions {
  bool shadows = true;
  bool room = true;               // floor and wall
  bool mobile = true;             // false: the empty room (tests compare against it)
  int highlighted = -1;           // component drawn with a warm glow (the grabbed one), -1: none
  // Per component: non-zero to draw it with a stronger glow of the same colour (pieces touching another,
  // in the viewer and `aloft render --glow-touching`); empty for none.
  std::vector<std::uint8_t> glowing;
  int shadow_map_size = 1024;     // texels per side (the light's frustum is fitted to the mobile)
  // Into a FrameTarget: keep the room shaded in its cached background while the camera, size and model
  // stay the same, and anti-alias only the mobile's rectangle. false: shade the whole picture anew
  // every frame (through the whole multisampled buffer), as the reference the fast path is tested against.
  bool reuse_background = true;
};

// Line segments drawn over the scene (depth-tested): the wind cone, the grab spring.
struct LineSet {
  std::vector<Vec3> points;               // pairs: segment k is points[2k] -> points[2k+1], world, m
  std::array<float, 4> color{0, 0, 0, 1}; // sRGB, alpha
};

// Where the floor and the wall stand for a mobile, and where the key light hangs: derived from its rest
// bounds so that every mobile gets the same composition.
struct Room {
  double floor_y = 0;      // m
  double wall_z = -1;      // m: the wall is the plane z = wall_z, facing +z
  Vec3 light_position;     // m, world
  Vec3 light_target;       // m, world: the spot's aim (the middle of the mobile)
  double light_radius = 1; // m: radius of a sphere around light_target that holds the mobile in any pose
};
Room room_for(const SceneMesh& scene);

// A camera that frames the whole mobile (and some floor and wall) for the given aspect ratio.
OrbitCamera framing_camera(const SceneMesh& scene, double aspect);

class Renderer {
 public:
  // `gles`: compile shaders as GLSL ES 3.00 (for an ES or WebGL2 context) instead of GLSL 3.30 core.
  explicit Renderer(bool gles = false);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Build and upload the meshes of `model` (replacing the previous model's).
  void set_model(const Model& model);
  const SceneMesh& scene() const;
  const Room& room() const;

  // Clear and draw the scene into the bound framebuffer's (0, 0, width, height) viewport. When that
  // framebuffer is a FrameTarget's of this size (FrameTarget::bind()), the same as draw(..., target, ...).
  void draw(const State& state, const OrbitCamera& camera, int width, int height, const DrawOptions& options,
            const std::vector<LineSet>& lines = {});
  // Draw the scene into `target` (call target.resolve() before reading it). Fast path: the background
  // (the room, lit and in full shadow) is shaded only when the camera, the size or the model changed;
  // each frame copies it, blends in the shadow inside the rectangle where it can fall, and draws the
  // mobile and the lines — through the multisampled buffer over their screen rectangle only.
  void draw(const State& state, const OrbitCamera& camera, FrameTarget& target, const DrawOptions& options,
            const std::vector<LineSet>& lines = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace aloft::render
