#pragma once
// Models built directly in code (no file, no balance), for tests of the dynamics alone.

#include <random>
#include <string>

#include "aloft/model.hpp"

namespace aloft::test {

// A model with `count` components, all fields sized; index 0 fixed at the origin.
inline Model empty_model(int count) {
  Model m;
  m.name = "test";
  m.count = count;
  m.parent.assign(count, -1);
  m.children.assign(count, {});
  m.names.resize(count);
  m.file_index.resize(count);
  for (int i = 0; i < count; ++i) {
    m.names[i] = "body" + std::to_string(i);
    m.file_index[i] = i;
  }
  m.mass.assign(count, 1.0);
  m.principal_moments.assign(count, Vec3::Ones());
  m.volume.assign(count, 1e-4);
  m.rest_position.assign(count, Vec3::Zero());
  m.rest_orientation.assign(count, Quat::Identity());
  m.joint_world.assign(count, Vec3::Zero());
  m.joint_in_child.assign(count, Vec3::Zero());
  m.joint_in_parent.assign(count, Vec3::Zero());
  m.shapes.assign(count, {});
  m.color.assign(count, Color{});
  m.restitution.assign(count, 0.3);
  m.friction.assign(count, 0.4);
  m.gravity = Vec3(0, -9.81, 0);
  return m;
}

// Fill children and the body-frame joint anchors from parent, rest pose and joint_world.
inline void finish_model(Model& m) {
  m.children.assign(m.count, {});
  for (int i = 1; i < m.count; ++i) {
    m.children[m.parent[i]].push_back(i);
    m.joint_in_child[i] = m.rest_orientation[i].conjugate() * (m.joint_world[i] - m.rest_position[i]);
    const int p = m.parent[i];
    m.joint_in_parent[i] = m.rest_orientation[p].conjugate() * (m.joint_world[i] - m.rest_position[p]);
  }
}

// A uniform solid rod (cylinder) of length `length` and radius `radius`, mass `mass`, hanging from a
// ball joint at its top end at `pivot`, tilted by `angle` (rad) about the z axis.
inline Model hanging_rod(double length, double radius, double mass, const Vec3& pivot, double angle) {
  Model m = empty_model(2);
  m.parent[1] = 0;
  m.mass[1] = mass;
  const double transverse = mass * (3 * radius * radius + length * length) / 12.0;
  const double axial = 0.5 * mass * radius * radius;
  // Principal frame: body y along the rod.
  m.principal_moments[1] = Vec3(transverse, axial, transverse);
  m.rest_orientation[1] = Quat(Eigen::AngleAxisd(angle, Vec3::UnitZ()));
  m.rest_position[1] = pivot + m.rest_orientation[1] * Vec3(0, -length / 2, 0);
  m.rest_position[0] = pivot;
  m.joint_world[1] = pivot;
  finish_model(m);
  return m;
}

// A random tree of `count` components (random parents, masses, inertias, orientations, joints).
inline Model random_tree(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  auto random_vec = [&](double scale) { return Vec3(uniform(-scale, scale), uniform(-scale, scale), uniform(-scale, scale)); };
  Model m = empty_model(count);
  for (int i = 1; i < count; ++i) {
    m.parent[i] = static_cast<int>(unit(rng) * i);  // any earlier component keeps parent < child
    m.mass[i] = uniform(0.05, 5.0);
    // Principal moments obeying the triangle inequality of a real body.
    const double a = uniform(0.2, 1.0), b = uniform(0.2, 1.0);
    const double c = uniform(std::abs(a - b) + 0.05, a + b);
    m.principal_moments[i] = m.mass[i] * 0.01 * Vec3(a, b, c);
    m.rest_orientation[i] = Quat::UnitRandom();  // uses std::rand; seeded below for determinism
    m.joint_world[i] = m.rest_position[m.parent[i]] + random_vec(0.3);
    m.rest_position[i] = m.joint_world[i] + random_vec(0.3);
  }
  finish_model(m);
  return m;
}

}  // namespace aloft::test
