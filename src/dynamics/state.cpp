#include "aloft/state.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "common/splitmix64.hpp"

namespace aloft {

State rest_state(const Model& model) {
  State s;
  s.time = 0;
  s.position = model.rest_position;
  s.orientation = model.rest_orientation;
  s.velocity.assign(model.count, Vec3::Zero());
  s.angular.assign(model.count, Vec3::Zero());
  return s;
}

State swinging_state(const Model& model, double max_rate, std::uint64_t seed) {
  std::uint64_t s = seed * 0x9E3779B97F4A7C15ull + 1;
  auto unit = [&s] { return splitmix64_unit(s); };
  State state = rest_state(model);
  for (int i = 1; i < model.count; ++i) {
    const double z = 2 * unit() - 1;
    const double phi = 2 * std::numbers::pi * unit();
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    const Vec3 axis(r * std::cos(phi), r * std::sin(phi), z);
    state.angular[i] = max_rate * (0.5 + 0.5 * unit()) * axis;
  }
  set_velocities_keeping_joints(model, state);
  return state;
}

void place_on_joints(const Model& model, State& state) {
  for (int i = 1; i < model.count; ++i)  // parents come before their children
    state.position[i] = joint_on_parent(model, state, i) - state.orientation[i] * model.joint_in_child[i];
}

void set_velocities_keeping_joints(const Model& model, State& state) {
  for (int i = 1; i < model.count; ++i) {  // parents come before their children
    const int p = model.parent[i];
    const Vec3 joint = joint_on_child(model, state, i);
    state.velocity[i] = state.velocity[p] + state.angular[p].cross(joint - state.position[p]) +
                        state.angular[i].cross(state.position[i] - joint);
  }
}

double kinetic_energy(const Model& model, const State& state) {
  double e = 0;
  for (int i = 1; i < model.count; ++i) {
    const Vec3 wb = state.orientation[i].conjugate() * state.angular[i];  // body frame
    e += 0.5 * model.mass[i] * state.velocity[i].squaredNorm() +
         0.5 * wb.dot(model.principal_moments[i].cwiseProduct(wb));
  }
  return e;
}

double potential_energy(const Model& model, const State& state) {
  double e = 0;
  for (int i = 1; i < model.count; ++i) e -= model.mass[i] * model.gravity.dot(state.position[i]);
  return e;
}

Vec3 angular_momentum(const Model& model, const State& state, const Vec3& about) {
  Vec3 l = Vec3::Zero();
  for (int i = 1; i < model.count; ++i) {
    const Quat& q = state.orientation[i];
    const Vec3 wb = q.conjugate() * state.angular[i];
    const Vec3 spin = q * model.principal_moments[i].cwiseProduct(wb);
    l += spin + (state.position[i] - about).cross(model.mass[i] * state.velocity[i]);
  }
  return l;
}

Vec3 joint_on_child(const Model& model, const State& state, int i) {
  return state.position[i] + state.orientation[i] * model.joint_in_child[i];
}

Vec3 joint_on_parent(const Model& model, const State& state, int i) {
  const int p = model.parent[i];
  return state.position[p] + state.orientation[p] * model.joint_in_parent[i];
}

double max_joint_separation(const Model& model, const State& state) {
  double worst = 0;
  for (int i = 1; i < model.count; ++i)
    worst = std::max(worst, (joint_on_child(model, state, i) - joint_on_parent(model, state, i)).norm());
  return worst;
}

}  // namespace aloft
