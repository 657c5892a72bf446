#include "aloft/simulation.hpp"

#include <cmath>
#include <sstream>

#include "dynamics/gyroscopic.hpp"
#include "dynamics/tree_solver.hpp"

namespace aloft {

void ExternalLoads::resize(int count) {
  force.assign(count, Vec3::Zero());
  torque.assign(count, Vec3::Zero());
}

void ExternalLoads::clear() {
  std::fill(force.begin(), force.end(), Vec3::Zero());
  std::fill(torque.begin(), torque.end(), Vec3::Zero());
}

// Everything step() needs, sized once per model.
struct StepWorkspace {
  explicit StepWorkspace(const Model& model)
      : solver(model),
        next(rest_state(model)),
        wrench(model.count, Vec6::Zero()),
        rows(model.count, Vec3::Zero()),
        unknowns(model.count, Vec6::Zero()) {}
  TreeSolver solver;
  State next;                    // the state being computed; swapped in when it is finite
  std::vector<Vec6> wrench;      // right-hand side f per body (force, torque), world
  std::vector<Vec3> rows;        // right-hand side c per joint
  std::vector<Vec6> unknowns;    // solution u per body
};

namespace {

// Rotation by the rotation vector `theta` (rad, world) as a unit quaternion: exp(theta / 2).
Quat rotation_quaternion(const Vec3& theta) {
  const double angle = theta.norm();
  if (angle < 1e-8) {
    // Taylor series; the neglected terms are O(angle^3) ~ 1e-24.
    return Quat(1.0 - angle * angle / 8.0, 0.5 * theta.x(), 0.5 * theta.y(), 0.5 * theta.z());
  }
  const double s = std::sin(0.5 * angle) / angle;
  return Quat(std::cos(0.5 * angle), s * theta.x(), s * theta.y(), s * theta.z());
}

bool finite(const Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

}  // namespace

Simulation::Simulation(const Model& model) : Simulation(model, rest_state(model)) {}

Simulation::Simulation(const Model& model, State initial)
    : model_(model),
      state_(std::move(initial)),
      timestep_(model.timestep),
      damping_(model.damping),
      work_(std::make_unique<StepWorkspace>(model)) {
  loads_.resize(model.count);
  work_->next = state_;
}

Simulation::~Simulation() = default;

void Simulation::set_timestep(double seconds) { timestep_ = seconds; }

bool Simulation::step() {
  const int n = model_.count;
  const double h = timestep_;
  const std::vector<int>& parent = model_.parent;
  const State& now = state_;
  State& next = work_->next;
  TreeSolver& solver = work_->solver;
  std::vector<Vec6>& f = work_->wrench;
  std::vector<Vec3>& c = work_->rows;
  std::vector<Vec6>& u = work_->unknowns;

  // 1. Factor H at the current pose (world inertias, lever arms).
  solver.factor(now);
  const std::vector<Vec3>& r = solver.child_arm();
  const std::vector<Vec3>& s = solver.parent_arm();
  const std::vector<Mat3>& inertia = solver.world_inertia();

  // 2. Applied wrenches: gravity, external loads, air damping, gyroscopic torque (implicit midpoint).
  for (int i = 1; i < n; ++i) {
    const double m = model_.mass[i];
    const Vec3& w = now.angular[i];
    f[i].head<3>() = m * model_.gravity + loads_.force[i] - damping_.linear * m * now.velocity[i];
    f[i].tail<3>() = loads_.torque[i] - damping_.angular * (inertia[i] * w) +
                     midpoint_gyroscopic_torque(now.orientation[i], model_.principal_moments[i], w, h);
  }

  // 3. Accelerations. Differentiating C_k twice: J a = -(w_k x (w_k x r_k) - w_p x (w_p x s_k)).
  for (int i = 1; i < n; ++i) {
    const Vec3& wc = now.angular[i];
    const Vec3& wp = now.angular[parent[i]];
    c[i] = wp.cross(wp.cross(s[i])) - wc.cross(wc.cross(r[i]));
  }
  solver.solve(f, c, u);

  // 4. Integrate: semi-implicit Euler (velocities first, positions with the new velocities); the
  //    orientation turns by the exact rotation of the new angular velocity over h.
  next.time = now.time + h;
  for (int i = 1; i < n; ++i) {
    next.velocity[i] = now.velocity[i] + h * u[i].head<3>();
    next.angular[i] = now.angular[i] + h * u[i].tail<3>();
    next.position[i] = now.position[i] + h * next.velocity[i];
    next.orientation[i] = (rotation_quaternion(h * next.angular[i]) * now.orientation[i]).normalized();
  }

  // 5. Drift correction (post-stabilisation, Cline & Pai 2003), reusing the factorization of step 1.
  //    Positions: the mass-weighted smallest displacement d with J d = -C(next).
  for (int i = 1; i < n; ++i) f[i].setZero();
  for (int i = 1; i < n; ++i) c[i] = joint_on_parent(model_, next, i) - joint_on_child(model_, next, i);
  solver.solve(f, c, u);
  for (int i = 1; i < n; ++i) {
    next.position[i] += u[i].head<3>();
    next.orientation[i] = (rotation_quaternion(u[i].tail<3>()) * next.orientation[i]).normalized();
  }
  //    Velocities: remove the joint-velocity error J(next) u(next) the same way.
  for (int i = 1; i < n; ++i) {
    const int p = parent[i];
    const Vec3 rc = next.orientation[i] * model_.joint_in_child[i];
    const Vec3 rp = next.orientation[p] * model_.joint_in_parent[i];
    const Vec3 child_point = next.velocity[i] + next.angular[i].cross(rc);
    const Vec3 parent_point = next.velocity[p] + next.angular[p].cross(rp);
    c[i] = parent_point - child_point;
  }
  solver.solve(f, c, u);
  for (int i = 1; i < n; ++i) {
    next.velocity[i] += u[i].head<3>();
    next.angular[i] += u[i].tail<3>();
  }

  // 6. Check: a non-finite state stops the simulation with a report; the last good state stays.
  double sum = 0;
  for (int i = 1; i < n; ++i)
    sum += next.position[i].sum() + next.velocity[i].sum() + next.angular[i].sum() + next.orientation[i].w();
  if (!std::isfinite(sum)) {
    for (int i = 1; i < n; ++i) {
      if (finite(next.position[i]) && finite(next.velocity[i]) && finite(next.angular[i]) &&
          std::isfinite(next.orientation[i].w()))
        continue;
      SimulationFailure fail;
      fail.component = i;
      fail.component_name = model_.names[i];
      fail.time = next.time;
      std::ostringstream msg;
      msg << "the simulation became non-finite at t = " << next.time << " s (step " << steps_ + 1
          << "): component '" << model_.names[i] << "' has a NaN or infinite position, velocity or "
          << "angular velocity; the last finite state is kept";
      fail.message = msg.str();
      failure_ = fail;
      return false;
    }
  }
  std::swap(state_, next);
  ++steps_;
  return true;
}

bool Simulation::advance(double duration) {
  const long long count = std::llround(duration / timestep_);
  for (long long k = 0; k < count; ++k)
    if (!step()) return false;
  return true;
}

}  // namespace aloft
