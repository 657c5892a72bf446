// The Steel Fish in a steady breath from the front: it turns and swings, stays finite and keeps its
// joints together; with no wind it stays at rest.

#include <gtest/gtest.h>

#include <cmath>

#include "aloft/simulation.hpp"
#include "aloft/wind.hpp"
#include "support/presets.hpp"

namespace aloft::test {
namespace {

struct Outcome {
  double largest_move = 0;      // m: largest displacement of any component's centre of mass from rest
  double largest_turn = 0;      // rad: largest rotation of any component from its rest orientation
  double joint_separation = 0;  // m, largest seen
  bool finite = true;
};

// `seconds` of simulation at 1 ms steps with the occlusion refreshed at 60 Hz, the cone in front of the
// mobile (along -z, S0 1.5 m from the mobile's centre, l0 = 1 m), constant v0.
Outcome breathe(double v0, double seconds, double beta) {
  static const Model model = load_preset("steel-fish", BalanceMode::Mass, /*damping=*/true);
  Simulation sim(model);
  const WindSource source = source_in_front(model, sim.state());
  WindSettings settings;
  settings.beta = beta;
  Wind wind(model, source, settings);
  const State rest = rest_state(model);
  Outcome out;
  const int steps = static_cast<int>(std::lround(seconds / sim.timestep()));
  const int refresh_every = static_cast<int>(std::lround(1.0 / 60 / sim.timestep()));
  for (int i = 0; i < steps; ++i) {
    if (i % refresh_every == 0) wind.refresh_occlusion(sim.state());
    sim.loads().clear();
    wind.apply(sim.state(), v0, sim.timestep(), sim.loads());
    if (!sim.step()) {
      out.finite = false;
      return out;
    }
    const State& s = sim.state();
    for (int c = 1; c < model.count; ++c) {
      out.largest_move = std::max(out.largest_move, (s.position[c] - rest.position[c]).norm());
      out.largest_turn = std::max(out.largest_turn, s.orientation[c].angularDistance(rest.orientation[c]));
    }
    out.joint_separation = std::max(out.joint_separation, max_joint_separation(model, s));
  }
  return out;
}

TEST(SteelFishWind, SteadyBreathTurnsAndSwingsIt) {
  const Outcome o = breathe(2.5, 3.0, 0.3);
  ASSERT_TRUE(o.finite);
  // A visible motion: 2 cm of travel or 0.1 rad (6 deg) of turn in 3 s. The default wind (alpha = rho
  // l0^4, v0 = 2.5 m/s) is meant to turn the fish gracefully, which is well above these.
  EXPECT_GT(o.largest_move, 0.02);
  EXPECT_GT(o.largest_turn, 0.1);
  // The joint solver holds joints to 1e-9 m per step (SHAKE tolerance); 1e-6 m allows for the velocity
  // projection's drift over 3000 steps and still catches a joint coming apart.
  EXPECT_LT(o.joint_separation, 1e-6);
}

TEST(SteelFishWind, NoWindNoMotion) {
  const Outcome o = breathe(0.0, 1.0, 0.3);
  ASSERT_TRUE(o.finite);
  // Balanced at its drawn pose ("mass" mode): only round-off moves it; 1e-6 m and 1e-5 rad are far above
  // that (~1e-12) and far below any wind's effect.
  EXPECT_LT(o.largest_move, 1e-6);
  EXPECT_LT(o.largest_turn, 1e-5);
}

}  // namespace
}  // namespace aloft::test
