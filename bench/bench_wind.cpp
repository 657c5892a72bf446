// The wind's cost (issue 4 targets): the occlusion pass for the Steel Fish at 256 x 256 (< 0.5 ms on one
// core), one apply() per physics step, and a whole Steel Fish simulation in wind with occlusion refreshed
// 60 times per simulated second and 1 ms steps (>= 30 x real time).
//
//   build/release/bench/aloft_bench_wind --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include "aloft/simulation.hpp"
#include "aloft/wind.hpp"
#include "bench_models.hpp"

namespace aloft::bench {
namespace {

void BM_WindOcclusion(benchmark::State& st) {
  if (!preset_exists("steel-fish")) return st.SkipWithError("mobiles/steel-fish.json not found");
  const auto model = preset_model("steel-fish");
  const State state = swinging_state(*model);  // a generic pose, not the symmetric drawing
  WindSettings settings;
  settings.resolution = static_cast<int>(st.range(0));
  Wind wind(*model, source_in_front(*model, state), settings);
  for (auto _ : st) {
    wind.refresh_occlusion(state);
    benchmark::DoNotOptimize(wind.elements().data());
  }
  st.counters["elements"] = static_cast<double>(wind.elements().size());
  std::size_t covered = 0;
  for (std::uint32_t id : wind.item_buffer().ids) covered += id != 0;
  st.counters["pixels"] = static_cast<double>(covered);
}
BENCHMARK(BM_WindOcclusion)->Arg(128)->Arg(256)->Arg(512)->Unit(benchmark::kMicrosecond);

void BM_WindApply(benchmark::State& st) {
  if (!preset_exists("steel-fish")) return st.SkipWithError("mobiles/steel-fish.json not found");
  const auto model = preset_model("steel-fish");
  const State state = swinging_state(*model);
  Wind wind(*model, source_in_front(*model, state), WindSettings{});
  wind.refresh_occlusion(state);
  ExternalLoads loads;
  loads.resize(model->count);
  for (auto _ : st) {
    loads.clear();
    wind.apply(state, 2.5, 0.001, loads);
    benchmark::DoNotOptimize(loads.force.data());
  }
  st.counters["elements"] = static_cast<double>(wind.elements().size());
}
BENCHMARK(BM_WindApply)->Unit(benchmark::kMicrosecond);

// One simulated second per iteration, continuing the same run (it keeps swinging in the wind).
void BM_SteelFishInWind(benchmark::State& st) {
  if (!preset_exists("steel-fish")) return st.SkipWithError("mobiles/steel-fish.json not found");
  const auto model = preset_model("steel-fish");
  Simulation sim(*model);
  Wind wind(*model, source_in_front(*model, sim.state()), WindSettings{});
  const int refresh_every = 17;  // 1 ms steps: 58.8 refreshes per simulated second (the CLI's --wind-refresh 60)
  long long step = 0;
  for (auto _ : st) {
    for (int i = 0; i < 1000; ++i, ++step) {
      if (step % refresh_every == 0) wind.refresh_occlusion(sim.state());
      sim.loads().clear();
      wind.apply(sim.state(), 2.5, sim.timestep(), sim.loads());
      if (!sim.step()) return st.SkipWithError("the simulation failed");
    }
  }
  // Simulated seconds per wall second.
  st.counters["x_real_time"] = benchmark::Counter(static_cast<double>(st.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SteelFishInWind)->Unit(benchmark::kMillisecond);

// The same without wind, for the ratio.
void BM_SteelFishNoWind(benchmark::State& st) {
  if (!preset_exists("steel-fish")) return st.SkipWithError("mobiles/steel-fish.json not found");
  const auto model = preset_model("steel-fish");
  Simulation sim(*model, swinging_state(*model));
  for (auto _ : st)
    for (int i = 0; i < 1000; ++i)
      if (!sim.step()) return st.SkipWithError("the simulation failed");
  st.counters["x_real_time"] = benchmark::Counter(static_cast<double>(st.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SteelFishNoWind)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace aloft::bench

BENCHMARK_MAIN();
