// A uniform rod on a ball joint: the exact large-amplitude compound-pendulum period.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "aloft/simulation.hpp"
#include "support/model_builder.hpp"

namespace aloft {
namespace {

// Complete elliptic integral of the first kind K(k) by the arithmetic-geometric mean (converges
// quadratically; 10 iterations reach double precision).
double elliptic_k(double k) {
  double a = 1.0, b = std::sqrt(1.0 - k * k);
  for (int i = 0; i < 10; ++i) {
    const double an = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = an;
  }
  return std::numbers::pi / (2.0 * a);
}

// Period of the rod's swing measured from the times its angle crosses zero upward, interpolated
// linearly between steps (at the crossing the angular acceleration is zero, so the interpolation
// error is O(h^3)).
double measured_period(Simulation& sim, const Vec3& pivot, int periods) {
  auto angle = [&] {
    const Vec3 d = sim.state().position[1] - pivot;
    return std::atan2(d.x(), -d.y());
  };
  std::vector<double> crossings;
  double previous = angle();
  while (static_cast<int>(crossings.size()) < periods + 1) {
    const double t0 = sim.state().time;
    EXPECT_TRUE(sim.step());
    const double now = angle();
    if (previous < 0 && now >= 0) crossings.push_back(t0 + sim.timestep() * (-previous) / (now - previous));
    previous = now;
  }
  return (crossings.back() - crossings.front()) / periods;
}

TEST(Pendulum, RodOnBallJointSwingsWithExactCompoundPendulumPeriod) {
  const double length = 0.5, radius = 0.004, mass = 0.2;
  const double amplitude = 5.0 * std::numbers::pi / 180.0;
  const Vec3 pivot(0, 2, 0);
  const Model model = test::hanging_rod(length, radius, mass, pivot, amplitude);
  Simulation sim(model);
  ASSERT_DOUBLE_EQ(sim.timestep(), 0.001);

  const double d = length / 2;
  const double i_pivot = model.principal_moments[1].x() + mass * d * d;
  const double g = 9.81;
  const double exact = 4.0 * std::sqrt(i_pivot / (mass * g * d)) * elliptic_k(std::sin(amplitude / 2));
  const double measured = measured_period(sim, pivot, 20);
  // 1e-5 relative (the requirement): semi-implicit Euler's period error for an oscillator of angular
  // frequency W is (W h)^2 / 24 ~ 1.5e-6 here (W ~ 5.4 rad/s, h = 1 ms); timing error of the crossings
  // is O(h^3) / 20 periods.
  RecordProperty("relative_error", std::to_string(measured / exact - 1));
  std::printf("period: measured %.9f s, exact %.9f s, relative error %.2e\n", measured, exact, measured / exact - 1);
  EXPECT_NEAR(measured / exact, 1.0, 1e-5) << "measured " << measured << " s, exact " << exact << " s";
  // The swing stays in its plane (ball joint, planar start): z stays ~0 (rounding only).
  EXPECT_LT(std::abs(sim.state().position[1].z()), 1e-9);
}

TEST(Pendulum, SmallAmplitudeAgreesWithLinearFormula) {
  // At 0.5 degrees the large-amplitude correction is 1 + theta^2/16 ~ 1 + 5e-6: the textbook
  // 2 pi sqrt(I/(m g d)) holds to 1e-5 as well.
  const double length = 0.3, radius = 0.003, mass = 0.1, amplitude = 0.5 * std::numbers::pi / 180.0;
  const Vec3 pivot(0, 1, 0);
  const Model model = test::hanging_rod(length, radius, mass, pivot, amplitude);
  Simulation sim(model);
  const double d = length / 2;
  const double i_pivot = model.principal_moments[1].x() + mass * d * d;
  const double linear = 2 * std::numbers::pi * std::sqrt(i_pivot / (mass * 9.81 * d));
  EXPECT_NEAR(measured_period(sim, pivot, 10) / linear, 1.0, 2e-5);
}

}  // namespace
}  // namespace aloft
