// Conservation laws of the step: energy and angular momentum with no wind, damping or collisions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "aloft/simulation.hpp"
#include "support/model_builder.hpp"
#include "support/presets.hpp"

namespace aloft {
namespace {

double total_energy(const Model& m, const State& s) { return kinetic_energy(m, s) + potential_energy(m, s); }

// The energy of the equilibrium the mobile settles into, found by letting it swing down under strong air
// damping (2/s for 40 s: the slowest swing mode decays by e^-40 in amplitude... well below 1e-9 J).
double settled_energy(const Model& model) {
  Simulation sim(model);
  sim.set_collisions(false);
  sim.set_damping(DampingSpec{2.0, 2.0});
  EXPECT_TRUE(sim.advance(40.0));
  return total_energy(model, sim.state());
}

TEST(Conservation, SteelFishSwingingConservesEnergyAndVerticalAngularMomentum) {
  // Mode "none": masses from densities, so the designed pose is not an equilibrium and it swings.
  const Model model = test::load_preset("steel-fish", BalanceMode::None);
  const double swing = total_energy(model, rest_state(model)) - settled_energy(model);
  ASSERT_GT(swing, 1e-3) << "the unbalanced Steel Fish should have swing energy to lose";

  Simulation sim(model);
  sim.set_collisions(false);  // the check is for the joints' dynamics alone: no collisions
  const double e0 = total_energy(model, sim.state());
  const Vec3 hook = model.rest_position[0];
  double worst_energy = 0, worst_momentum = 0, momentum_scale = 0;
  for (int k = 0; k < 60000; ++k) {  // 60 s at 1 ms
    ASSERT_TRUE(sim.step());
    if (k % 10 == 0) {
      worst_energy = std::max(worst_energy, std::abs(total_energy(model, sim.state()) - e0));
      const Vec3 l = angular_momentum(model, sim.state(), hook);
      worst_momentum = std::max(worst_momentum, std::abs(l.y()));  // starts at 0 (released at rest)
      momentum_scale = std::max(momentum_scale, l.norm());
    }
  }
  std::printf("swing energy %.4g J, worst |E - E0| %.3g J (%.3g%%); max |L| %.4g, worst |L_y| %.3g (%.3g%%)\n",
              swing, worst_energy, 100 * worst_energy / swing, momentum_scale, worst_momentum,
              100 * worst_momentum / momentum_scale);
  // 0.5% of the swing energy (the requirement): RATTLE's energy error is bounded and O(h^2).
  EXPECT_LT(worst_energy, 0.005 * swing);
  // Gravity and the hook's force have no moment about the vertical through the hook, so L_y stays 0;
  // "the same order" = 0.5% of the largest angular momentum about the hook during the swing.
  EXPECT_LT(worst_momentum, 0.005 * momentum_scale);
  EXPECT_GT(momentum_scale, 0.0);
}

TEST(Conservation, TumblingRandomTreeKeepsEnergy) {
  // Nine bodies of random shape, tumbling at up to ~8 rad/s: the hard case for the gyroscopic term.
  std::srand(1);
  Model model = test::random_tree(9, 1);
  for (int i = 1; i < model.count; ++i) model.parent[i] = (i - 1) / 2;
  for (int i = 1; i < model.count; ++i) {
    model.joint_world[i] = model.rest_position[model.parent[i]] + Vec3(0.1, -0.1, 0);
    model.rest_position[i] = model.joint_world[i] + Vec3(0.0, -0.1, 0.01);
  }
  test::finish_model(model);
  Simulation sim(model);
  const double e0 = total_energy(model, sim.state());
  double peak_kinetic = 0, worst = 0;
  for (int k = 0; k < 30000; ++k) {
    ASSERT_TRUE(sim.step());
    peak_kinetic = std::max(peak_kinetic, kinetic_energy(model, sim.state()));
    worst = std::max(worst, std::abs(total_energy(model, sim.state()) - e0));
  }
  // 0.1% of the peak kinetic energy over 30 s; measured ~2e-5 relative (bounded, no drift).
  EXPECT_LT(worst, 1e-3 * peak_kinetic);
}

TEST(Conservation, FreelySpinningPlateKeepsEnergyAndMomentum) {
  // A thin plate hung by a joint at its own centre of mass rotates freely (gravity has no moment about
  // it). Spun near its intermediate axis it flips over and over (the Dzhanibekov effect), the classic
  // case where an explicit gyroscopic term gains energy every step.
  Model model = test::empty_model(2);
  model.parent[1] = 0;
  model.mass[1] = 0.5;
  model.principal_moments[1] = Vec3(0.002, 0.005, 0.007);  // thin plate: I1 + I2 = I3
  model.rest_position[0] = model.rest_position[1] = model.joint_world[1] = Vec3(0, 1, 0);
  test::finish_model(model);
  State start = rest_state(model);
  start.angular[1] = Vec3(0.05, 20.0, 0.05);  // about the intermediate axis, slightly off
  Simulation sim(model, start);
  const double e0 = kinetic_energy(model, sim.state());
  const Vec3 l0 = angular_momentum(model, sim.state(), Vec3(0, 1, 0));
  double worst_e = 0, worst_l = 0;
  int flips = 0;
  double last_sign = 1;
  for (int k = 0; k < 20000; ++k) {  // 20 s at 20 rad/s: h|w| = 0.02
    ASSERT_TRUE(sim.step());
    worst_e = std::max(worst_e, std::abs(kinetic_energy(model, sim.state()) - e0));
    worst_l = std::max(worst_l, (angular_momentum(model, sim.state(), Vec3(0, 1, 0)) - l0).norm());
    const double sign = (sim.state().orientation[1].conjugate() * sim.state().angular[1]).y() > 0 ? 1 : -1;
    if (sign != last_sign) ++flips;
    last_sign = sign;
  }
  EXPECT_GT(flips, 4) << "the plate should tumble about its intermediate axis";
  // The drift is a free-body flow at constant L, so |L| is exact to rounding and the implicit-midpoint
  // orientation keeps the energy to O((h|w|)^2) ~ 4e-4 relative, with no growth.
  EXPECT_LT(worst_l, 1e-9 * l0.norm());
  EXPECT_LT(worst_e, 2e-3 * e0);
}

}  // namespace
}  // namespace aloft
