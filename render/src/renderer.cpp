#include "aloft/render/renderer.hpp"

#include <algorithm>
#include <cmath>

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
  camera.yaw = 0.28;
  camera.pitch = 0.12;
  const double t = std::tan(camera.fov_y / 2);
  camera.distance = 1.05 * std::max(half_height / t, half_width / (t * std::max(aspect, 0.2))) + 0.5 * scene.reach;
  return camera;
}

struct Renderer::Impl {
  bool gles;
  std::unique_ptr<GlProgram> lit[2][2];   // [room][shadows]: compiled variants of the lit shader
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

  explicit Impl(bool gles_)
      : gles(gles_),
        depth(shaders::glsl_source(shaders::kDepthVertex, gles_),
              shaders::glsl_source(shaders::kDepthFragment, gles_), "shadow"),
        line(shaders::glsl_source(shaders::kLineVertex, gles_), shaders::glsl_source(shaders::kLineFragment, gles_),
             "line") {
    for (int room = 0; room < 2; ++room)
      for (int shadows = 0; shadows < 2; ++shadows) {
        const std::string defines = std::string(room ? "#define ROOM\n" : "") + (shadows ? "#define SHADOWS\n" : "");
        lit[room][shadows] = std::make_unique<GlProgram>(shaders::glsl_source(shaders::kLitVertex, gles_, defines),
                                                         shaders::glsl_source(shaders::kLitFragment, gles_, defines),
                                                         "lit");
      }
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

  Mat4f light_view_proj() const {
    const double dist = (room.light_position - room.light_target).norm();
    const double half_angle = std::asin(std::min(0.95, room.light_radius / dist)) * 1.1;
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

  void draw_mobile(GlProgram& program, const State& state, bool with_color, int highlighted) {
    glBindVertexArray(mobile_vao);
    const int n = std::min<int>(static_cast<int>(ranges.size()), static_cast<int>(state.position.size()));
    for (int i = 0; i < n; ++i) {
      if (ranges[i].second == 0) continue;
      set_mat4(program.uniform("u_model"), rigid_transform(state.position[i], state.orientation[i]));
      if (with_color) {
        glUniform3fv(program.uniform("u_color"), 1, &colors[3 * i]);
        glUniform1f(program.uniform("u_highlight"), i == highlighted ? 1.0f : 0.0f);
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
  GLint target_fbo = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &target_fbo);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);

  // 1. Shadow map: depth of the mobile as the key light sees it.
  const Mat4f light_vp = m.light_view_proj();
  if (options.shadows) {
    // (Without the mobile the map stays clear: nothing casts.)
    m.ensure_shadow_map(options.shadow_map_size);
    glBindFramebuffer(GL_FRAMEBUFFER, m.shadow_fbo);
    glViewport(0, 0, m.shadow_size, m.shadow_size);
    glClear(GL_DEPTH_BUFFER_BIT);
    glDisable(GL_CULL_FACE);  // thin plates: both faces cast
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(2.0f, 4.0f);  // against self-shadowing acne on lit faces
    m.depth.use();
    set_mat4(m.depth.uniform("u_light_view_proj"), light_vp);
    if (options.mobile) m.draw_mobile(m.depth, state, false, -1);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(target_fbo));
  }

  // 2. The scene from the camera.
  glViewport(0, 0, width, height);
  glClearColor(kBackground[0], kBackground[1], kBackground[2], 1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  const Mat4f view_proj = camera.projection(static_cast<double>(width) / height) * camera.view();
  const auto setup = [&](GlProgram& program) {
    program.use();
    set_mat4(program.uniform("u_view_proj"), view_proj);
    set_mat4(program.uniform("u_light_view_proj"), light_vp);
    set_vec3(program.uniform("u_eye"), camera.eye());
    set_vec3(program.uniform("u_light_pos"), m.room.light_position);
    set_vec3(program.uniform("u_light_dir"), (m.room.light_target - m.room.light_position).normalized());
    glUniform1f(program.uniform("u_shadow_radius"), kShadowRadius);
    glUniform2f(program.uniform("u_corner"), static_cast<float>(m.room.floor_y), static_cast<float>(m.room.wall_z));
    glUniform1i(program.uniform("u_shadow_map"), 0);
  };
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, options.shadows ? m.shadow_texture : 0);
  const int shadowed = options.shadows ? 1 : 0;

  // The mobile first: it hides part of the room, so fewer room pixels get shaded.
  if (options.mobile) {
    GlProgram& mobile = *m.lit[0][shadowed];
    setup(mobile);
    glDisable(GL_CULL_FACE);
    glUniform2f(mobile.uniform("u_material"), kMobileSpecular, kMobileShininess);
    m.draw_mobile(mobile, state, true, options.highlighted);
  }

  if (options.room) {
    // Shadow lookups are the costliest part of a frame on a software rasteriser, so only the rectangle
    // where the mobile's shadow falls is drawn with them; the rest of the room after it, without (the
    // depth test then skips what the first pass drew).
    const auto draw_room = [&](GlProgram& room) {
      setup(room);
      glBindVertexArray(m.room_vao);
      set_mat4(room.uniform("u_model"), Mat4f::Identity());
      glUniform2f(room.uniform("u_material"), kRoomSpecular, kRoomShininess);
      set_color(room.uniform("u_color"), kFloorColor);
      glDrawArrays(GL_TRIANGLES, 0, 6);
      set_color(room.uniform("u_color"), kWallColor);
      glDrawArrays(GL_TRIANGLES, 6, 6);
    };
    glEnable(GL_CULL_FACE);  // from behind the wall or below the floor, see through them
    glCullFace(GL_BACK);
    if (shadowed && options.mobile) {
      const std::array<int, 4> r = m.shadow_rectangle(state, view_proj, width, height);
      if (r[2] > 0 && r[3] > 0) {
        glEnable(GL_SCISSOR_TEST);
        glScissor(r[0], r[1], r[2], r[3]);
        draw_room(*m.lit[1][1]);
        glDisable(GL_SCISSOR_TEST);
      }
    }
    draw_room(*m.lit[1][0]);
    glDisable(GL_CULL_FACE);
  }

  // 3. Overlay lines.
  if (!lines.empty()) {
    m.line.use();
    set_mat4(m.line.uniform("u_view_proj"), view_proj);
    glBindVertexArray(m.line_vao);
    glBindBuffer(GL_ARRAY_BUFFER, m.line_vbo);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    for (const LineSet& set : lines) {
      if (set.points.size() < 2) continue;
      std::vector<float> data;
      data.reserve(set.points.size() * 3);
      for (const Vec3& p : set.points)
        data.insert(data.end(), {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data.size() * sizeof(float)), data.data(), GL_STREAM_DRAW);
      glUniform4fv(m.line.uniform("u_color"), 1, set.color.data());
      glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(set.points.size() / 2 * 2));
    }
    glDisable(GL_BLEND);
  }
  glBindVertexArray(0);
  glBindTexture(GL_TEXTURE_2D, 0);
}

}  // namespace aloft::render
