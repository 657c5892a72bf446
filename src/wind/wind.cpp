// The virtual wind: body-frame meshes, the occlusion pass (item buffer -> area elements), and the forces of
// eqs. 4-5 applied every step. See include/aloft/wind.hpp and docs/wind.md.

#include "aloft/wind.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "aloft/geometry.hpp"
#include "common/splitmix64.hpp"
#include "wind/item_rasterizer.hpp"

namespace aloft {

namespace {

// Two unit normals (and plane offsets, m) closer than this are the same plane: coplanar triangles of a
// plate's face are computed from the same polygon, so they agree to rounding (1e-9 is far above it and
// far below any real bend).
constexpr double kSamePlane = 1e-9;

// The source's frame: right, up, direction as columns. Up is the world y axis made orthogonal to the
// direction (the world x axis when the wind blows almost vertically). Left-handed, like a camera
// looking along the wind: right = direction x up_hint.
Mat3 source_frame(const Vec3& direction) {
  const Vec3 up_hint = std::abs(direction.y()) < 0.99 ? Vec3::UnitY() : Vec3::UnitX();
  const Vec3 right = direction.cross(up_hint).normalized();
  const Vec3 up = right.cross(direction);
  Mat3 f;
  f.col(0) = right;
  f.col(1) = up;
  f.col(2) = direction;
  return f;
}

// Uniform in (0, 1].
double next_uniform(std::uint64_t& state) { return (static_cast<double>(splitmix64(state) >> 11) + 1) * 0x1p-53; }

// Standard normal by Box-Muller (the cosine branch; portable, unlike std::normal_distribution).
double next_normal(std::uint64_t& state) {
  const double r = std::sqrt(-2 * std::log(next_uniform(state)));
  return r * std::cos(2 * std::numbers::pi * next_uniform(state));
}

}  // namespace

Wind::Wind(const Model& model, const WindSource& source, const WindSettings& settings) : model_(model) {
  source.validate();
  settings.validate();
  source_ = source;
  settings_ = settings;
  frame_ = source_frame(source_.direction);
  // Body-frame meshes of every component (shapes are stored in body frames already), planes grouped.
  meshes_.resize(model.count);
  std::vector<Vec3> plane_normals;   // of the current component
  std::vector<double> plane_offsets;
  std::vector<char> plane_is_round;  // made by a round shape's facets
  int plane_base = 0;
  for (int c = 0; c < model.count; ++c) {
    ComponentMesh& m = meshes_[c];
    plane_normals.clear();
    plane_offsets.clear();
    plane_is_round.clear();
    for (const BodyShape& shape : model.shapes[c]) {
      const TriangleMesh mesh = shape_mesh(shape.shape, settings_.round_segments);
      const RoundSurface round = RoundSurface::of(shape.shape);
      const bool is_round = round.kind != RoundSurface::Kind::kFlat;
      // A round shape's facets get planes of their own: an element's point is moved by the surface of
      // one triangle of its plane (refresh_occlusion), which must then stand for all its pixels.
      const std::size_t first_own_plane = is_round ? plane_normals.size() : 0;
      const int base = static_cast<int>(m.vertices.size());
      m.vertices.insert(m.vertices.end(), mesh.vertices.begin(), mesh.vertices.end());
      for (const auto& t : mesh.triangles) {
        const Vec3& a = mesh.vertices[t[0]];
        const Vec3 cross = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
        if (!(cross.norm() > 0)) continue;  // degenerate: no area, no wind
        const Vec3 n = cross.normalized();
        const double offset = n.dot(a);
        int plane = -1;
        for (std::size_t p = first_own_plane; p < plane_normals.size() && plane < 0; ++p)
          if (plane_is_round[p] == is_round && (plane_normals[p] - n).norm() < kSamePlane &&
              std::abs(plane_offsets[p] - offset) < kSamePlane)
            plane = static_cast<int>(p);
        if (plane < 0) {
          plane = static_cast<int>(plane_normals.size());
          plane_normals.push_back(n);
          plane_offsets.push_back(offset);
          plane_is_round.push_back(is_round);
        }
        m.triangles.push_back({base + t[0], base + t[1], base + t[2]});
        m.plane_of_triangle.push_back(plane);
        triangle_normal_body_.push_back(n);
        triangle_point_body_.push_back(a);
        triangle_component_.push_back(c);
        triangle_plane_.push_back(plane_base + plane);
        triangle_round_.push_back(round);
      }
    }
    plane_base += static_cast<int>(plane_normals.size());
  }
  plane_count_ = plane_base;
  buffer_.component_of_id.assign(triangle_component_.size() + 1, -1);
  for (std::size_t t = 0; t < triangle_component_.size(); ++t) buffer_.component_of_id[t + 1] = triangle_component_[t];
  rasterizer_ = std::make_unique<internal::ItemRasterizer>();
  last_.stoke_force.assign(model.count, Vec3::Zero());
  last_.random_force.assign(model.count, Vec3::Zero());
  last_.torque.assign(model.count, Vec3::Zero());
  rotation_.assign(model.count, Mat3::Identity());
  pressure_center_.assign(model.count, Vec3::Zero());
  pressure_weight_.assign(model.count, 0.0);
  reset_turbulence();
}

Wind::~Wind() = default;

Wind::RoundSurface Wind::RoundSurface::of(const Shape& shape) {
  RoundSurface round;
  if (const auto* wire = std::get_if<Wire>(&shape)) {
    round.kind = Kind::kAxis;
    round.point = wire->from;
    round.direction = (wire->to - wire->from).normalized();
  } else if (const auto* sphere = std::get_if<Sphere>(&shape)) {
    round.kind = Kind::kCentre;
    round.point = sphere->center;
  }
  return round;
}

Vec3 Wind::RoundSurface::through_axis(const Vec3& point_body, const Vec3& normal) const {
  const Vec3 offset = point_body - point;
  switch (kind) {
    case Kind::kFlat:
      return point_body;
    case Kind::kCentre:  // on the normal through the centre, as far out as the point
      return point + offset.dot(normal) * normal;
    case Kind::kAxis:
      // A wire's end (its normal along the axis; the sides' normals are square to it) is flat.
      if (std::abs(normal.dot(direction)) > 0.5) return point_body;
      // In the plane of the axis and the normal: the offset across the facet is dropped.
      return point + offset.dot(direction) * direction + offset.dot(normal) * normal;
  }
  return point_body;
}

void Wind::set_source(const WindSource& source) {
  source.validate();
  source_ = source;
  frame_ = source_frame(source_.direction);
}

void Wind::set_settings(const WindSettings& settings) {
  settings.validate();
  if (settings.round_segments != settings_.round_segments)
    throw std::invalid_argument("the wind's round_segments is fixed when the Wind is built");
  const bool reseed = settings.seed != settings_.seed;
  settings_ = settings;
  if (reseed) reset_turbulence();
}

double Wind::alpha() const { return settings_.alpha >= 0 ? settings_.alpha : kAirDensity * std::pow(source_.l0, 4); }

std::vector<double> Wind::visible_area() const {
  std::vector<double> area(model_.count, 0.0);
  for (const WindElement& e : elements_) area[e.component] += e.area;
  return area;
}

void Wind::reset_turbulence() {
  rng_state_ = settings_.seed;
  gust_.assign(model_.count, Vec3::Zero());
  // Start from the stationary distribution (unit variance per axis), so there is no warm-up.
  for (Vec3& g : gust_) g = Vec3(next_normal(rng_state_), next_normal(rng_state_), next_normal(rng_state_));
}

// Ornstein-Uhlenbeck, exact in distribution for any dt: g <- a g + sqrt(1 - a^2) xi, a = exp(-dt / tau).
void Wind::step_turbulence(double dt) {
  const double tau = settings_.correlation_time;
  const double a = tau > 0 ? std::exp(-dt / tau) : 0.0;
  const double b = std::sqrt(std::max(0.0, 1 - a * a));
  for (Vec3& g : gust_)
    for (int k = 0; k < 3; ++k) g[k] = a * g[k] + b * next_normal(rng_state_);
}

void Wind::refresh_occlusion(const State& state) {
  const int width = settings_.resolution;
  const double l0 = source_.l0, r0 = source_.r0;
  internal::ItemRasterizer& raster = *rasterizer_;
  raster.reset(width, r0, l0);

  // 1. Draw every front-facing triangle of every moving component, in camera coordinates.
  const Mat3 to_camera = frame_.transpose();
  std::uint32_t id = 1;
  for (int c = 0; c < model_.count; ++c) {
    const ComponentMesh& m = meshes_[c];
    // The fixed hook (c == 0) feels no wind but still hides what is behind it: drawn too.
    const Mat3 rotation = state.orientation[c].toRotationMatrix();
    const Mat3 body_to_camera = to_camera * rotation;
    const Vec3 origin = to_camera * (state.position[c] - source_.vertex);
    camera_vertices_.resize(m.vertices.size());
    for (std::size_t v = 0; v < m.vertices.size(); ++v) camera_vertices_[v] = origin + body_to_camera * m.vertices[v];
    for (std::size_t t = 0; t < m.triangles.size(); ++t, ++id) {
      const auto& tri = m.triangles[t];
      const Vec3& a = camera_vertices_[tri[0]];
      // Front face: its outward normal points back at the vertex (the camera frame's origin).
      const Vec3 n = body_to_camera * triangle_normal_body_[id - 1];
      if (n.dot(a) >= 0) continue;
      raster.draw(a, camera_vertices_[tri[1]], camera_vertices_[tri[2]], id);
    }
  }

  // 2. Every covered pixel is a sample: the ray q = (u, v, l0) (camera frame) meets the triangle's plane
  // n.p = d at p = (d / n.q) q, and the pixel's area s^2 on the plane z = l0 maps to
  // A = s^2 l0 d^2 / |n.q|^3 on the face (solid angle s^2 l0 / |q|^3 times l1^2 / cos).
  // Pixels are merged per (tile, plane): summed area, area-weighted centroid.
  elements_.clear();
  const double s2 = raster.pixel_size() * raster.pixel_size();
  const int tile = settings_.tile_pixels;
  const std::vector<std::uint32_t>& ids = raster.ids();
  std::vector<TileAccumulator>& local = tile_scratch_;
  // Per-triangle camera-frame plane (n, d), computed when first seen in this refresh.
  plane_seen_.assign(triangle_component_.size() + 1, 0);
  plane_n_.resize(triangle_component_.size() + 1);
  plane_d_.resize(triangle_component_.size() + 1);
  for (int ty = 0; ty < width; ty += tile) {
    for (int tx = 0; tx < width; tx += tile) {
      if (!raster.any_touched(tx, ty, std::min(width, tx + tile) - 1, std::min(width, ty + tile) - 1)) continue;
      local.clear();
      for (int y = ty; y < std::min(width, ty + tile); ++y) {
        const int x0 = std::max(tx, raster.row_first(y));
        const int x1 = std::min(std::min(width, tx + tile) - 1, raster.row_last(y));
        const double v = raster.v_of(y);
        for (int x = x0; x <= x1; ++x) {
          const std::uint32_t pid = ids[static_cast<std::size_t>(y) * width + x];
          if (pid == 0) continue;
          const int c = triangle_component_[pid - 1];
          if (c == 0) continue;  // the fixed component hides, but does not move
          if (!plane_seen_[pid]) {
            const Mat3 rotation = state.orientation[c].toRotationMatrix();
            const Vec3 n = to_camera * (rotation * triangle_normal_body_[pid - 1]);
            const Vec3 a = to_camera * (state.position[c] + rotation * triangle_point_body(pid - 1) - source_.vertex);
            plane_n_[pid] = n;
            plane_d_[pid] = n.dot(a);
            plane_seen_[pid] = 1;
          }
          const Vec3 q(raster.u_of(x), v, l0);
          const Vec3& n = plane_n_[pid];
          const double nq = n.dot(q);
          if (!(std::abs(nq) > 0)) continue;
          const double d = plane_d_[pid];
          const double area = s2 * l0 * d * d / std::abs(nq * nq * nq);
          const Vec3 p = (d / nq) * q;
          const int plane = triangle_plane_[pid - 1];
          TileAccumulator* acc = nullptr;
          for (TileAccumulator& e : local)
            if (e.plane == plane) {
              acc = &e;
              break;
            }
          if (!acc) {
            local.push_back({plane, c, pid, 0.0, Vec3::Zero()});
            acc = &local.back();
          }
          acc->area += area;
          acc->moment += area * p;
        }
      }
      for (const TileAccumulator& e : local) {
        WindElement el;
        el.component = e.component;
        el.area = e.area;
        el.point_world = source_.vertex + frame_ * (e.moment / e.area);
        el.normal_world = frame_ * plane_n_[e.id];
        const Mat3 rotation = state.orientation[e.component].toRotationMatrix();
        el.normal_body = triangle_normal_body_[e.id - 1];
        el.point_body = triangle_round_[e.id - 1].through_axis(
            rotation.transpose() * (el.point_world - state.position[e.component]), el.normal_body);
        el.point_world = state.position[e.component] + rotation * el.point_body;
        elements_.push_back(el);
      }
    }
  }
  buffer_.width = width;
  // Hand the ids over without copying; the rasterizer refills the old buffer at the next refresh.
  std::swap(buffer_.ids, raster.ids());
}

void Wind::apply(const State& state, double v0, double dt, ExternalLoads& loads) {
  const int count = model_.count;
  if (static_cast<int>(loads.force.size()) != count || static_cast<int>(loads.torque.size()) != count)
    throw std::invalid_argument("Wind::apply: the loads are not sized to the model");
  for (int c = 0; c < count; ++c) {
    rotation_[c] = state.orientation[c].toRotationMatrix();
    last_.stoke_force[c].setZero();
    last_.random_force[c].setZero();
    last_.torque[c].setZero();
    pressure_center_[c].setZero();
    pressure_weight_[c] = 0;
  }
  // Eq. 4 on every element still inside the cone and beyond S0 at the current pose:
  // F = alpha A v0^2 / l1^4 (n_v . n) n with n_v = r / l1, r from the vertex: alpha A v0^2 (r . n) / l1^5 n.
  const double k = alpha() * v0 * v0;
  const double l0 = source_.l0;
  const double tan2 = (source_.r0 / l0) * (source_.r0 / l0);
  const Vec3& axis = source_.direction;
  if (k > 0) {
    for (const WindElement& e : elements_) {
      const int c = e.component;
      const Vec3 arm = rotation_[c] * e.point_body;
      const Vec3 r = state.position[c] + arm - source_.vertex;
      const double along = r.dot(axis);
      const double l2 = r.squaredNorm();
      if (along < l0 || l2 - along * along > tan2 * along * along) continue;
      const Vec3 n = rotation_[c] * e.normal_body;
      const double l1 = std::sqrt(l2);
      const double rn = r.dot(n);
      const Vec3 force = (k * e.area * rn / (l2 * l2 * l1)) * n;
      last_.stoke_force[c] += force;
      last_.torque[c] += arm.cross(force);
      const double weight = force.norm();
      pressure_center_[c] += weight * arm;
      pressure_weight_[c] += weight;
    }
  }
  // Eq. 5: a random force |F_random| = beta |F_stoke| |g| / sqrt(1 + |g|^2) < beta |F_stoke|, along the
  // component's gust vector g, acting at its centre of pressure.
  if (settings_.beta > 0) {
    step_turbulence(dt);
    for (int c = 1; c < count; ++c) {
      const double stoke = last_.stoke_force[c].norm();
      if (!(stoke > 0)) continue;
      const Vec3& g = gust_[c];
      const Vec3 random = (settings_.beta * stoke / std::sqrt(1 + g.squaredNorm())) * g;
      last_.random_force[c] = random;
      last_.torque[c] += (pressure_center_[c] / pressure_weight_[c]).cross(random);
    }
  }
  for (int c = 1; c < count; ++c) {
    loads.force[c] += last_.stoke_force[c] + last_.random_force[c];
    loads.torque[c] += last_.torque[c];
  }
}

}  // namespace aloft
