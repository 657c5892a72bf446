#pragma once
// Balancing a mobile (method notes, section 2): derive the masses, or move the hanging points, so that
// the designed pose is an equilibrium: for every moving component, the centre of mass of the subtree
// hanging from it lies on the vertical through its joint.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "aloft/model.hpp"

namespace aloft::internal {

// The per-component data balancing works on, in depth-first order (parent[i] < i, 0 = fixed).
struct BalanceInput {
  std::vector<int> parent;
  std::vector<std::vector<int>> children;
  std::vector<std::string> names;
  std::vector<std::string> paths;         // JSON path of each component, for errors
  std::vector<double> base_mass;          // kg at the given densities
  std::vector<Vec3> center;               // centre of mass, world, m
  std::vector<Vec3> joint;                // world hanging point (joint[0] unused), m
  Vec3 gravity{0, -9.81, 0};
};

struct BalanceResult {
  std::vector<double> mass_scale;         // mass_i = mass_scale_i * base_mass_i
  std::vector<Vec3> joint;                // hanging points after balancing (moved in mode Joints)
  double max_imbalance = 0;               // m, largest horizontal joint-to-subtree-centre distance
  std::vector<std::string> notes;
};

// A centre of mass closer than this to the vertical through a joint counts as on it (m). It is what a
// hand-written file can hold (coordinates to the micrometre): it tilts a 5 cm leaf by 1e-3 degrees.
inline constexpr double kBalanceTolerance = 1e-6;

// Balance per `mode`, scaling to `total_mass` (kg of the moving components) when given. Throws
// InputError via `fail(path, problem)` when the design cannot balance with positive masses.
BalanceResult balance(const BalanceInput& in, BalanceMode mode, std::optional<double> total_mass,
                      const std::function<void(const std::string&, const std::string&)>& fail);

// Largest horizontal distance (m) between a joint and the centre of mass of the subtree it carries.
double max_imbalance(const BalanceInput& in, const std::vector<double>& mass, const std::vector<Vec3>& joint);

}  // namespace aloft::internal
