#pragma once
// The mutable simulation state: positions and velocities of every component. Kept apart from the
// immutable Model; index 0 (the fixed component) never moves.

#include <vector>

#include "aloft/model.hpp"

namespace aloft {

struct State {
  double time = 0;                 // s since release
  std::vector<Vec3> position;      // centre of mass, world, m
  std::vector<Quat> orientation;   // body frame -> world, unit
  std::vector<Vec3> velocity;      // of the centre of mass, world, m/s
  std::vector<Vec3> angular;       // angular velocity, world, rad/s
};

// The designed pose, at rest.
State rest_state(const Model& model);

// Energy (J) of a state: kinetic + gravitational potential (zero at the world origin).
double kinetic_energy(const Model& model, const State& state);
double potential_energy(const Model& model, const State& state);

// Angular momentum (kg m^2/s) of the moving components about the world point `about`.
Vec3 angular_momentum(const Model& model, const State& state, const Vec3& about);

// World position of joint i as seen from the child (i) and from its parent; equal when joined.
Vec3 joint_on_child(const Model& model, const State& state, int i);
Vec3 joint_on_parent(const Model& model, const State& state, int i);

// Largest distance (m) between the two sides of any joint.
double max_joint_separation(const Model& model, const State& state);

}  // namespace aloft
