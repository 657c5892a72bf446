#pragma once
// The mutable simulation state: positions and velocities of every component. Kept apart from the
// immutable Model; index 0 (the fixed component) never moves.

#include <cstdint>
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

// The designed pose set swinging: every moving component turning at a random angular velocity (world,
// uniform direction, magnitude uniform in [max_rate / 2, max_rate] rad/s), with centre-of-mass
// velocities that keep every joint together, v_i = v_p + w_p x (j_i - x_p) + w_i x (x_i - j_i). The
// benchmarks' start (BM_StepSpan, aloft_step_profile, `aloft bench --start swinging:SEED`). The same
// seed gives the same state on every machine: a fixed 64-bit generator (splitmix64), no <random>
// distributions.
State swinging_state(const Model& model, double max_rate = 0.5, std::uint64_t seed = 7);

// Puts every moving component where its joint holds at its orientation, from the hook down:
// x_i = (joint i's point on the parent) - R_i c_i (c_i: the joint in the child's body frame, m).
// Orientations are left as they are; afterwards max_joint_separation is round-off.
void place_on_joints(const Model& model, State& state);

// Sets every moving component's centre-of-mass velocity (world, m/s) so that its joint's point moves
// alike on both sides, from its angular velocity and the parent's motion, from the hook down:
// v_i = v_p + w_p x (j_i - x_p) + w_i x (x_i - j_i), j_i the joint's world point. Angular velocities
// and positions are left as they are.
void set_velocities_keeping_joints(const Model& model, State& state);

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
