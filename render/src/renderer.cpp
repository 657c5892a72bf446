#include "aloft/render/renderer.hpp"

#include <algorithm>
#include <cmath>

#include "aloft/render/frame_target.hpp"
#include "aloft/render/gl.hpp"
#include "gl_program.hpp"
#include "shaders.hpp"

namespace aloft::render {

namespace {

// Gallery colours (sRGB) and finishes.
constexpr float kFloorColor[3] = {0.60f, 0.58f, 0.55f};   // pale concrete
constexpr float kWallColor[3] = {0.84f, 0.82f, 0.78f};    // warm white
constexpr float kBackground[3] = {0.16f, 0.16f, 0.17f};   // beyond the room (seen from behind the wall)
constexpr float kMobileSpecular = 0.35f, kMobileShininess = 48.0f;  // painted steel
// DrawOptions::glowing: stronger than the grabbed piece's 1 (0.72 of the way to the glow's orange against
// 0.45), so that a touching piece stands out among a generated mobile's many colours.
constexpr float kGlowingHighlight = 1.6f;
constexpr float kRoomSpecular = 0.03f, kRoomShininess = 8.0f;       // matt paint
// Soft-shadow filter radius as a fraction of the shadow map's width (with 1024 texels: 2.5 texels).
constexpr float kShadowRadius = 0.0025f;

// The shader lights in linear space; the file's colours are sRGB.
float srgb_to_linear(float c) { return std::pow(c, 2.2f); }
void set_color(GLint location, const float* srgb) {
  glUniform3f(location, srgb_to_linear(srgb[0]), srgb_to_linear(srgb[1]), srgb_to_linear(srgb[2]));
}

void set_mat4(GLint location, const Mat4f& m) { glUniformMatrix4fv(location, 1, GL_FALSE, m.data()); }
void set_vec3(GLint location, const Vec3& v) {
  glUniform3f(location, static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()));
}

// Quad as two triangles, each vertex position + normal.
void add_quad(std::vector<float>& out, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& n) {
  for (const Vec3* p : {&a, &b, &c, &a, &c, &d})
    for (double x : {p->x(), p->y(), p->z(), n.x(), n.y(), n.z()}) out.push_back(static_cast<float>(x));
}

// Screen rectangles (x, y, width, height in pixels; empty: width or height 0).
using Rect = std::array<int, 4>;

// Grows a pixel-space bounding box by a world point seen through `view_proj`; false when the point is
// behind the camera (the rectangle would be unbounded).
bool add_to_box(const Mat4f& view_proj, const Vec3& p, int width, int height, double box[4]) {
  const Eigen::Vector4f clip =
      view_proj * Eigen::Vector4f(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()), 1.0f);
  if (clip.w() <= 1e-4f) return false;
  const double sx = (clip.x() / clip.w() * 0.5 + 0.5) * width, sy = (clip.y() / clip.w() * 0.5 + 0.5) * height;
  box[0] = std::min(box[0], sx), box[1] = std::min(box[1], sy), box[2] = std::max(box[2], sx), box[3] = std::max(box[3], sy);
  return true;
}

// The box (x0, y0, x1, y1) grown by `margin` pixels, clipped to the screen, as a Rect.
Rect to_rect(const double box[4], double margin, int width, int height) {
  if (box[0] > box[2]) return {0, 0, 0, 0};
  const int ax = std::clamp(static_cast<int>(std::floor(box[0] - margin)), 0, width);
  const int bx = std::clamp(static_cast<int>(std::ceil(box[2] + margin)), 0, width);
  const int ay = std::clamp(static_cast<int>(std::floor(box[1] - margin)), 0, height);
  const int by = std::clamp(static_cast<int>(std::ceil(box[3] + margin)), 0, height);
  return {ax, ay, bx - ax, by - ay};
}

Rect unite(const Rect& a, const Rect& b) {
  if (a[2] <= 0 || a[3] <= 0) return b;
  if (b[2] <= 0 || b[3] <= 0) return a;
  const int x0 = std::min(a[0], b[0]), y0 = std::min(a[1], b[1]);
  const int x1 = std::max(a[0] + a[2], b[0] + b[2]), y1 = std::max(a[1] + a[3], b[1] + b[3]);
  return {x0, y0, x1 - x0, y1 - y0};
}

int area(const Rect& r) { return std::max(r[2], 0) * std::max(r[3], 0); }

// Drops empty rectangles and merges any two whose union costs no more pixels than the two apart, until
// none do: fewer, non-wasteful rectangles to shade (an overlap would be shaded twice).
void merge(std::vector<Rect>& rects) {
  std::erase_if(rects, [](const Rect& r) { return area(r) == 0; });
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t i = 0; i < rects.size() && !merged; ++i)
      for (std::size_t j = i + 1; j < rects.size() && !merged; ++j) {
        const Rect u = unite(rects[i], rects[j]);
        if (area(u) <= area(rects[i]) + area(rects[j])) {
          rects[i] = u;
          rects.erase(rects.begin() + static_cast<std::ptrdiff_t>(j));
          merged = true;
        }
      }
  }
}

// Where the overlay lines fall on the screen (a line is one pixel wide: one pixel of margin).
Rect lines_rectangle(const std::vector<LineSet>& lines, const Mat4f& view_proj, int width, int height) {
  double box[4] = {1e30, 1e30, -1e30, -1e30};
  for (const LineSet& set : lines)
    for (const Vec3& p : set.points)
      if (!add_to_box(view_proj, p, width, height, box)) return {0, 0, width, height};
  return to_rect(box, 2, width, height);
}

}  // namespace

Room room_for(const SceneMesh& scene) {
  Room room;
  const Bounds& b = scene.rest_bounds;
  const Vec3 hook = scene.hook;
  const double height = std::max(hook.y() - b.min.y(), 0.1);
  // A standing piece (its fixed stand reaches the lowest point) stands on the floor; a hanging one hangs
  // well above it.
  room.floor_y = scene.fixed_min_y <= b.min.y() + 0.02 ? b.min.y() : b.min.y() - std::max(0.9, 0.6 * height);
  room.wall_z = std::min(hook.z() - scene.reach, b.min.z()) - 0.45;
  room.light_target = Vec3(hook.x(), (std::max(hook.y(), b.max.y()) + b.min.y()) / 2, hook.z());
  room.light_radius = std::hypot(scene.reach, (std::max(hook.y(), b.max.y()) - b.min.y()) / 2) + 0.05;
  // Above, in front and to the left, so the shadow falls behind and to the right on the wall and floor.
  const Vec3 direction = Vec3(-0.4, 0.62, 1.0).normalized();
  room.light_position = room.light_target + direction * std::max(3.0, 3.2 * room.light_radius);
  return room;
}

OrbitCamera framing_camera(const SceneMesh& scene, double aspect) {
  OrbitCamera camera;
  const Bounds& b = scene.rest_bounds;
  const double top = std::max(scene.hook.y(), b.max.y());
  const double half_height = (top - b.min.y()) / 2 + 0.1;
  const double half_width = scene.reach + 0.1;
  camera.target = Vec3((b.min.x() + b.max.x()) / 2, (top + b.min.y()) / 2 - 0.1, scene.hook.z());
  camera.yaw = 0.28;  // rad (16 degrees): from a little to the right (+x) of the front (+z)
  camera.pitch = 0.12;
  const double t = std::tan(camera.fov_y / 2);
  camera.distance = 1.05 * std::max(half_height / t, half_width / (t * std::max(aspect, 0.2))) + 0.5 * scene.reach;
  return camera;
}

struct Renderer::Impl {
  bool gles;
  std::unique_ptr<GlProgram> lit[2][2];   // [room][shadows]: compiled variants of the lit shader
  std::unique_ptr<GlProgram> background;     // the room lit and unlit at once (FrameTarget's cache)
  std::unique_ptr<GlProgram> shadowed_room;  // the cache blended by the shadow (the shadow's rectangle)
  std::unique_ptr<GlProgram> copy;           // the picture under the room's geometry (into the MSAA buffer)
  GlProgram depth;
  GlProgram line;
  SceneMesh scene;
  Room room;
  std::vector<float> colors;               // per component, sRGB
  std::vector<std::pair<int, int>> ranges; // per component: first vertex, vertex count
  std::vector<Bounds> body_bounds;         // per component, body frame, m
  GLuint mobile_vao = 0, mobile_vbo = 0;
  GLuint room_vao = 0, room_vbo = 0;
  int room_vertices = 0;
  GLuint line_vao = 0, line_vbo = 0;
  GLuint shadow_texture = 0, shadow_fbo = 0;
  int shadow_size = 0;
  int model_generation = 0;                // unique over all renderers: part of the background's key

  explicit Impl(bool gles_)
      : gles(gles_),
        depth(shaders::glsl_source(shaders::kDepthVertex, gles_),
              shaders::glsl_source(shaders::kDepthFragment, gles_), "shadow"),
        line(shaders::glsl_source(shaders::kLineVertex, gles_), shaders::glsl_source(shaders::kLineFragment, gles_),
             "line") {
    using shaders::glsl_source;
    const std::string lit_fragment = std::string(shaders::kShadowFunction) + shaders::kLitFragment;
    for (int room = 0; room < 2; ++room)
      for (int shadows = 0; shadows < 2; ++shadows) {
        const std::string defines = std::string(room ? "#define ROOM\n" : "") + (shadows ? "#define SHADOWS\n" : "");
        lit[room][shadows] = std::make_unique<GlProgram>(glsl_source(shaders::kLitVertex, gles_, defines),
                                                         glsl_source(lit_fragment, gles_, defines), "lit");
      }
    background = std::make_unique<GlProgram>(glsl_source(shaders::kLitVertex, gles_),
                                             glsl_source(lit_fragment, gles_, "#define ROOM\n#define BACKGROUND\n"),
                                             "background");
    shadowed_room = std::make_unique<GlProgram>(
        glsl_source(shaders::kLitVertex, gles_),
        glsl_source(std::string(shaders::kShadowFunction) + shaders::kShadowedRoomFragment, gles_,
                    "#define ROOM\n#define SHADOWS\n"),
        "shadowed room");
    copy = std::make_unique<GlProgram>(glsl_source(shaders::kLitVertex, gles_), glsl_source(shaders::kCopyFragment, gles_),
                                       "copy");
    glGenVertexArrays(1, &mobile_vao);
    glGenBuffers(1, &mobile_vbo);
    glGenVertexArrays(1, &room_vao);
    glGenBuffers(1, &room_vbo);
    glGenVertexArrays(1, &line_vao);
    glGenBuffers(1, &line_vbo);
    glBindVertexArray(line_vao);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
    glBindVertexArray(0);
    check_gl("renderer setup");
  }

  ~Impl() {
    glDeleteVertexArrays(1, &mobile_vao);
    glDeleteBuffers(1, &mobile_vbo);
    glDeleteVertexArrays(1, &room_vao);
    glDeleteBuffers(1, &room_vbo);
    glDeleteVertexArrays(1, &line_vao);
    glDeleteBuffers(1, &line_vbo);
    if (shadow_fbo) glDeleteFramebuffers(1, &shadow_fbo);
    if (shadow_texture) glDeleteTextures(1, &shadow_texture);
  }

  static void upload(GLuint vao, GLuint vbo, const std::vector<float>& data) {
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), reinterpret_cast<void*>(3 * sizeof(float)));
    glBindVertexArray(0);
  }

  void ensure_shadow_map(int size) {
    if (size == shadow_size) return;
    if (!shadow_texture) glGenTextures(1, &shadow_texture);
    if (!shadow_fbo) glGenFramebuffers(1, &shadow_fbo);
    glBindTexture(GL_TEXTURE_2D, shadow_texture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, size, size, 0, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadow_texture, 0);
    const GLenum none = GL_NONE;
    glDrawBuffers(1, &none);
    glReadBuffer(GL_NONE);
    shadow_size = size;
  }

  // Half the light frustum's opening angle, rad: the sphere that holds the mobile, and 10 % more.
  double light_half_angle() const {
    const double dist = (room.light_position - room.light_target).norm();
    return std::asin(std::min(0.95, room.light_radius / dist)) * 1.1;
  }

  Mat4f light_view_proj() const {
    const double dist = (room.light_position - room.light_target).norm();
    const double half_angle = light_half_angle();
    const double near = std::max(0.05, dist - room.light_radius - 0.2);
    const double far = dist + room.light_radius + 0.2;
    return perspective(2 * half_angle, 1.0, near, far) * look_at(room.light_position, room.light_target, Vec3::UnitY());
  }

  // The screen rectangle (x, y, width, height in pixels) that holds the mobile's shadow on the floor and
  // the wall: every corner of every component's box, sent from the light onto the first of the two
  // planes it meets, projected, plus a margin for the soft edge. Empty when nothing casts there; the
  // whole screen when a corner is behind the camera (the rectangle would be unbounded).
  std::array<int, 4> shadow_rectangle(const State& state, const Mat4f& view_proj, int width, int height) const {
    const std::array<int, 4> whole{0, 0, width, height};
    double x0 = 1e30, y0 = 1e30, x1 = -1e30, y1 = -1e30;
    const Vec3 light = room.light_position;
    const int n = std::min<int>(static_cast<int>(body_bounds.size()), static_cast<int>(state.position.size()));
    for (int i = 0; i < n; ++i) {
      const Bounds& b = body_bounds[i];
      if (b.min.x() > b.max.x()) continue;
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3 local((corner & 1) ? b.max.x() : b.min.x(), (corner & 2) ? b.max.y() : b.min.y(),
                         (corner & 4) ? b.max.z() : b.min.z());
        const Vec3 p = state.position[i] + state.orientation[i] * local;
        const Vec3 d = p - light;
        // Distances along the ray to the floor (y = floor_y) and the wall (z = wall_z); the first hit counts.
        double t = 1e30;
        if (d.y() < 0) t = std::min(t, (room.floor_y - light.y()) / d.y());
        if (d.z() < 0) t = std::min(t, (room.wall_z - light.z()) / d.z());
        if (t >= 1e29 || t < 1) continue;  // the shadow falls nowhere in the room
        const Vec3 q = light + t * d;
        const Eigen::Vector4f clip = view_proj * Eigen::Vector4f(static_cast<float>(q.x()), static_cast<float>(q.y()),
                                                                 static_cast<float>(q.z()), 1.0f);
        if (clip.w() <= 1e-4f) return whole;
        const double sx = (clip.x() / clip.w() * 0.5 + 0.5) * width, sy = (clip.y() / clip.w() * 0.5 + 0.5) * height;
        x0 = std::min(x0, sx), x1 = std::max(x1, sx), y0 = std::min(y0, sy), y1 = std::max(y1, sy);
      }
    }
    if (x0 > x1) return {0, 0, 0, 0};
    const double margin = 0.03 * std::max(width, height);  // the filter's blur and the boxes' rounding
    const int ax = std::clamp(static_cast<int>(x0 - margin), 0, width), bx = std::clamp(static_cast<int>(x1 + margin), 0, width);
    const int ay = std::clamp(static_cast<int>(y0 - margin), 0, height), by = std::clamp(static_cast<int>(y1 + margin), 0, height);
    return {ax, ay, bx - ax, by - ay};
  }

  // Component i's box in world space as the corners of up to 16 slices across its longest side (a bar's
  // box cut into short pieces: their screen rectangles hug a slanted bar far closer than the whole
  // box's), world, m. The slices together are the box.
  std::vector<std::array<Vec3, 8>> box_slices(const State& state, int i) const {
    const Bounds& b = body_bounds[i];
    const Vec3 size = b.max - b.min;
    int axis = 0;
    size.maxCoeff(&axis);
    Vec3 rest = size;
    rest[axis] = 0;
    const double across = std::max(rest.maxCoeff(), 0.01);  // m
    const int count = std::clamp(static_cast<int>(std::ceil(size[axis] / (2 * across))), 1, 16);
    std::vector<std::array<Vec3, 8>> slices(count);
    for (int k = 0; k < count; ++k) {
      Vec3 lo = b.min, hi = b.max;
      lo[axis] = b.min[axis] + size[axis] * k / count;
      hi[axis] = b.min[axis] + size[axis] * (k + 1) / count;
      for (int c = 0; c < 8; ++c)
        slices[k][c] = state.position[i] + state.orientation[i] * Vec3((c & 1) ? hi.x() : lo.x(),
                                                                       (c & 2) ? hi.y() : lo.y(),
                                                                       (c & 4) ? hi.z() : lo.z());
    }
    return slices;
  }
  int drawn_components(const State& state) const {
    return std::min<int>(static_cast<int>(body_bounds.size()), static_cast<int>(state.position.size()));
  }
  bool has_box(int i) const { return body_bounds[i].min.x() <= body_bounds[i].max.x(); }

  // The screen rectangles that hold the mobile: one per slice of each component's box (its corners
  // projected, and two pixels for the multisampled edge), merged where that costs nothing. The whole
  // screen when a box reaches behind the camera.
  std::vector<Rect> mobile_rectangles(const State& state, const Mat4f& view_proj, int width, int height) const {
    std::vector<Rect> rects;
    for (int i = 0; i < drawn_components(state); ++i) {
      if (!has_box(i)) continue;
      for (const std::array<Vec3, 8>& slice : box_slices(state, i)) {
        double box[4] = {1e30, 1e30, -1e30, -1e30};
        for (const Vec3& p : slice)
          if (!add_to_box(view_proj, p, width, height, box)) return {{0, 0, width, height}};
        rects.push_back(to_rect(box, 2, width, height));
      }
    }
    merge(rects);
    return rects;
  }

  // The screen rectangles that hold the mobile's shadow on the floor and on the wall. For each slice of
  // each component's box and each of the two planes: the rays from the light through its corners meet the plane in
  // points whose bounding rectangle in the plane, cut to the part of the plane that is in the room and
  // grown by the filter's blur there, holds the box's shadow on that plane; its four corners are
  // projected to the screen. Merged where that costs nothing; the whole screen when a ray does not reach
  // a plane or a point is behind the camera.
  std::vector<Rect> shadow_rectangles(const State& state, const Mat4f& view_proj, int width, int height) const {
    const std::vector<Rect> whole{{0, 0, width, height}};
    const Vec3 light = room.light_position;
    // The blur's radius per metre from the light: the PCF radius (and one texel of bilinear comparison)
    // as a fraction of the map, times the map's width per metre of distance; plus the normal offset.
    const double half_angle = light_half_angle();
    const double blur_per_metre = (kShadowRadius + 1.0 / std::max(shadow_size, 64)) * 2 * std::tan(half_angle);
    std::vector<Rect> rects;
    for (int i = 0; i < drawn_components(state); ++i) {
      if (!has_box(i)) continue;
      for (const std::array<Vec3, 8>& corners : box_slices(state, i))
      for (int plane = 0; plane < 2; ++plane) {  // 0: the floor y = floor_y, 1: the wall z = wall_z
        double lo[2] = {1e30, 1e30}, hi[2] = {-1e30, -1e30}, blur = 0;
        for (const Vec3& p : corners) {
          const Vec3 d = p - light;
          const double along = plane == 0 ? d.y() : d.z();
          if (along >= -1e-9) return whole;  // the ray never meets the plane
          const double t = ((plane == 0 ? room.floor_y : room.wall_z) - (plane == 0 ? light.y() : light.z())) / along;
          const Vec3 q = light + t * d;
          // In-plane coordinates: x and z on the floor, x and y on the wall.
          const double u = q.x(), v = plane == 0 ? q.z() : q.y();
          lo[0] = std::min(lo[0], u), hi[0] = std::max(hi[0], u), lo[1] = std::min(lo[1], v), hi[1] = std::max(hi[1], v);
          blur = std::max(blur, blur_per_metre * (q - light).norm() + 0.004);
        }
        lo[0] -= blur, lo[1] -= blur, hi[0] += blur, hi[1] += blur;
        // The floor is in the room in front of the wall (z >= wall_z), the wall above the floor.
        lo[1] = std::max(lo[1], plane == 0 ? room.wall_z : room.floor_y);
        if (lo[1] > hi[1]) continue;
        double box[4] = {1e30, 1e30, -1e30, -1e30};
        for (int c = 0; c < 4; ++c) {
          const double u = (c & 1) ? hi[0] : lo[0], v = (c & 2) ? hi[1] : lo[1];
          const Vec3 q = plane == 0 ? Vec3(u, room.floor_y, v) : Vec3(u, v, room.wall_z);
          if (!add_to_box(view_proj, q, width, height, box)) return whole;
        }
        rects.push_back(to_rect(box, 1, width, height));
      }
    }
    merge(rects);
    return rects;
  }

  // The uniforms every lit pass shares; leaves `program` in use.
  void setup(GlProgram& program, const OrbitCamera& camera, const Mat4f& view_proj, const Mat4f& light_vp) {
    program.use();
    set_mat4(program.uniform("u_view_proj"), view_proj);
    set_mat4(program.uniform("u_light_view_proj"), light_vp);
    set_vec3(program.uniform("u_eye"), camera.eye());
    set_vec3(program.uniform("u_light_pos"), room.light_position);
    set_vec3(program.uniform("u_light_dir"), (room.light_target - room.light_position).normalized());
    glUniform1f(program.uniform("u_shadow_radius"), kShadowRadius);
    glUniform2f(program.uniform("u_corner"), static_cast<float>(room.floor_y), static_cast<float>(room.wall_z));
    glUniform1i(program.uniform("u_shadow_map"), 0);
  }

  // The floor and the wall with `program` (already set up).
  void draw_room(GlProgram& program) {
    glBindVertexArray(room_vao);
    set_mat4(program.uniform("u_model"), Mat4f::Identity());
    glUniform2f(program.uniform("u_material"), kRoomSpecular, kRoomShininess);
    set_color(program.uniform("u_color"), kFloorColor);
    glDrawArrays(GL_TRIANGLES, 0, 6);
    set_color(program.uniform("u_color"), kWallColor);
    glDrawArrays(GL_TRIANGLES, 6, 6);
  }

  void draw_lit_mobile(GlProgram& program, const State& state, const OrbitCamera& camera, const Mat4f& view_proj,
                       const Mat4f& light_vp, const DrawOptions& options) {
    setup(program, camera, view_proj, light_vp);
    glUniform2f(program.uniform("u_material"), kMobileSpecular, kMobileShininess);
    draw_mobile(program, state, &options);
  }

  // The shadow map: depth of the mobile as the key light sees it (clear without the mobile: nothing
  // casts). Restores the draw framebuffer.
  void render_shadow_map(const State& state, const DrawOptions& options, const Mat4f& light_vp) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_BLEND);
    if (!options.shadows) return;
    GLint target_fbo = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &target_fbo);
    ensure_shadow_map(options.shadow_map_size);
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
    glViewport(0, 0, shadow_size, shadow_size);
    glClear(GL_DEPTH_BUFFER_BIT);
    glDisable(GL_CULL_FACE);  // thin plates: both faces cast
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(2.0f, 4.0f);  // against self-shadowing acne on lit faces
    depth.use();
    set_mat4(depth.uniform("u_light_view_proj"), light_vp);
    if (options.mobile) draw_mobile(depth, state, nullptr);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(target_fbo));
  }

  // The FrameTarget's cached background: clear, then the room lit (attachment 0) and unlit (1), with
  // `samples` > 0 through the multisampled buffer and resolved; its depth drawn single-sample.
  void render_background(FrameTarget& target, int samples, bool with_room, const OrbitCamera& camera,
                         const Mat4f& view_proj, const Mat4f& light_vp) {
    const int width = target.width(), height = target.height();
    const GLenum both[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glBindFramebuffer(GL_FRAMEBUFFER, samples > 0 ? target.msaa_fbo_ : target.background_fbo_);
    glDrawBuffers(2, both);
    glViewport(0, 0, width, height);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_CULL_FACE);  // from behind the wall or below the floor, see through them
    glCullFace(GL_BACK);
    if (with_room) {
      setup(*background, camera, view_proj, light_vp);
      draw_room(*background);
    }
    if (samples > 0) {
      for (int i = 0; i < 2; ++i) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, target.msaa_fbo_);
        glReadBuffer(both[i]);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target.background_fbo_);
        const GLenum one[] = {i == 0 ? both[0] : GL_NONE, i == 1 ? both[1] : GL_NONE};
        glDrawBuffers(2, one);
        glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
      }
      // The depth, single-sample, with the trivial depth shader (colour writes off).
      glBindFramebuffer(GL_FRAMEBUFFER, target.background_fbo_);
      glDrawBuffers(2, both);
      glClear(GL_DEPTH_BUFFER_BIT);
      if (with_room) {
        glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        depth.use();
        set_mat4(depth.uniform("u_light_view_proj"), view_proj);
        glBindVertexArray(room_vao);
        set_mat4(depth.uniform("u_model"), Mat4f::Identity());
        glDrawArrays(GL_TRIANGLES, 0, 12);
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
      }
    }
    glDisable(GL_CULL_FACE);
  }

  // Overlay lines (depth-tested, blended).
  void draw_lines(const std::vector<LineSet>& lines, const Mat4f& view_proj) {
    if (lines.empty()) return;
    line.use();
    set_mat4(line.uniform("u_view_proj"), view_proj);
    glBindVertexArray(line_vao);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    for (const LineSet& set : lines) {
      if (set.points.size() < 2) continue;
      std::vector<float> data;
      data.reserve(set.points.size() * 3);
      for (const Vec3& p : set.points)
        data.insert(data.end(), {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data.size() * sizeof(float)), data.data(), GL_STREAM_DRAW);
      glUniform4fv(line.uniform("u_color"), 1, set.color.data());
      glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(set.points.size() / 2 * 2));
    }
    glDisable(GL_BLEND);
  }

  // With `colored` (the lit pass), each component in its colour and with its glow: full for the
  // highlighted one, kGlowingHighlight for the glowing ones; without (the shadow map's depth), shapes only.
  void draw_mobile(GlProgram& program, const State& state, const DrawOptions* colored) {
    glBindVertexArray(mobile_vao);
    const int n = std::min<int>(static_cast<int>(ranges.size()), static_cast<int>(state.position.size()));
    for (int i = 0; i < n; ++i) {
      if (ranges[i].second == 0) continue;
      set_mat4(program.uniform("u_model"), rigid_transform(state.position[i], state.orientation[i]));
      if (colored) {
        glUniform3fv(program.uniform("u_color"), 1, &colors[3 * i]);
        const bool glowing = static_cast<std::size_t>(i) < colored->glowing.size() && colored->glowing[i] != 0;
        glUniform1f(program.uniform("u_highlight"),
                    i == colored->highlighted ? 1.0f : glowing ? kGlowingHighlight : 0.0f);
      }
      glDrawArrays(GL_TRIANGLES, ranges[i].first, ranges[i].second);
    }
  }
};

Renderer::Renderer(bool gles) : impl_(std::make_unique<Impl>(gles)) {}
Renderer::~Renderer() = default;

const SceneMesh& Renderer::scene() const { return impl_->scene; }
const Room& Renderer::room() const { return impl_->room; }

void Renderer::set_model(const Model& model) {
  Impl& m = *impl_;
  static int generations = 0;  // every model uploaded by any renderer gets its own number
  m.model_generation = ++generations;
  m.scene = build_scene_mesh(model);
  m.room = room_for(m.scene);
  std::vector<float> all;
  m.ranges.clear();
  m.colors.clear();
  m.body_bounds.assign(model.count, Bounds{});
  for (int i = 0; i < model.count; ++i)
    for (const Vec3& v : m.scene.components[i].triangles.vertices) m.body_bounds[i].add(v);
  for (int i = 0; i < model.count; ++i) {
    const ComponentMesh& c = m.scene.components[i];
    m.ranges.emplace_back(static_cast<int>(all.size() / 6), c.vertex_count());
    all.insert(all.end(), c.vertices.begin(), c.vertices.end());
    for (float c : {model.color[i].r, model.color[i].g, model.color[i].b}) m.colors.push_back(srgb_to_linear(c));
  }
  Impl::upload(m.mobile_vao, m.mobile_vbo, all);

  // The room: a floor and a back wall, wide enough to fill the view from any orbit in front of the wall.
  const Room& r = m.room;
  const double x0 = m.scene.hook.x() - 12, x1 = m.scene.hook.x() + 12;
  const double z1 = r.wall_z + 24, y1 = r.floor_y + 12;
  std::vector<float> room;
  add_quad(room, Vec3(x0, r.floor_y, z1), Vec3(x1, r.floor_y, z1), Vec3(x1, r.floor_y, r.wall_z),
           Vec3(x0, r.floor_y, r.wall_z), Vec3::UnitY());
  add_quad(room, Vec3(x0, r.floor_y, r.wall_z), Vec3(x1, r.floor_y, r.wall_z), Vec3(x1, y1, r.wall_z),
           Vec3(x0, y1, r.wall_z), Vec3::UnitZ());
  m.room_vertices = static_cast<int>(room.size() / 6);
  Impl::upload(m.room_vao, m.room_vbo, room);
  check_gl("uploading the model");
}

void Renderer::draw(const State& state, const OrbitCamera& camera, int width, int height, const DrawOptions& options,
                    const std::vector<LineSet>& lines) {
  Impl& m = *impl_;
  if (width <= 0 || height <= 0) return;
  FrameTarget* target = FrameTarget::bound();
  if (target && (target->width() != width || target->height() != height)) target = nullptr;
  if (target && options.reuse_background) {
    draw(state, camera, *target, options, lines);
    return;
  }
  // Everything shaded anew, into the bound framebuffer (a FrameTarget's multisampled one when it has it).
  if (target && target->samples_ > 0) {
    glBindFramebuffer(GL_FRAMEBUFFER, target->msaa_fbo_);
    const GLenum first[] = {GL_COLOR_ATTACHMENT0, GL_NONE};
    glDrawBuffers(2, first);
    target->pending_resolve_ = {{0, 0, width, height}};
  }
  const Mat4f light_vp = m.light_view_proj();
  m.render_shadow_map(state, options, light_vp);
  glViewport(0, 0, width, height);
  glClearColor(kBackground[0], kBackground[1], kBackground[2], 1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  const Mat4f view_proj = camera.projection(static_cast<double>(width) / height) * camera.view();
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, options.shadows ? m.shadow_texture : 0);
  const int shadowed = options.shadows ? 1 : 0;

  // The mobile first: it hides part of the room, so fewer room pixels get shaded.
  if (options.mobile) m.draw_lit_mobile(*m.lit[0][shadowed], state, camera, view_proj, light_vp, options);

  if (options.room) {
    // Shadow lookups are the costliest part of a frame on a software rasteriser, so only the rectangle
    // where the mobile's shadow falls is drawn with them; the rest of the room after it, without (the
    // depth test then skips what the first pass drew).
    glEnable(GL_CULL_FACE);  // from behind the wall or below the floor, see through them
    glCullFace(GL_BACK);
    if (shadowed && options.mobile) {
      const std::array<int, 4> r = m.shadow_rectangle(state, view_proj, width, height);
      if (r[2] > 0 && r[3] > 0) {
        glEnable(GL_SCISSOR_TEST);
        glScissor(r[0], r[1], r[2], r[3]);
        m.setup(*m.lit[1][1], camera, view_proj, light_vp);
        m.draw_room(*m.lit[1][1]);
        glDisable(GL_SCISSOR_TEST);
      }
    }
    m.setup(*m.lit[1][0], camera, view_proj, light_vp);
    m.draw_room(*m.lit[1][0]);
    glDisable(GL_CULL_FACE);
  }
  m.draw_lines(lines, view_proj);
  glBindVertexArray(0);
  glBindTexture(GL_TEXTURE_2D, 0);
}

void Renderer::draw(const State& state, const OrbitCamera& camera, FrameTarget& target, const DrawOptions& options,
                    const std::vector<LineSet>& lines) {
  Impl& m = *impl_;
  const int width = target.width(), height = target.height();
  if (width <= 0 || height <= 0 || !target.frame_fbo_) return;
  const Mat4f light_vp = m.light_view_proj();
  m.render_shadow_map(state, options, light_vp);
  const Mat4f view_proj = camera.projection(static_cast<double>(width) / height) * camera.view();
  glClearColor(kBackground[0], kBackground[1], kBackground[2], 1);

  // 1. The background: the room lit and unlit, shaded again only when what it shows changed. While the
  //    camera keeps moving (redrawn on the last frame too) it is drawn without anti-aliasing, and again
  //    with it on the first frame the camera rests.
  std::vector<float> key(view_proj.data(), view_proj.data() + 16);
  const Vec3 eye = camera.eye();
  key.insert(key.end(), {static_cast<float>(eye.x()), static_cast<float>(eye.y()), static_cast<float>(eye.z()),
                         static_cast<float>(m.model_generation), options.room ? 1.0f : 0.0f});
  const bool changed = key != target.background_key_;
  int background_samples = -1;  // -1: keep the cached one
  if (changed) background_samples = target.background_redrawn_ ? 0 : target.samples_;
  else if (target.background_samples_ < target.samples_) background_samples = target.samples_;
  if (background_samples >= 0) {
    m.render_background(target, background_samples, options.room, camera, view_proj, light_vp);
    target.background_key_ = std::move(key);
    target.background_samples_ = background_samples;
  }
  target.background_redrawn_ = background_samples >= 0;

  // 2. The picture starts as the lit background, with its depth.
  glBindFramebuffer(GL_READ_FRAMEBUFFER, target.background_fbo_);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target.frame_fbo_);
  glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, target.frame_fbo_);
  glViewport(0, 0, width, height);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, options.shadows ? m.shadow_texture : 0);

  // 3. The shadow: inside its rectangle the room is the lit and the unlit background blended by the
  //    light that gets through (the room is all there is yet, so no depth test).
  if (options.shadows && options.mobile && options.room) {
    const std::vector<Rect> rects = m.shadow_rectangles(state, view_proj, width, height);
    if (!rects.empty()) {
      glEnable(GL_SCISSOR_TEST);
      glDisable(GL_DEPTH_TEST);
      glEnable(GL_CULL_FACE);
      glCullFace(GL_BACK);
      GlProgram& program = *m.shadowed_room;
      m.setup(program, camera, view_proj, light_vp);
      glActiveTexture(GL_TEXTURE1);
      glBindTexture(GL_TEXTURE_2D, target.background_lit_);
      glActiveTexture(GL_TEXTURE2);
      glBindTexture(GL_TEXTURE_2D, target.background_unlit_);
      glUniform1i(program.uniform("u_lit"), 1);
      glUniform1i(program.uniform("u_unlit"), 2);
      for (const Rect& r : rects) {
        glScissor(r[0], r[1], r[2], r[3]);
        m.draw_room(program);
      }
      glDisable(GL_CULL_FACE);
      glDisable(GL_SCISSOR_TEST);
    }
  }

  // 4. The mobile and the lines. With anti-aliasing, only their screen rectangle goes through the
  //    multisampled buffer: the picture so far is copied into it under the room's geometry (colour and
  //    the room's depth), the mobile and lines drawn over it; resolve() brings the rectangle back.
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  std::vector<Rect> regions;
  if (options.mobile) regions = m.mobile_rectangles(state, view_proj, width, height);
  regions.push_back(lines_rectangle(lines, view_proj, width, height));
  merge(regions);
  const bool antialias = target.samples_ > 0 && !regions.empty();
  if (antialias) {
    glBindFramebuffer(GL_FRAMEBUFFER, target.msaa_fbo_);
    const GLenum first[] = {GL_COLOR_ATTACHMENT0, GL_NONE};
    glDrawBuffers(2, first);
    glEnable(GL_SCISSOR_TEST);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    GlProgram& program = *m.copy;
    m.setup(program, camera, view_proj, light_vp);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, target.frame_color_);
    glUniform1i(program.uniform("u_frame"), 1);
    for (const Rect& r : regions) {
      glScissor(r[0], r[1], r[2], r[3]);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      if (options.room) m.draw_room(program);
    }
    glDisable(GL_CULL_FACE);
    glDisable(GL_SCISSOR_TEST);  // the mobile and lines lie inside the rectangles
  }
  glActiveTexture(GL_TEXTURE0);
  if (options.mobile)
    m.draw_lit_mobile(*m.lit[0][options.shadows ? 1 : 0], state, camera, view_proj, light_vp, options);
  m.draw_lines(lines, view_proj);
  if (antialias) target.pending_resolve_ = std::move(regions);
  for (GLenum unit : {GL_TEXTURE2, GL_TEXTURE1, GL_TEXTURE0}) {
    glActiveTexture(unit);
    glBindTexture(GL_TEXTURE_2D, 0);
  }
  glBindVertexArray(0);
}

}  // namespace aloft::render
