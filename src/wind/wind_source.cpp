// Wind sources and settings: construction, validation, a default source facing the mobile.

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "aloft/geometry.hpp"
#include "aloft/wind.hpp"

namespace aloft {

namespace {

void require_positive(double value, const char* name, const char* unit) {
  if (!(std::isfinite(value) && value > 0))
    throw std::invalid_argument(std::string(name) + " must be a positive number (" + unit + "), got " +
                                std::to_string(value));
}

}  // namespace

WindSource WindSource::aimed(const Vec3& from, const Vec3& to, double r0, double l0) {
  const Vec3 axis = to - from;
  if (!(axis.norm() > 0) || !axis.allFinite())
    throw std::invalid_argument("the wind's source and target must be two different points");
  WindSource s;
  s.direction = axis.normalized();
  s.r0 = r0;
  s.l0 = l0;
  s.vertex = from - l0 * s.direction;
  s.validate();
  return s;
}

double WindSource::half_angle() const { return std::atan2(r0, l0); }

void WindSource::validate() const {
  require_positive(r0, "the wind's r0 (radius of S0)", "m");
  require_positive(l0, "the wind's l0 (distance from the cone's vertex to S0)", "m");
  if (!vertex.allFinite()) throw std::invalid_argument("the wind's vertex must be finite");
  if (!direction.allFinite() || std::abs(direction.norm() - 1) > 1e-6)
    throw std::invalid_argument("the wind's direction must be a unit vector");
}

void WindSettings::validate() const {
  if (!std::isfinite(alpha)) throw std::invalid_argument("the wind's alpha must be a number (kg m)");
  if (!(std::isfinite(beta) && beta >= 0 && beta <= 10))
    throw std::invalid_argument("the wind's beta (turbulence) must be in [0, 10], got " + std::to_string(beta));
  if (!(std::isfinite(correlation_time) && correlation_time >= 0))
    throw std::invalid_argument("the turbulence correlation time must be >= 0 s");
  if (resolution < 8 || resolution > 8192)
    throw std::invalid_argument("the wind's item buffer resolution must be in [8, 8192] pixels, got " +
                                std::to_string(resolution));
  if (tile_pixels < 1 || tile_pixels > resolution)
    throw std::invalid_argument("the wind's tile size must be in [1, resolution] pixels, got " +
                                std::to_string(tile_pixels));
  if (round_segments < 3 || round_segments > 256)
    throw std::invalid_argument("the wind's round_segments must be in [3, 256], got " +
                                std::to_string(round_segments));
}

int occlusion_refresh_steps(double rate, double h) {
  // Clamped as a double: the cast of a count beyond int (1e-300 Hz) is undefined, and gave 1, every step.
  const double steps = std::round(1.0 / (rate * h));
  return static_cast<int>(std::clamp(steps, 1.0, static_cast<double>(std::numeric_limits<int>::max())));
}

MobileSphere mobile_sphere(const Model& model, const State& state) {
  Bounds world;  // of the corners of every shape's body-frame box, carried to the world
  for (int c = 0; c < model.count; ++c) {
    const Mat3 rotation = state.orientation[c].toRotationMatrix();
    for (const BodyShape& shape : model.shapes[c]) {
      const Bounds b = shape_bounds(shape.shape);
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3 p((corner & 1) ? b.max.x() : b.min.x(), (corner & 2) ? b.max.y() : b.min.y(),
                     (corner & 4) ? b.max.z() : b.min.z());
        world.add(state.position[c] + rotation * p);
      }
    }
  }
  return {0.5 * (world.min + world.max), 0.5 * (world.max - world.min).norm()};
}

WindSource source_covering(const Vec3& from, const Vec3& to, double l0, const MobileSphere& cover) {
  require_positive(l0, "the wind's l0", "m");
  const double reach = (cover.center - from).norm() + l0;  // m, from the vertex when `to` is the centre
  const double sine = std::min(0.95, cover.radius / reach);  // of the half angle; 0.95: 72 degrees
  return WindSource::aimed(from, to, l0 * sine / std::sqrt(1 - sine * sine), l0);
}

WindSource source_facing_mobile(const Model& model, const State& state, const Vec3& along, double distance,
                                double l0) {
  require_positive(distance, "the wind source's distance", "m");
  if (!(along.norm() > 0)) throw std::invalid_argument("the wind's direction must not be zero");
  const MobileSphere cover = mobile_sphere(model, state);
  return source_covering(cover.center - distance * along.normalized(), cover.center, l0, cover);
}

WindSource file_source_cone(const WindSourceSpec& source) {
  return WindSource::aimed(source.from, source.to, source.r0, source.l0);
}

WindSettings file_source_settings(const WindSourceSpec& source, std::size_t index, WindSettings run) {
  if (source.alpha) run.alpha = *source.alpha;
  if (source.beta) run.beta = *source.beta;
  run.seed = source.seed ? *source.seed : run.seed + 1 + index;
  return run;
}

WindSource source_in_front(const Model& model, const State& state, double l0) {
  return source_facing_mobile(model, state, Vec3(0, 0, -1), kFrontSourceDistance, l0);
}

}  // namespace aloft
