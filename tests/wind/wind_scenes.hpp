#pragma once
// Small scenes for the wind tests: square plates as free components, and the exact integral of eq. 4 over
// a plate's face for comparison with the item-buffer result.

#include <cmath>

#include "aloft/model.hpp"
#include "aloft/state.hpp"
#include "aloft/wind.hpp"
#include "support/model_builder.hpp"

namespace aloft::test {

// A thin square plate: side `side` (m), centred at the body origin, spanned by the body's (u, v) axes.
inline Plate square_plate(double side, const Vec3& u, const Vec3& v, double thickness = 1e-5) {
  Plate p;
  const double h = side / 2;
  p.points = {Vec2(-h, -h), Vec2(h, -h), Vec2(h, h), Vec2(-h, h)};
  p.origin = Vec3::Zero();
  p.u_axis = u;
  p.v_axis = v;
  p.thickness = thickness;
  return p;
}

struct PlacedPlate {
  Vec3 center;
  double side = 0.1;
  Vec3 u = Vec3::UnitX();
  Vec3 v = Vec3::UnitY();
};

// Component 0 is a fixed component without shapes, far away; component i + 1 carries plates[i], its body
// frame parallel to the world at the plate's centre.
inline Model plates_model(const std::vector<PlacedPlate>& plates) {
  Model m = empty_model(static_cast<int>(plates.size()) + 1);
  m.rest_position[0] = Vec3(0, 100, 0);
  for (std::size_t i = 0; i < plates.size(); ++i) {
    const int c = static_cast<int>(i) + 1;
    m.parent[c] = 0;
    m.rest_position[c] = plates[i].center;
    m.joint_world[c] = plates[i].center;
    m.shapes[c].push_back(BodyShape{square_plate(plates[i].side, plates[i].u, plates[i].v), Color{}});
  }
  finish_model(m);
  return m;
}

// Eq. 4 integrated over the plate's face by the midpoint rule on n x n points (all visible, all inside the
// cone): F = sum alpha dA v0^2 / l1^4 (n_v . n) n, n_v from the vertex.
inline Vec3 exact_plate_force(const PlacedPlate& plate, const WindSource& source, double alpha, double v0,
                              int n = 400) {
  const Vec3 normal = plate.u.cross(plate.v);
  const double d = plate.side / n;
  Vec3 total = Vec3::Zero();
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Vec3 p = plate.center + (-plate.side / 2 + (i + 0.5) * d) * plate.u + (-plate.side / 2 + (j + 0.5) * d) * plate.v;
      const Vec3 r = p - source.vertex;
      const double l1 = r.norm();
      total += alpha * d * d * v0 * v0 / std::pow(l1, 4) * (r / l1).dot(normal) * normal;
    }
  return total;
}

// The wind's force on every component for a state: occlusion, then one apply() without turbulence.
inline std::vector<Vec3> wind_forces(const Model& model, const WindSource& source, WindSettings settings, double v0,
                                     const State& state) {
  settings.beta = 0;
  Wind wind(model, source, settings);
  wind.refresh_occlusion(state);
  ExternalLoads loads;
  loads.resize(model.count);
  loads.clear();
  wind.apply(state, v0, 0.001, loads);
  return loads.force;
}

// Vertex at the origin blowing along +z; S0 at z = l0 = 1 m, radius r0 = 0.05 m (half angle 2.9 deg): at
// z = 2 m the cone is 0.1 m in radius.
inline WindSource axis_source(double r0 = 0.05, double l0 = 1.0) {
  WindSource s;
  s.vertex = Vec3::Zero();
  s.direction = Vec3::UnitZ();
  s.r0 = r0;
  s.l0 = l0;
  return s;
}

}  // namespace aloft::test
