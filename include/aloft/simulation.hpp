#pragma once
// Stepping a mobile in time: constraint dynamics with Baraff's linear-time tree factorization.
//
// One step (fixed h, default 1 ms), top to bottom in Simulation::step():
//   1. applied forces     gravity, external (wind), air damping, implicit-midpoint gyroscopic torque
//   2. factor             children-first block LDL^T of the joint KKT matrix at the current pose, O(n)
//   3. accelerations      solve for accelerations and joint forces (with the centripetal term)
//   4. integrate          semi-implicit (symplectic) Euler; orientations as unit quaternions
//   5. drift correction   project positions, then velocities, back onto the joint constraints
//   6. check              stop with a report if any component's state is not finite

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "aloft/state.hpp"

namespace aloft {

// Why a simulation stopped: the first component whose state became non-finite, and when.
struct SimulationFailure {
  int component = -1;
  std::string component_name;
  double time = 0;        // s
  std::string message;    // full, user-facing
};

// Forces applied from outside (wind, a user's pull) for the next steps, per component, world frame.
struct ExternalLoads {
  std::vector<Vec3> force;    // N, through the centre of mass
  std::vector<Vec3> torque;   // N m, about the centre of mass
  void resize(int count);
  void clear();
};

struct StepWorkspace;  // solver factorization and scratch (dynamics/simulation.cpp)

class Simulation {
 public:
  explicit Simulation(const Model& model);          // starts from the designed pose at rest
  Simulation(const Model& model, State initial);
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // Advance by one step of timestep() seconds. Returns false (and failure() tells why) when the state
  // became non-finite; the state is then left as it was before the step.
  bool step();

  // Advance by whole steps covering `duration` seconds. Returns false on failure.
  bool advance(double duration);

  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  State& state() { return state_; }
  ExternalLoads& loads() { return loads_; }

  double timestep() const { return timestep_; }
  void set_timestep(double seconds);

  // Air damping rates (1/s); default from the model.
  void set_damping(const DampingSpec& damping) { damping_ = damping; }

  const std::optional<SimulationFailure>& failure() const { return failure_; }
  long long step_count() const { return steps_; }

 private:
  const Model& model_;
  State state_;
  ExternalLoads loads_;
  double timestep_;
  DampingSpec damping_;
  std::optional<SimulationFailure> failure_;
  long long steps_ = 0;
  std::unique_ptr<StepWorkspace> work_;  // sized once; step() never allocates
};

}  // namespace aloft
