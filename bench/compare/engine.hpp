#pragma once
// One simulator behind a common face, for aloft_compare: built from an Aloft Model and an initial State
// at the model's designed pose (aloft/state.hpp: swinging_state), stepped at a fixed timestep with no
// damping, and read back as an Aloft State (centres of mass, body = principal frames) so that energies
// and joint separations are measured by the same code for every engine. Aloft and Bullet can also be
// built with collisions (aloft_compare --collisions): the cost of the same span with and without them.

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
  // With collisions: the contact points the last step found (each engine's own count: Aloft's detector's
  // contacts within its margin, Bullet's persistent-manifold points) and the deepest overlap seen so far
  // (m, >= 0). Zero without collisions.
  virtual int contact_points() const { return 0; }
  virtual double deepest_overlap() const { return 0; }
};

// Aloft's Simulation with air damping switched off; collisions as the mobile file sets them (restitution,
// friction) when `collisions`, else off.
std::unique_ptr<Engine> make_aloft(const Model& model, const State& initial, double timestep,
                                   bool collisions = false);

// Bullet btMultiBody (Featherstone): fixed base = the hook, one spherical link per moving component; with
// `collisions`, each component (the hook too) gets a link collider made of Aloft's convex pieces, with
// the mobile's restitution and friction, and the links collide with each other (not with their parents).
std::unique_ptr<Engine> make_bullet(const Model& model, const State& initial, double timestep,
                                    bool collisions = false);

// ODE: one body per moving component, ball joints; quick = dWorldQuickStep, else dWorldStep.
std::unique_ptr<Engine> make_ode(const Model& model, const State& initial, double timestep, bool quick);
std::string ode_configuration();  // precision and settings, for the report

}  // namespace aloft::compare
