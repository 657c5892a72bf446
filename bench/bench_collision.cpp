// Collision detection cost: CollisionDetector::find_contacts on the Steel Fish and on generated mobiles
// of 127, 1023 and 8191 components, at rest (the designed pose, still) and slightly displaced (every
// joint turned by a random angle of up to `kTurn` about a random axis, composed down the tree, with the
// velocities of swinging_state (aloft/state.hpp), so that the speculative margins are those of a moving
// mobile).
// Reports time per call and, as the counter "per_component", per component. Margin: 1 mm + step * speed.
//
//   build/<dir>/bench/aloft_bench_collision --benchmark_repetitions=5 --benchmark_report_aggregates_only

#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "aloft/collision.hpp"
#include "bench_models.hpp"
#include "common/splitmix64.hpp"

namespace {

using namespace aloft;

constexpr double kBaseMargin = 0.001;  // m
constexpr double kTurn = 0.15;         // rad: largest joint turn of the displaced pose

// The rest pose with every joint turned by a random rotation (angle up to max_turn), composed from the
// hook down: component i turns with its parent's accumulated rotation and then its own, about its joint.
State displaced_state(const Model& model, double max_turn, std::uint64_t seed = 11) {
  std::uint64_t s = seed * 0x9E3779B97F4A7C15ull + 3;
  auto unit = [&s] { return splitmix64_unit(s); };
  State state = swinging_state(model);
  std::vector<Quat> turn(model.count, Quat::Identity());
  for (int i = 1; i < model.count; ++i) {
    const Vec3 axis = Vec3(2 * unit() - 1, 2 * unit() - 1, 2 * unit() - 1).normalized();
    const int p = model.parent[i];
    turn[i] = (turn[p] * Quat(Eigen::AngleAxisd(max_turn * unit(), axis))).normalized();
    state.orientation[i] = (turn[i] * model.rest_orientation[i]).normalized();
  }
  place_on_joints(model, state);
  return state;
}

void run(benchmark::State& bs, const Model& model, const State& state) {
  CollisionDetector detector(model);
  std::vector<Contact> contacts;
  detector.find_contacts(state, model.timestep, kBaseMargin, contacts);  // warm up (sizes the buffers)
  for (auto _ : bs) {
    detector.find_contacts(state, model.timestep, kBaseMargin, contacts);
    benchmark::DoNotOptimize(contacts.data());
  }
  bs.counters["contacts"] = static_cast<double>(contacts.size());
  bs.counters["candidates"] = static_cast<double>(detector.pairs().candidate_count);
  bs.counters["per_component"] =
      benchmark::Counter(static_cast<double>(model.count), benchmark::Counter::kIsIterationInvariantRate |
                                                               benchmark::Counter::kInvert);
}

void BM_CollisionSteelFish(benchmark::State& bs, bool displaced) {
  if (!bench::preset_exists("steel-fish")) {
    bs.SkipWithError("mobiles/steel-fish.json not found");
    return;
  }
  const auto model = bench::preset_model("steel-fish");
  const State state = displaced ? displaced_state(*model, kTurn) : rest_state(*model);
  run(bs, *model, state);
}

void BM_CollisionGenerated(benchmark::State& bs, bool displaced) {
  const auto model = bench::generated_model(static_cast<int>(bs.range(0)));
  const State state = displaced ? displaced_state(*model, kTurn) : rest_state(*model);
  run(bs, *model, state);
}

void BM_PrunePairs(benchmark::State& bs) {
  const auto model = bench::generated_model(static_cast<int>(bs.range(0)));
  for (auto _ : bs) benchmark::DoNotOptimize(prune_pairs(*model).candidates.size());
}

BENCHMARK_CAPTURE(BM_CollisionSteelFish, rest, false);
BENCHMARK_CAPTURE(BM_CollisionSteelFish, displaced, true);
BENCHMARK_CAPTURE(BM_CollisionGenerated, rest, false)->Arg(127)->Arg(1023)->Arg(8191);
BENCHMARK_CAPTURE(BM_CollisionGenerated, displaced, true)->Arg(127)->Arg(1023)->Arg(8191);
BENCHMARK(BM_PrunePairs)->Arg(127)->Arg(1023)->Arg(8191)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
