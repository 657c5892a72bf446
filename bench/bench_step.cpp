// aloft_bench: the cost of a simulation step, and of the tree solver's factor and solve alone.
//
//   BM_Step/<mobile>     Simulation::step() on a swinging mobile (aloft/state.hpp: swinging_state),
//                        collisions off (issue 2's figure): presets from mobiles/ and generated mobiles
//                        of 15 ... 65535 components
//   BM_StepCollisions/<mobile>  the same with collisions on (issue 3's figure)
//   BM_StepSpan/<mobile>/off, .../on  the same over a fixed number of steps (span_steps), so that with
//                        collisions off and on the same motion is timed: BM_Step and BM_StepCollisions
//                        step on for as long as --benchmark_min_time asks, and the swing changes along
//                        the way (docs/performance.md, "The benchmark's span matters")
//   BM_StepSpanSeeds/<mobile>/off, .../on/seed:S  BM_StepSpan of the generated mobiles of 127 to 8191
//                        components from other swinging states (seeds 1, 2, 3; BM_StepSpan's is 7): the
//                        collisions' cost differs by half between trajectories
//   BM_Factor/<mobile>   TreeSolver::factor() at a swinging pose
//   BM_Solve/<mobile>    TreeSolver::solve() with the factorization of that pose
//
// items_per_second is steps (or factorizations, solves) per second of CPU time; us_per_component_step is
// the CPU time per moving component (count - 1) and per step, in microseconds. The mobiles start swinging
// (aloft/state.hpp: swinging_state), so that the joint iterations do real work. The step benchmarks also
// count halvings and tree solves per step and, with collisions on, the contact law's solves per step
// (law_solves) and the contacts per solve (law_contacts: its sweeps and collision matrix cost O(m^2) in
// them), as aloft_step_profile does.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdio>
#include <exception>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "aloft/generate.hpp"
#include "aloft/simulation.hpp"
#include "aloft/thread_clock.hpp"
#include "bench_models.hpp"
#include "dynamics/tree_solver.hpp"

namespace {

using aloft::Model;

const std::vector<std::string> kPresets = {"steel-fish", "southern-cross"};
const std::vector<int> kGenerated = {15, 127, 1023, 8191, 65535};
// The swinging state's seed for every step benchmark, and the others the generated mobiles' spans are
// also timed from (BM_StepSpanSeeds/<mobile>/<on|off>/seed:S, 127 to 8191 components).
constexpr std::uint64_t kSeed = 7;
const std::vector<std::uint64_t> kMoreSeeds = {1, 2, 3};

// Models are built on first use (generating and compiling 65535 components takes a while) and kept.
// A preset that is missing or does not load leaves an error message instead.
struct Entry {
  std::unique_ptr<Model> model;
  std::string error;
};

const Entry& model_entry(const std::string& key) {
  static std::map<std::string, Entry> cache;
  auto found = cache.find(key);
  if (found != cache.end()) return found->second;
  Entry entry;
  try {
    if (key.rfind("generated-", 0) == 0) {
      entry.model = aloft::bench::generated_model(std::stoi(key.substr(10)), 1);
    } else if (!aloft::bench::preset_exists(key)) {
      entry.error = "no preset " + aloft::bench::preset_path(key);
    } else {
      entry.model = aloft::bench::preset_model(key);
    }
  } catch (const std::exception& e) {
    entry.error = key + ": " + e.what();
  }
  return cache.emplace(key, std::move(entry)).first->second;
}

// items_per_second = steps per second; us_per_component_step from the CPU time of the timed loop
// (thread_seconds: seconds spent in the loop, measured by the caller around it).
void set_counters(benchmark::State& state, const Model& model, double loop_seconds) {
  state.SetItemsProcessed(state.iterations());
  state.counters["components"] = model.count;
  if (state.iterations() > 0)
    state.counters["us_per_component_step"] =
        loop_seconds * 1e6 / (static_cast<double>(state.iterations()) * (model.count - 1));
}

// The model for `key`, or nothing after marking the benchmark skipped (a missing preset).
const Model* model_or_skip(benchmark::State& state, const std::string& key) {
  const Entry& entry = model_entry(key);
  if (!entry.model) {
    state.SkipWithError(entry.error.c_str());
    for (auto _ : state) {
    }
  }
  return entry.model.get();
}

// Steps the mobile from the swinging state drawn with `seed` (aloft/state.hpp: swinging_state).
void BM_Step(benchmark::State& state, const std::string& key, bool collisions, std::uint64_t seed) {
  const Model* found = model_or_skip(state, key);
  if (!found) return;
  const Model& model = *found;
  aloft::Simulation sim(model, aloft::swinging_state(model, 0.5, seed));
  sim.set_collisions(collisions);
  const double start = aloft::thread_seconds();
  for (auto _ : state) {
    if (!sim.step()) {
      state.SkipWithError(sim.failure()->message.c_str());
      break;
    }
  }
  const double elapsed = aloft::thread_seconds() - start;
  benchmark::DoNotOptimize(sim.state().position.data());
  set_counters(state, model, elapsed);
  // How often a step was halved (step-size rule or unconverged joints) and the tree solves per step
  // (Newton corrections plus one velocity projection per (sub)step), as in aloft_step_profile.
  const double steps = static_cast<double>(state.iterations());
  if (steps > 0) {
    const double halvings = static_cast<double>(sim.subdivisions());
    state.counters["halvings"] = halvings / steps;
    state.counters["solves"] = (static_cast<double>(sim.joint_iterations()) + steps + halvings) / steps;
    const aloft::CollisionStatistics& contacts = sim.collision_statistics();
    if (collisions && contacts.law_solves > 0) {
      state.counters["law_solves"] = static_cast<double>(contacts.law_solves) / steps;
      state.counters["law_contacts"] =
          static_cast<double>(contacts.law_contacts) / static_cast<double>(contacts.law_solves);
    }
  }
}

void BM_Factor(benchmark::State& state, const std::string& key) {
  const Model* found = model_or_skip(state, key);
  if (!found) return;
  const Model& model = *found;
  const aloft::State pose = aloft::swinging_state(model);
  aloft::TreeSolver solver(model);
  const double start = aloft::thread_seconds();
  for (auto _ : state) {
    solver.factor(pose);
    benchmark::ClobberMemory();
  }
  set_counters(state, model, aloft::thread_seconds() - start);
}

void BM_Solve(benchmark::State& state, const std::string& key) {
  const Model* found = model_or_skip(state, key);
  if (!found) return;
  const Model& model = *found;
  const aloft::State pose = aloft::swinging_state(model);
  aloft::TreeSolver solver(model);
  solver.factor(pose);
  // Right-hand side: gravity on every body, a small gap at every joint.
  std::vector<aloft::Vec6> f(model.count, aloft::Vec6::Zero());
  std::vector<aloft::Vec3> c(model.count, aloft::Vec3::Zero());
  for (int i = 1; i < model.count; ++i) {
    f[i].head<3>() = model.mass[i] * model.gravity;
    c[i] = aloft::Vec3(1e-6, -2e-6, 3e-6);
  }
  std::vector<aloft::Vec6> u(model.count, aloft::Vec6::Zero());
  std::vector<aloft::Vec3> lambda(model.count, aloft::Vec3::Zero());
  const double start = aloft::thread_seconds();
  for (auto _ : state) {
    solver.solve(f, c, u, &lambda);
    benchmark::DoNotOptimize(u.data());
    benchmark::DoNotOptimize(lambda.data());
    benchmark::ClobberMemory();
  }
  set_counters(state, model, aloft::thread_seconds() - start);
}

// Loading: generate_mobile text -> parse_mobile_text -> compile, the whole path a 65535-component file
// takes before its first step (items_per_second = components loaded per second).
void BM_Load(benchmark::State& state, int components) {
  aloft::GenerateOptions options;
  options.components = components;
  options.seed = 1;
  const std::string text = aloft::generate_mobile(options);
  for (auto _ : state) {
    const aloft::Model model = aloft::compile(aloft::parse_mobile_text(text, "generated.json"));
    benchmark::DoNotOptimize(model.mass.data());
  }
  state.SetItemsProcessed(state.iterations() * components);
  state.counters["megabytes"] = static_cast<double>(text.size()) / 1e6;
}

void register_all() {
  for (int n : {1023, 65535})
    benchmark::RegisterBenchmark(("BM_Load/generated-" + std::to_string(n)).c_str(), BM_Load, n)
        ->Unit(benchmark::kMillisecond);
  std::vector<std::string> keys = kPresets;
  for (int n : kGenerated) keys.push_back("generated-" + std::to_string(n));
  for (const std::string& key : keys)
    benchmark::RegisterBenchmark(("BM_Step/" + key).c_str(), BM_Step, key, false, kSeed)
        ->Unit(benchmark::kMicrosecond);
  for (const std::string& key : keys)
    benchmark::RegisterBenchmark(("BM_StepCollisions/" + key).c_str(), BM_Step, key, true, kSeed)
        ->Unit(benchmark::kMicrosecond);
  for (const std::string& key : keys) {
    const int components = key.rfind("generated-", 0) == 0 ? std::stoi(key.substr(10)) : 10;
    for (const bool collisions : {false, true})
      benchmark::RegisterBenchmark(("BM_StepSpan/" + key + (collisions ? "/on" : "/off")).c_str(), BM_Step, key,
                                   collisions, kSeed)
          ->Iterations(aloft::bench::span_steps(components))
          ->Unit(benchmark::kMicrosecond);
  }
  // The generated mobiles' spans from more swinging states: a tangle's cost differs by half between
  // trajectories (docs/performance.md, "2026-12-06, fifth session"), and a change to the collisions
  // changes the trajectory, so one start cannot show a change of a few per cent.
  for (const int components : kGenerated) {
    if (components < 127 || components > 8191) continue;
    const std::string key = "generated-" + std::to_string(components);
    for (const std::uint64_t seed : kMoreSeeds)
      for (const bool collisions : {false, true})
        benchmark::RegisterBenchmark(
            ("BM_StepSpanSeeds/" + key + (collisions ? "/on" : "/off") + "/seed:" + std::to_string(seed)).c_str(),
            BM_Step, key, collisions, seed)
            ->Iterations(aloft::bench::span_steps(components))
            ->Unit(benchmark::kMicrosecond);
  }
  for (const std::string& key : keys)
    benchmark::RegisterBenchmark(("BM_Factor/" + key).c_str(), BM_Factor, key)->Unit(benchmark::kMicrosecond);
  for (const std::string& key : keys)
    benchmark::RegisterBenchmark(("BM_Solve/" + key).c_str(), BM_Solve, key)->Unit(benchmark::kMicrosecond);
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
