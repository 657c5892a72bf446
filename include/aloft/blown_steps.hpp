#pragma once
// Steps blown by a steady wind, the wind's own work timed apart: how `aloft bench --wind` and
// aloft_step_profile --wind time a step in the wind, so that a collisions on / off comparison times the
// step alone.
//
// The wind is the command line's default one (`aloft simulate --wind V0`): S0 1.5 m in front (+z) of the
// mobile as it stands when the steps are made, blowing along -z, its cone just covering the mobile
// (source_facing_mobile), l0 = 1 m, the default WindSettings (turbulence beta 0.3, seed 1), and the
// occlusion refreshed at kOcclusionRefreshRate, 60 Hz (every 17 steps of 1 ms).

#include <memory>

#include "aloft/simulation.hpp"
#include "aloft/thread_clock.hpp"
#include "aloft/wind.hpp"

namespace aloft {

class BlownSteps {
 public:
  // v0 (m/s at S0) > 0: every step is blown; 0: plain steps. Throws std::invalid_argument for a speed
  // the cone model does not take (acceptable_wind_speed). Blown, it calibrates the CPU clock's read cost
  // first (about 8 ms). `sim` must outlive this.
  BlownSteps(const Model& model, Simulation& sim, double v0);

  // The wind's loads at the simulation's state (the occlusion refreshed when due), timed apart; then
  // Simulation::step(), whose result it returns.
  bool step();

  double v0() const { return v0_; }
  long long steps_blown() const { return steps_blown_; }
  // CPU time (s) a timed span of steps gives up for the wind so far, the clock's reads included (0
  // without a wind): subtract the difference of two readings from the span's time.
  double wind_seconds() const { return timer_ ? timer_->taken_from_span() : 0.0; }
  // The wind's own CPU time (s) so far, without the clock's reads.
  double wind_work_seconds() const { return timer_ ? timer_->work_seconds() : 0.0; }

 private:
  Simulation& sim_;
  double v0_ = 0;
  std::unique_ptr<Wind> wind_;
  std::unique_ptr<ApartTimer> timer_;
  int refresh_every_ = 1;  // steps
  long long steps_blown_ = 0;
};

}  // namespace aloft
