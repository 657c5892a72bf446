#pragma once
// One simulator behind a common face, for aloft_compare: built from an Aloft Model and an initial State
// at the model's designed pose (bench_models.hpp: swinging_state), stepped at a fixed timestep with no
// damping and no collisions, and read back as an Aloft State (centres of mass, body = principal frames)
// so that energies and joint separations are measured by the same code for every engine.

#include <memory>
#include <string>

#include "aloft/state.hpp"

namespace aloft::compare {

class Engine {
 public:
  virtual ~Engine() = default;
  virtual std::string name() const = 0;
  virtual void step() = 0;                        // one step of the timestep given at creation
  virtual void read(State& out) = 0;              // out sized by rest_state(model)
};

// Aloft's Simulation with air damping switched off.
std::unique_ptr<Engine> make_aloft(const Model& model, const State& initial, double timestep);

// Bullet btMultiBody (Featherstone): fixed base = the hook, one spherical link per moving component.
std::unique_ptr<Engine> make_bullet(const Model& model, const State& initial, double timestep);

// ODE: one body per moving component, ball joints; quick = dWorldQuickStep, else dWorldStep.
std::unique_ptr<Engine> make_ode(const Model& model, const State& initial, double timestep, bool quick);
std::string ode_configuration();  // precision and settings, for the report

}  // namespace aloft::compare
