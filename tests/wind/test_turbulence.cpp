// Eq. 5: the random force is bounded by beta |F_stoke|, reproducible from a seed, absent with beta = 0,
// and correlated in time (gusts, not hiss).

#include <gtest/gtest.h>

#include <cmath>

#include "wind/wind_scenes.hpp"

namespace aloft::test {
namespace {

struct WindRun {
  std::vector<Vec3> force;      // component 1, per step
  std::vector<Vec3> random;
  std::vector<Vec3> stoke;
};

WindRun run_wind(double beta, std::uint64_t seed, int steps = 2000) {
  static const Model model = plates_model({PlacedPlate{Vec3(0, 0, 2), 0.1}});
  WindSettings settings;
  settings.resolution = 128;
  settings.beta = beta;
  settings.seed = seed;
  Wind wind(model, axis_source(), settings);
  const State state = rest_state(model);
  wind.refresh_occlusion(state);
  WindRun r;
  ExternalLoads loads;
  loads.resize(model.count);
  for (int i = 0; i < steps; ++i) {
    loads.clear();
    wind.apply(state, 2.0, 0.001, loads);
    r.force.push_back(loads.force[1]);
    r.random.push_back(wind.last_loads().random_force[1]);
    r.stoke.push_back(wind.last_loads().stoke_force[1]);
  }
  return r;
}

TEST(WindTurbulence, BetaZeroIsDeterministicAndSteady) {
  const WindRun a = run_wind(0, 1, 50), b = run_wind(0, 99, 50);
  for (std::size_t i = 0; i < a.force.size(); ++i) {
    EXPECT_EQ(a.force[i], a.force[0]);   // steady: the same state and v0 give the same force every step
    EXPECT_EQ(a.force[i], b.force[i]);   // the seed does not matter without turbulence
    EXPECT_EQ(a.random[i], Vec3::Zero());
  }
}

TEST(WindTurbulence, SeededRunsRepeatAndSeedsDiffer) {
  const WindRun a = run_wind(0.5, 7), b = run_wind(0.5, 7), c = run_wind(0.5, 8);
  EXPECT_EQ(a.force, b.force);  // bit for bit
  int different = 0;
  for (std::size_t i = 0; i < a.force.size(); ++i) different += a.force[i] != c.force[i];
  EXPECT_EQ(different, static_cast<int>(a.force.size()));
}

TEST(WindTurbulence, RandomForceIsBoundedByBetaStoke) {
  for (double beta : {0.1, 0.5, 2.0}) {
    const WindRun r = run_wind(beta, 3);
    double largest = 0;
    for (std::size_t i = 0; i < r.random.size(); ++i) {
      ASSERT_GT(r.stoke[i].norm(), 0);
      const double ratio = r.random[i].norm() / (beta * r.stoke[i].norm());
      EXPECT_LT(ratio, 1.0) << beta << " step " << i;  // strict: |g| / sqrt(1 + |g|^2) < 1
      largest = std::max(largest, ratio);
    }
    // Not a vanishing term either: over 2 s (5 correlation times) the gusts reach half the bound
    // (|g| > 0.58 has probability 0.9 per independent draw).
    EXPECT_GT(largest, 0.5) << beta;
  }
}

TEST(WindTurbulence, GustsAreCorrelatedInTime) {
  // Correlation time 0.4 s, 1 ms steps: successive random forces differ by ~ sqrt(2 dt / tau) = 7 % of
  // their scale, while values 1 s apart are nearly independent. Compare the mean step-to-step change with
  // the mean change over 1 s: the ratio is ~ 0.07 / 1.1; 0.3 leaves room for sampling noise and still
  // fails for white noise (ratio ~ 1).
  const WindRun r = run_wind(1.0, 11, 4000);
  double step_change = 0, second_change = 0;
  int n1 = 0, n2 = 0;
  for (std::size_t i = 1; i < r.random.size(); ++i, ++n1) step_change += (r.random[i] - r.random[i - 1]).norm();
  for (std::size_t i = 1000; i < r.random.size(); ++i, ++n2) second_change += (r.random[i] - r.random[i - 1000]).norm();
  EXPECT_LT((step_change / n1) / (second_change / n2), 0.3);
}

}  // namespace
}  // namespace aloft::test
