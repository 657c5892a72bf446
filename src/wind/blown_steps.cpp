// Steps blown by a steady wind, its work timed apart (see include/aloft/blown_steps.hpp).

#include "aloft/blown_steps.hpp"

#include <stdexcept>
#include <string>

#include "aloft/spec.hpp"

namespace aloft {

BlownSteps::BlownSteps(const Model& model, Simulation& sim, double v0) : sim_(sim) {
  if (v0 == 0) return;
  if (!acceptable_wind_speed(v0)) throw std::invalid_argument(wind_speed_rule() + ", got " + std::to_string(v0));
  v0_ = v0;
  wind_ = std::make_unique<Wind>(model, source_in_front(model, sim.state()), WindSettings{});
  refresh_every_ = occlusion_refresh_steps(kOcclusionRefreshRate, sim.timestep());
  timer_ = std::make_unique<ApartTimer>();
}

bool BlownSteps::step() {
  if (wind_) {
    timer_->apart([&] {
      if (steps_blown_ % refresh_every_ == 0) wind_->refresh_occlusion(sim_.state());
      sim_.loads().clear();
      wind_->apply(sim_.state(), v0_, sim_.timestep(), sim_.loads());
    });
    ++steps_blown_;
  }
  return sim_.step();
}

}  // namespace aloft
