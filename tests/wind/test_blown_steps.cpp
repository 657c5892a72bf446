// BlownSteps (aloft/blown_steps.hpp): the benchmarks' steps in a steady wind, its work timed apart.

#include <gtest/gtest.h>

#include <stdexcept>

#include "aloft/blown_steps.hpp"
#include "aloft/state.hpp"
#include "support/presets.hpp"

namespace aloft::test {
namespace {

TEST(BlownSteps, BlowTheMobileFromRestAndTimeTheWindApart) {
  const Model model = load_mobile(preset_path("steel-fish"));
  Simulation still(model), blown_sim(model);
  BlownSteps plain(model, still, 0.0), blown(model, blown_sim, 3.0);
  constexpr int kSteps = 200;  // 0.2 s: the wind has turned the fish visibly
  for (int k = 0; k < kSteps; ++k) {
    ASSERT_TRUE(plain.step());
    ASSERT_TRUE(blown.step());
  }
  // Without a wind, a balanced mobile released at rest stays at rest: 1.3e-18 J of round-off here
  // (the balance holds to about 1e-16 relative), against 2.5e-6 J the wind gives it in the same time.
  EXPECT_LT(kinetic_energy(model, still.state()), 1e-15);  // J
  EXPECT_EQ(plain.steps_blown(), 0);
  EXPECT_EQ(plain.wind_seconds(), 0.0);
  // In a 3 m/s wind it moves, every step was blown and the wind's CPU time was counted.
  EXPECT_GT(kinetic_energy(model, blown_sim.state()), 1e-7);
  EXPECT_EQ(blown.steps_blown(), kSteps);
  EXPECT_GT(blown.wind_work_seconds(), 0.0);
  EXPECT_GT(blown.wind_seconds(), blown.wind_work_seconds());  // the clock's reads counted too
  EXPECT_THROW(BlownSteps(model, blown_sim, 150.0), std::invalid_argument);  // over kFastestWind
  EXPECT_THROW(BlownSteps(model, blown_sim, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace aloft::test
