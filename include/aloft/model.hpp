#pragma once
// The compiled, immutable mobile. Components are stored as arrays in depth-first order with
// parent[i] < i; index 0 is the fixed component (the hook). Each component's body frame is its
// principal frame: origin at its centre of mass, axes along its principal axes of inertia.

#include <string>
#include <vector>

#include "aloft/spec.hpp"

namespace aloft {

// A shape carried into the model, expressed in its component's body (principal) frame.
struct BodyShape {
  Shape shape;             // body-frame coordinates (m)
  Color color;
};

// What balancing did, per component and overall (for `aloft inspect`).
struct BalanceReport {
  BalanceMode mode = BalanceMode::Mass;
  double total_mass = 0;                     // kg of the moving components
  // Largest horizontal distance (m) between a joint and the centre of mass of the subtree hanging from
  // it, after balancing: ~0 for a balanced mobile.
  double max_imbalance = 0;
  std::vector<double> mass_scale;            // per component: mass / (density * volume) chosen
  std::vector<std::string> notes;            // human-readable remarks
};

struct Model {
  std::string name;
  std::string file;                          // mobile file it came from
  int count = 0;                             // number of components (bodies), fixed one included

  // Topology, indexed by component (0 = fixed).
  std::vector<int> parent;                   // parent[0] == -1, parent[i] < i
  std::vector<std::vector<int>> children;
  std::vector<std::string> names;
  std::vector<int> file_index;               // index of the component in the file's array

  // Mass properties.
  std::vector<double> mass;                  // kg (the fixed component's mass is informational)
  std::vector<Vec3> principal_moments;       // kg m^2, about the centre of mass, body axes
  std::vector<double> volume;                // m^3

  // Designed rest pose.
  std::vector<Vec3> rest_position;           // centre of mass, world, m
  std::vector<Quat> rest_orientation;        // body (principal) frame -> world

  // Joints: joint i (i >= 1) joins component i to parent[i].
  std::vector<Vec3> joint_world;             // world point at rest, m (joint_world[0] unused)
  std::vector<Vec3> joint_in_child;          // from i's centre of mass, in i's body frame, m
  std::vector<Vec3> joint_in_parent;         // from parent's centre of mass, in parent's body frame, m

  // Geometry (body frames) and appearance.
  std::vector<std::vector<BodyShape>> shapes;
  std::vector<Color> color;

  // Settings.
  Vec3 gravity{0, -9.81, 0};                 // m/s^2, world
  double timestep = 0.001;                   // s
  DampingSpec damping;
  ContactSpec contact;
  std::vector<double> restitution;           // per component
  std::vector<double> friction;              // per component

  BalanceReport balance;
};

// Check the spec's meaning and build the model: validate topology (one fixed component, known parents,
// no cycles), order depth-first, compute mass properties, balance, principal frames and joint anchors.
// Throws InputError naming the file, the JSON path and the line.
Model compile(const MobileSpec& spec);

// parse_mobile_file + compile.
Model load_mobile(const std::string& path);

}  // namespace aloft
