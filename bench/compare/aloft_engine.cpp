#include <stdexcept>

#include "aloft/simulation.hpp"
#include "compare/engine.hpp"

namespace aloft::compare {
namespace {

class AloftEngine : public Engine {
 public:
  AloftEngine(const Model& model, const State& initial, double timestep, bool collisions)
      : sim_(model, initial) {
    sim_.set_timestep(timestep);
    sim_.set_damping(DampingSpec{});
    sim_.set_collisions(collisions);  // off where the comparison is of the joints' dynamics alone
  }
  std::string name() const override { return "Aloft"; }
  void step() override {
    if (!sim_.step()) throw std::runtime_error("Aloft: " + sim_.failure()->message);
  }
  void read(State& out) override { out = sim_.state(); }
  int contact_points() const override { return static_cast<int>(sim_.contacts().size()); }
  double deepest_overlap() const override { return sim_.collision_statistics().deepest; }

 private:
  Simulation sim_;
};

}  // namespace

std::unique_ptr<Engine> make_aloft(const Model& model, const State& initial, double timestep, bool collisions) {
  return std::make_unique<AloftEngine>(model, initial, timestep, collisions);
}

}  // namespace aloft::compare
