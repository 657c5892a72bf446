// compile(): from what a person wrote (MobileSpec) to the immutable Model, as a list of phases:
//   1. topology     names unique, exactly one fixed component, parents known, no cycles
//   2. order        depth-first from the fixed component, so parent[i] < i
//   3. mass         each component's mass properties at its densities (Mirtich / closed forms)
//   4. balance      masses (mode "mass") or hanging points (mode "joints") so the pose is an equilibrium
//   5. joints       every joint within joint_tolerance of both parts it joins
//   6. frames       principal axes, rest orientation, joint anchors and shapes in body frames

#include <Eigen/Eigenvalues>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <unordered_map>

#include "aloft/geometry.hpp"
#include "aloft/model.hpp"
#include "model/balance.hpp"
#include "model/transform_shape.hpp"

namespace aloft {

namespace {

[[noreturn]] void fail(const MobileSpec& spec, const std::string& path, const std::string& problem) {
  throw spec.error_at(path, problem);
}

std::string format_cm(double metres) {
  std::ostringstream s;
  s << std::setprecision(3) << metres * 100 << " cm";
  return s.str();
}

// Phase 1 and 2: check the tree and list the components depth-first from the fixed one.
// Returns order[k] = file index of the k-th component; parent_of[k] = position of its parent.
void order_tree(const MobileSpec& spec, std::vector<int>& order, std::vector<int>& parent_of) {
  const int n = static_cast<int>(spec.components.size());
  if (n == 0) fail(spec, "components", "a mobile needs at least one component");
  std::unordered_map<std::string, int> index;
  int fixed = -1;
  for (int i = 0; i < n; ++i) {
    const ComponentSpec& c = spec.components[i];
    auto [it, fresh] = index.emplace(c.name, i);
    if (!fresh)
      fail(spec, c.path + ".name",
           "the name \"" + c.name + "\" is already used by components[" + std::to_string(it->second) +
               "]; every component needs its own name");
    if (c.fixed) {
      if (fixed >= 0)
        fail(spec, c.path + ".fixed",
             "a second fixed component (\"" + spec.components[fixed].name + "\" is fixed too); a mobile hangs "
             "from exactly one fixed component");
      fixed = i;
    }
  }
  if (fixed < 0) fail(spec, "components", "no component is fixed; mark the hook with \"fixed\": true");

  std::vector<int> parent(n, -1);
  std::vector<std::vector<int>> children(n);
  for (int i = 0; i < n; ++i) {
    const ComponentSpec& c = spec.components[i];
    if (c.fixed) continue;
    if (!c.parent) fail(spec, c.path, "missing key \"parent\": every component but the fixed one hangs from a parent");
    auto it = index.find(*c.parent);
    if (it == index.end())
      fail(spec, c.path + ".parent", "unknown parent \"" + *c.parent + "\": no component has that name");
    if (it->second == i) fail(spec, c.path + ".parent", "a component cannot hang from itself");
    parent[i] = it->second;
    children[it->second].push_back(i);
  }

  // Depth-first preorder (explicit stack: chains may be tens of thousands deep).
  order.clear();
  std::vector<int> position(n, -1);
  std::vector<int> stack{fixed};
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    position[i] = static_cast<int>(order.size());
    order.push_back(i);
    for (auto it = children[i].rbegin(); it != children[i].rend(); ++it) stack.push_back(*it);
  }
  if (static_cast<int>(order.size()) != n) {
    // Some component is not below the fixed one: following its parents must loop.
    int start = 0;
    while (position[start] >= 0) ++start;
    std::vector<int> seen(n, 0);
    int i = start;
    while (!seen[i]) {
      seen[i] = 1;
      i = parent[i];
    }
    std::string cycle = "\"" + spec.components[i].name + "\"";
    for (int j = parent[i]; j != i; j = parent[j]) cycle += " -> \"" + spec.components[j].name + "\"";
    cycle += " -> \"" + spec.components[i].name + "\"";
    fail(spec, spec.components[i].path + ".parent",
         "the parents form a cycle (" + cycle + "), so these components do not hang from the fixed one");
  }
  parent_of.assign(n, -1);
  for (int k = 1; k < n; ++k) parent_of[k] = position[parent[order[k]]];
}

// Distance from a world point to the nearest shape of a component (m).
double distance_to_component(const ComponentSpec& c, const Vec3& point) {
  double best = INFINITY;
  for (const ShapeSpec& s : c.shapes) best = std::min(best, distance_to_shape(s.shape, point));
  return best;
}

}  // namespace

Model compile(const MobileSpec& spec) {
  // 1-2. Topology and depth-first order.
  std::vector<int> order, parent;
  order_tree(spec, order, parent);
  const int n = static_cast<int>(order.size());

  Model model;
  model.name = spec.name;
  model.file = spec.file;
  model.count = n;
  model.parent = parent;
  model.children.assign(n, {});
  for (int i = 1; i < n; ++i) model.children[parent[i]].push_back(i);
  model.file_index = order;
  model.names.resize(n);
  for (int i = 0; i < n; ++i) model.names[i] = spec.components[order[i]].name;

  // 3. Mass properties at the given densities (kg, world).
  std::vector<double> base_mass(n);
  std::vector<Vec3> center(n);
  std::vector<Mat3> base_inertia(n);
  std::vector<double> volume(n);
  for (int i = 0; i < n; ++i) {
    const ComponentSpec& c = spec.components[order[i]];
    MassAccumulator acc;
    double vol = 0;
    for (const ShapeSpec& s : c.shapes) {
      const double density = s.density.value_or(c.density.value_or(spec.density));
      const MassProperties mp = shape_mass_properties(s.shape);
      if (!(mp.volume > 0)) fail(spec, s.path, "this shape encloses no volume");
      acc.add(density * mp.volume, mp.center, density * mp.inertia);
      vol += mp.volume;
    }
    if (!(acc.mass > 0)) fail(spec, c.path + ".shapes", "the component has no mass");
    base_mass[i] = acc.mass;
    center[i] = acc.center();
    base_inertia[i] = acc.inertia_about_center();
    volume[i] = vol;
  }

  // 4. Balance.
  internal::BalanceInput in;
  in.parent = parent;
  in.children = model.children;
  in.names = model.names;
  in.base_mass = base_mass;
  in.center = center;
  in.gravity = spec.gravity;
  in.paths.resize(n);
  in.joint.assign(n, Vec3::Zero());
  for (int i = 0; i < n; ++i) {
    const ComponentSpec& c = spec.components[order[i]];
    in.paths[i] = c.path;
    if (i > 0) {
      if (!c.joint) fail(spec, c.path, "missing key \"joint\": the world point where it hangs from its parent");
      in.joint[i] = *c.joint;
    }
  }
  if (spec.balance.mode == BalanceMode::Mass && !spec.balance.total_mass)
    fail(spec, "balance", "balance mode \"mass\" needs \"total_mass\" (kg of the moving components)");
  const internal::BalanceResult balanced = internal::balance(
      in, spec.balance.mode, spec.balance.total_mass,
      [&](const std::string& path, const std::string& problem) { fail(spec, path, problem); });

  // 5. Joints lie on (or within joint_tolerance of) both parts they join.
  for (int i = 1; i < n; ++i) {
    const ComponentSpec& child = spec.components[order[i]];
    const ComponentSpec& par = spec.components[order[parent[i]]];
    const Vec3& p = balanced.joint[i];
    const double to_child = distance_to_component(child, p);
    const double to_parent = distance_to_component(par, p);
    if (to_child > spec.joint_tolerance || to_parent > spec.joint_tolerance) {
      const bool child_far = to_child > spec.joint_tolerance;
      std::ostringstream why;
      why << (spec.balance.mode == BalanceMode::Joints ? "after balancing, the joint " : "the joint ") << "["
          << p.x() << ", " << p.y() << ", " << p.z() << "] is "
          << format_cm(child_far ? to_child : to_parent) << " from '"
          << (child_far ? child.name : par.name) << "' (" << (child_far ? "the component itself" : "its parent")
          << "); a joint must lie within " << format_cm(spec.joint_tolerance)
          << " of both parts it joins (setting \"joint_tolerance\")";
      fail(spec, child.path + ".joint", why.str());
    }
  }

  // 6. Principal frames, joint anchors, body-frame shapes; settings.
  model.mass.resize(n);
  model.volume = volume;
  model.principal_moments.resize(n);
  model.rest_position = center;
  model.rest_orientation.resize(n);
  model.joint_world = balanced.joint;
  model.joint_in_child.assign(n, Vec3::Zero());
  model.joint_in_parent.assign(n, Vec3::Zero());
  model.shapes.resize(n);
  model.color.resize(n);
  model.restitution.resize(n);
  model.friction.resize(n);
  for (int i = 0; i < n; ++i) {
    const ComponentSpec& c = spec.components[order[i]];
    model.mass[i] = balanced.mass_scale[i] * base_mass[i];
    const Mat3 inertia = balanced.mass_scale[i] * base_inertia[i];
    Eigen::SelfAdjointEigenSolver<Mat3> eig(inertia);
    Mat3 axes = eig.eigenvectors();                 // columns: principal axes in world
    if (axes.determinant() < 0) axes.col(2) *= -1;  // a proper rotation
    model.principal_moments[i] = eig.eigenvalues();
    if (i > 0 && !(model.principal_moments[i].minCoeff() > 0 && model.principal_moments[i].allFinite())) {
      std::ostringstream why;
      why << "the component's inertia is not positive (principal moments " << model.principal_moments[i].x() << ", "
          << model.principal_moments[i].y() << ", " << model.principal_moments[i].z()
          << " kg m^2): its shapes are too small or too thin to compute in double precision";
      fail(spec, c.path + ".shapes", why.str());
    }
    model.rest_orientation[i] = Quat(axes).normalized();
    model.color[i] = c.color;
    model.restitution[i] = c.restitution.value_or(spec.contact.restitution);
    model.friction[i] = c.friction.value_or(spec.contact.friction);
    const Mat3 to_body = axes.transpose();
    for (const ShapeSpec& s : c.shapes)
      model.shapes[i].push_back({internal::transform_shape(s.shape, to_body, -(to_body * center[i])), c.color});
  }
  for (int i = 1; i < n; ++i) {
    const int p = parent[i];
    model.joint_in_child[i] = model.rest_orientation[i].conjugate() * (model.joint_world[i] - center[i]);
    model.joint_in_parent[i] = model.rest_orientation[p].conjugate() * (model.joint_world[i] - center[p]);
  }
  model.gravity = spec.gravity;
  model.timestep = spec.timestep;
  model.damping = spec.damping;
  model.contact = spec.contact;
  model.balance.mode = spec.balance.mode;
  model.balance.mass_scale = balanced.mass_scale;
  model.balance.max_imbalance = balanced.max_imbalance;
  model.balance.notes = balanced.notes;
  model.balance.total_mass = 0;
  for (int i = 1; i < n; ++i) model.balance.total_mass += model.mass[i];
  return model;
}

Model load_mobile(const std::string& path) { return compile(parse_mobile_file(path)); }

}  // namespace aloft
