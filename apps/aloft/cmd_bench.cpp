// aloft bench: simulation speed (steps per second) on the preset mobiles and on generated mobiles of
// growing size, without collisions (issue 2's figure) and with them (issue 3's), in the same run. Each
// mobile is set swinging once, by a breeze (0.2 g for 300 steps, collisions on) or, with --start
// swinging[:SEED], by the benchmarks' swinging state (aloft/state.hpp: swinging_state), and both figures
// are timed from that same state, each over 5 repetitions (--repetitions) of enough steps for at least
// 0.5 s (or --steps); the median is reported. One start for both, as in BM_StepSpan, and a start that
// does not depend on the machine (each column used to get a breeze of its own, cut short after 0.3 s of
// CPU time). The two runs still part from there: without collisions the pieces pass through each other
// and keep the energy the knocks would take (the footer below says so to the user). With --start
// swinging:SEED --repetitions 1 --steps N the collisions-on over collisions-off ratio is issue 3's
// measure, BM_StepSpan's, for that start and span. With --wind V0 (and --start rest) the steps are timed
// in the paper's wind, the wind's own work left out: the mobile as it moves in its main use.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <thread>

#include "aloft/bench_start.hpp"
#include "aloft/blown_steps.hpp"
#include "aloft/generate.hpp"
#include "aloft/model.hpp"
#include "aloft/simulation.hpp"
#include "aloft/state.hpp"
#include "aloft/thread_clock.hpp"
#include "common.hpp"
#include "progress.hpp"
#include "wind_options.hpp"

#ifndef ALOFT_BUILD_TYPE
#define ALOFT_BUILD_TYPE "unknown"
#endif

namespace aloft::cli {

namespace {

// CPU seconds this thread has used since `start` (a thread_seconds() reading).
double cpu_seconds_since(double start) { return thread_seconds() - start; }

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0 || line.rfind("Model", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) {
        std::string s = line.substr(colon + 1);
        s.erase(0, s.find_first_not_of(" \t"));
        if (!s.empty()) return s;
      }
    }
  }
  return "unknown CPU";
}

struct Measurement {
  double steps_per_second = 0;
  double subdivided = 0;  // step halvings per timed step (0: no step had to be divided for a fast spin)
  double solves = 0;      // tree solves per timed step (joint corrections + velocity projections)
  long long steps_per_repetition = 0;
  std::string failure;  // non-empty if the simulation failed
};

std::string failure_of(const Simulation& sim) {
  return sim.failure() ? sim.failure()->message : std::string("the simulation failed");
}

// Where both timed runs of a mobile start (--start, aloft/bench_start.hpp), for the report's header.
std::string describe(const BenchStart& start) {
  switch (start.from) {
    case BenchStart::From::kSwinging:
      return format("the swinging state of seed %llu (as BM_StepSpan)", static_cast<unsigned long long>(start.seed));
    case BenchStart::From::kRest:
      return "the designed pose at rest";
    case BenchStart::From::kBreeze:
      break;
  }
  return format("%d steps of a breeze with collisions on", kBreezeSteps);
}

// The state both timed runs of a mobile start from: the designed pose at rest, pushed for kBreezeSteps
// steps by a horizontal 0.2 g on every component (its direction turning by the golden angle from one
// component to the next), with collisions on, as the mobile would move in a room's draught (a balanced
// mobile at rest would be an unrepresentatively easy case). Empty, with `failure` set, if the
// simulation failed. Shows its progress on a terminal: the largest mobiles take seconds.
std::optional<State> breeze_start(const Model& model, const std::string& name, std::string& failure) {
  Simulation sim(model);
  sim.set_collisions(true);
  set_breeze(model, sim.loads());
  ProgressReport progress(is_terminal(stderr), kBreezeSteps, name + ": breeze", 1.0);  // the table stays clean
  for (int s = 1; s <= kBreezeSteps; ++s) {
    if (!sim.step()) {
      progress.finish();
      failure = "in the breeze: " + failure_of(sim);
      return std::nullopt;
    }
    if (progress.due(s)) progress.show(s, format("step %d of %d", s, kBreezeSteps));
  }
  progress.finish();
  return sim.state();
}

// The timing both ways: `repetitions` runs of `fixed_steps` steps each (or, if it is 0, enough for 0.5 s),
// one after another from the start; the median rate is reported. With a wind (v0 > 0, m/s) every step
// is blown by it, placed as `aloft simulate --wind V0` places it, and its own work (occlusion and loads)
// is left out of the figures (BlownSteps, aloft/blown_steps.hpp).
struct Timing {
  long long fixed_steps = 0;
  int repetitions = 5;
  double wind = 0;
};

Measurement measure(const Model& model, const State& start, const Timing& timing, bool collisions) {
  const long long fixed_steps = timing.fixed_steps;
  Measurement out;
  Simulation sim(model, start);
  sim.set_collisions(collisions);
  BlownSteps blown(model, sim, timing.wind);
  out.steps_per_repetition = fixed_steps;
  if (fixed_steps <= 0) {
    // Enough steps for 0.5 s at the rate of a few calibration steps (re-measured below if the first
    // repetition is much shorter).
    constexpr long long kCalibrationSteps = 3;
    const double calibration_start = thread_seconds();
    const double calibration_wind = blown.wind_seconds();
    for (long long s = 0; s < kCalibrationSteps; ++s) {
      if (!blown.step()) {
        out.failure = failure_of(sim);
        return out;
      }
    }
    const double rate = static_cast<double>(kCalibrationSteps) /
                        std::max(cpu_seconds_since(calibration_start) - (blown.wind_seconds() - calibration_wind), 1e-9);
    out.steps_per_repetition = std::max(3LL, static_cast<long long>(std::ceil(0.5 * rate)));
  }

  std::vector<double> rates;
  const long long subdivisions_before = sim.subdivisions();
  const long long iterations_before = sim.joint_iterations();
  const long long steps_before = sim.step_count();
  for (int r = 0; r < timing.repetitions; ++r) {
    const double repetition_start = thread_seconds();
    const double repetition_wind = blown.wind_seconds();
    for (long long s = 0; s < out.steps_per_repetition; ++s) {
      if (!blown.step()) {
        out.failure = failure_of(sim);
        return out;
      }
    }
    const double elapsed =
        std::max(cpu_seconds_since(repetition_start) - (blown.wind_seconds() - repetition_wind), 1e-9);
    rates.push_back(static_cast<double>(out.steps_per_repetition) / elapsed);
    // Keep a too-short calibration from making the repetitions short: re-measure at >= 0.5 s.
    if (r == 0 && fixed_steps <= 0 && elapsed < 0.4) {
      out.steps_per_repetition = std::max(3LL, static_cast<long long>(std::ceil(0.5 * rates.back())));
      rates.clear();
      r = -1;
    }
  }
  std::sort(rates.begin(), rates.end());
  const std::size_t middle = rates.size() / 2;
  out.steps_per_second = rates.size() % 2 == 1 ? rates[middle] : 0.5 * (rates[middle - 1] + rates[middle]);
  const double steps = static_cast<double>(std::max(1LL, sim.step_count() - steps_before));
  const double subdivided = static_cast<double>(sim.subdivisions() - subdivisions_before);
  out.subdivided = subdivided / steps;
  // Every accepted (sub)step makes one velocity projection; a halving turns one step into two.
  out.solves = (static_cast<double>(sim.joint_iterations() - iterations_before) + steps + subdivided) / steps;
  return out;
}

// One line: the collision-free figures, then those with collisions on (same mobile, same warm-up).
void print_row(const std::string& name, int components, const Measurement& free, const Measurement& with) {
  const int moving = std::max(1, components - 1);
  if (!free.failure.empty()) {
    std::printf("%-20s %6d  failed: %s\n", name.c_str(), components, free.failure.c_str());
  } else {
    const double us = 1e6 / free.steps_per_second;
    std::printf("%-20s %6d %11.1f %10.2f %8.4f %6.2f %6.2f", name.c_str(), components, free.steps_per_second, us,
                us / moving, free.subdivided, free.solves);
    if (!with.failure.empty()) {
      std::printf("   with collisions failed: %s\n", with.failure.c_str());
    } else {
      const double us_with = 1e6 / with.steps_per_second;
      std::printf(" | %10.2f %8.4f %6.2f %6.2f\n", us_with, us_with / moving, with.subdivided, us_with / us);
    }
  }
  std::fflush(stdout);
}

// Sets the mobile swinging, times it both ways from there and prints its line.
void bench_mobile(const Model& model, const std::string& name, const BenchStart& how, const Timing& timing) {
  std::string failure;
  const std::optional<State> start = how.from == BenchStart::From::kSwinging ? swinging_state(model, 0.5, how.seed)
                                     : how.from == BenchStart::From::kRest   ? rest_state(model)
                                                                              : breeze_start(model, name, failure);
  if (!start) {
    std::printf("%-20s %6d  failed: %s\n", name.c_str(), model.count, failure.c_str());
    std::fflush(stdout);
    return;
  }
  print_row(name, model.count, measure(model, *start, timing, false), measure(model, *start, timing, true));
}

}  // namespace

Runner add_bench(CLI::App& app) {
  struct Options {
    long long steps = 0;
    int repetitions = 5;
    std::vector<int> sizes{15, 127, 1023, 8191, 65535};
    std::string presets;
    std::string start = "breeze";
    double wind = 0;
  };
  auto o = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "bench",
      "Measure simulation speed on the preset mobiles and on generated ones, without and with collisions");
  sub->add_option("--steps", o->steps, "Steps per repetition (>= 1; default: enough for 0.5 s)")
      ->type_name("N")
      ->check(integer_in(1, 1000000000));
  sub->add_option("--repetitions", o->repetitions, "Timed runs per figure, one after another; the median is reported (default 5)")
      ->type_name("R")
      ->check(integer_in(1, 1000));
  sub->add_option("--start", o->start,
                  "Where both runs start: 'breeze' (default: 300 steps of a 0.2 g breeze, collisions on), "
                  "'swinging' / 'swinging:SEED' (the benchmarks' swinging state; seed 7 if not given), or 'rest' "
                  "(the designed pose)")
      ->type_name("FROM")
      ->check(CLI::Validator(
          [](std::string& input) -> std::string {
            return parse_bench_start(input) ? std::string()
                                      : "must be 'breeze', 'rest', 'swinging' or 'swinging:SEED' (SEED a whole "
                                        "number), got \"" +
                                            input + "\"";
          },
          ""));
  sub->add_option("--wind", o->wind,
                  "Blow every timed step with a steady wind, speed v0 at S0 (m/s, 0 to 100), placed as by "
                  "'aloft simulate --wind'; the wind's own work is left out of the figures (default: none)")
      ->type_name("V0")
      ->check(wind_speed());
  sub->add_option("--sizes", o->sizes, "Sizes (components, hook included) of the generated mobiles, comma-separated (each >= 2; default 15,127,1023,8191,65535)")
      ->type_name("N,...")
      ->delimiter(',')
      ->check(integer_in(2, 1 << 24));
  sub->add_option("--presets", o->presets, "Directory of the preset mobiles (default: the source tree's mobiles/)")
      ->type_name("DIR");
  sub->footer(
      "Prints steps per second, microseconds per step and per moving component per step for the preset\n"
      "mobiles (steel-fish.json and southern-cross.json; a missing one is skipped with a note) and for\n"
      "generated mobiles (seed 1), first with collisions off, then (right of the bar) with collisions on.\n"
      "Each mobile is set swinging once, by a breeze (0.2 g for 300 steps, collisions on) or, with\n"
      "--start swinging[:SEED], from the benchmarks' swinging state (every component turning at 0.25-0.5\n"
      "rad/s in a random direction drawn from SEED, 7 if not given). Both are timed (thread CPU time) from\n"
      "that same state, over 5 repetitions (--repetitions) of at least 0.5 s (or --steps steps) one after\n"
      "another, and the median is reported. \"halv\" counts how often per step the step had to be halved\n"
      "because something spun too fast for it; \"solves\" the tree solves per step (joint corrections and\n"
      "velocity projections); \"ratio\" the time per step with collisions over without.\n"
      "The two columns start from the same state but do not stay in the same motion: without collisions\n"
      "pieces pass through each other and keep the energy knocks would take. After the breeze light bars\n"
      "then spin and halve the step (compare \"halv\"), so the default start's ratio is not issue 3's\n"
      "measure. That is the benchmarks' BM_StepSpan: one span from the swinging state, timed whole, e.g.\n"
      "5000 steps at 1023 components (docs/performance.md); --start swinging:SEED --repetitions 1\n"
      "--steps N gives it for one start.\n"
      "With --wind V0 every timed step is blown by a steady wind placed as 'aloft simulate --wind V0' places\n"
      "it; the wind's own work (occlusion and loads, timed apart by the same clock) is left out, what it\n"
      "costs the step (its data pushed out of the caches) is not. With --start rest the wind alone sets\n"
      "the mobile moving, as in its main use.\n"
      "\n"
      "Examples:\n"
      "  aloft bench\n"
      "  aloft bench --sizes 15,127 --steps 2000\n"
      "  aloft bench --presets ~/aloft/mobiles --sizes 1023\n"
      "  aloft bench --sizes 1023 --start swinging:1 --repetitions 1 --steps 5000   # issue 3's measure\n"
      "  aloft bench --sizes 127,1023 --start rest --wind 3 --repetitions 1 --steps 3000   # in a breath\n");
  return [o] {
    namespace fs = std::filesystem;
    const BenchStart start = *parse_bench_start(o->start);  // checked by the option's validator
    const Timing timing{o->steps, o->repetitions, o->wind};
    const std::string dir = o->presets.empty() ? (fs::path(source_dir()) / "mobiles").string() : o->presets;
    std::printf("aloft bench: %s, %u cores; build %s\n", cpu_model().c_str(), std::thread::hardware_concurrency(),
                ALOFT_BUILD_TYPE);
    std::printf("thread CPU time, median of %d repetition%s of %s; both columns from the same start,\n%s%s\n\n",
                timing.repetitions, timing.repetitions == 1 ? "" : "s",
                o->steps > 0 ? format("%lld steps", o->steps).c_str() : "at least 0.5 s", describe(start).c_str(),
                timing.wind > 0 ? format(", in a steady wind of v0 = %g m/s (its own work left out)", timing.wind).c_str()
                                : "");
    std::printf("%-27s %-46s | %s\n", "", "collisions off (issue 2)", "collisions on (issue 3)");
    std::printf("%-20s %6s %11s %10s %8s %6s %6s | %10s %8s %6s %6s\n", "mobile", "comps", "steps/s", "us/step",
                "us/comp", "halv", "solves", "us/step", "us/comp", "halv", "ratio");
    std::fflush(stdout);
    std::vector<std::string> notes;
    for (const char* preset : {"steel-fish.json", "southern-cross.json"}) {
      const fs::path path = fs::path(dir) / preset;
      std::error_code ec;
      if (!fs::is_regular_file(path, ec)) {
        notes.push_back(std::string(preset) + " skipped: " + path.string() + " not found");
        continue;
      }
      try {
        bench_mobile(load_mobile(path.string()), preset, start, timing);
      } catch (const std::exception& e) {
        notes.push_back(std::string(preset) + " skipped: " + e.what());
      }
    }
    for (int n : o->sizes) {
      GenerateOptions g;
      g.components = n;
      g.seed = 1;
      bench_mobile(compile(parse_mobile_text(generate_mobile(g), format("generated-%d.json", n))),
                   "generated (seed 1)", start, timing);
    }
    if (!notes.empty()) {
      std::printf("\n");
      for (const std::string& n : notes) std::printf("note: %s\n", n.c_str());
    }
    return kExitOk;
  };
}

static const CommandRegistration registration{"bench", 90, add_bench};

}  // namespace aloft::cli
