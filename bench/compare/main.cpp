// aloft_compare: Aloft against Bullet (btMultiBody, Featherstone) and ODE (dWorldStep, dWorldQuickStep)
// on the same mobiles, in one process.
//
//   1. Trajectories: every engine starts from the same swinging state (aloft/state.hpp) of the Steel
//      Fish (or a generated 15-component mobile); the largest distance over components between the
//      centres of mass of Aloft and each other engine at t = 0.1, 0.5, 1 s, at h = 1 ms and 0.1 ms, and
//      every engine's distance to Aloft at h = 0.01 ms (its own discretization error).
//   2. Cost and accuracy on generated mobiles of 15, 127, 1023, 8191 components (seed 1) and the Steel
//      Fish: CPU time per step (median of interleaved repetitions A B C A B C ...), per moving
//      component, relative to Aloft; and over `--seconds` of swinging from the same state, the energy
//      drift (end and largest, relative to the initial kinetic energy) and the largest joint separation.
//   3. Collisions (--collisions; Aloft and Bullet): the cost of a span from the swinging state with
//      collisions off and on, in each engine (issue 3's target is Aloft's on / off <= 2 up to 8191
//      components; docs/performance.md), with the contact points, the deepest overlap and the energy the
//      span ends with. Generated mobiles tangle (their pieces are packed within each other's reach), so
//      both engines meet knocks and resting contacts.
// All at h = 1 ms, one thread, no damping; no collisions but in 3.

#include <LinearMath/btScalar.h>
#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "aloft/thread_clock.hpp"
#include "bench_models.hpp"
#include "compare/engine.hpp"

namespace {

using aloft::Model;
using aloft::State;
using aloft::compare::Engine;

struct Options {
  std::vector<int> sizes = {15, 127, 1023, 8191};
  bool preset = true;
  int repetitions = 5;
  double seconds = 10;          // of swinging, for the energy drift and separations
  double budget = 0.2;          // s of CPU per timing sample and engine
  int ode_step_max = 200;       // dWorldStep is dense (O(m^3) in the m = 3(n-1) joint rows): larger is skipped
  double accuracy_max = 1e9;    // skip the drift run above this many components
  bool trajectory = true;
  bool table = true;
  bool collisions = false;                       // section 3
  std::vector<int> collision_sizes = {127, 1023};
  std::vector<int> collision_seeds = {7};        // of the swinging state (aloft/state.hpp)
  long long collision_steps = 0;                 // 0: BM_StepSpan's span for the size
  double bullet_contact_threshold = -1;          // gContactBreakingThreshold; < 0: Bullet's default
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

enum class Kind { Aloft, Bullet, OdeStep, OdeQuick };
const char* kind_name(Kind k) {
  switch (k) {
    case Kind::Aloft: return "Aloft";
    case Kind::Bullet: return "Bullet";
    case Kind::OdeStep: return "ODE step";
    case Kind::OdeQuick: return "ODE quick";
  }
  return "?";
}

// With `collisions` (Aloft and Bullet only; ODE is built without colliders).
std::unique_ptr<Engine> make(Kind kind, const Model& model, const State& initial, double h, bool collisions = false) {
  if (collisions && (kind == Kind::OdeStep || kind == Kind::OdeQuick))
    throw std::invalid_argument("aloft_compare builds ODE without colliders");
  switch (kind) {
    case Kind::Aloft: return aloft::compare::make_aloft(model, initial, h, collisions);
    case Kind::Bullet: return aloft::compare::make_bullet(model, initial, h, collisions);
    case Kind::OdeStep: return aloft::compare::make_ode(model, initial, h, false);
    case Kind::OdeQuick: return aloft::compare::make_ode(model, initial, h, true);
  }
  return nullptr;
}

double max_distance(const State& a, const State& b) {
  double worst = 0;
  for (size_t i = 1; i < a.position.size(); ++i) worst = std::max(worst, (a.position[i] - b.position[i]).norm());
  return worst;
}

// ---- 1. Trajectories -------------------------------------------------------------------------------

// Centres of mass at the sample times, stepping at h.
std::vector<State> sample_trajectory(Kind kind, const Model& model, const State& initial, double h,
                                     const std::vector<double>& times) {
  auto engine = make(kind, model, initial, h);
  std::vector<State> out;
  State s = initial;
  long long done = 0;
  for (double t : times) {
    const long long target = std::llround(t / h);
    for (; done < target; ++done) engine->step();
    engine->read(s);
    out.push_back(s);
  }
  return out;
}

void trajectories(const Model& model, const std::string& label) {
  const State initial = aloft::swinging_state(model);
  const std::vector<double> times = {0.1, 0.5, 1.0};
  const std::vector<Kind> kinds = {Kind::Aloft, Kind::Bullet, Kind::OdeStep, Kind::OdeQuick};
  std::printf("\n## Trajectories: %s (%d components), from the swinging state\n", label.c_str(), model.count);
  std::printf("Largest distance over components between centres of mass (m).\n\n");
  const std::vector<State> reference = sample_trajectory(Kind::Aloft, model, initial, 1e-5, times);
  std::printf("| h | compared | t = 0.1 s | t = 0.5 s | t = 1 s |\n|---|---|---|---|---|\n");
  for (double h : {1e-3, 1e-4}) {
    std::vector<std::vector<State>> runs;
    for (Kind k : kinds) runs.push_back(sample_trajectory(k, model, initial, h, times));
    auto row = [&](const std::string& what, const std::vector<State>& a, const std::vector<State>& b) {
      std::printf("| %g ms | %s |", h * 1e3, what.c_str());
      for (size_t t = 0; t < times.size(); ++t) std::printf(" %.2e |", max_distance(a[t], b[t]));
      std::printf("\n");
    };
    for (size_t k = 1; k < kinds.size(); ++k) row(std::string(kind_name(kinds[k])) + " - Aloft", runs[k], runs[0]);
    row("Bullet - ODE step", runs[1], runs[2]);
    for (size_t k = 0; k < kinds.size(); ++k)
      row(std::string(kind_name(kinds[k])) + " - Aloft at 0.01 ms", runs[k], reference);
  }
}

// ---- 2. Cost and accuracy --------------------------------------------------------------------------

struct Accuracy {
  bool run = false;
  double kinetic0 = 0;
  double drift_end = 0;    // (E(T) - E(0)) / KE(0)
  double drift_max = 0;    // max |E(t) - E(0)| / KE(0)
  double separation = 0;   // max over t of max_joint_separation (m)
  std::string error;
};

Accuracy accuracy(Kind kind, const Model& model, const State& initial, double seconds) {
  Accuracy a;
  a.run = true;
  try {
    auto engine = make(kind, model, initial, model.timestep);
    State s = initial;
    engine->read(s);
    const double e0 = aloft::kinetic_energy(model, s) + aloft::potential_energy(model, s);
    a.kinetic0 = aloft::kinetic_energy(model, s);
    a.separation = aloft::max_joint_separation(model, s);
    const long long steps = std::llround(seconds / model.timestep);
    const int every = 10;  // sample every 10 ms
    for (long long k = 1; k <= steps; ++k) {
      engine->step();
      if (k % every && k != steps) continue;
      engine->read(s);
      const double e = aloft::kinetic_energy(model, s) + aloft::potential_energy(model, s);
      if (!std::isfinite(e)) throw std::runtime_error("non-finite energy at step " + std::to_string(k));
      a.drift_max = std::max(a.drift_max, std::abs(e - e0) / a.kinetic0);
      a.drift_end = (e - e0) / a.kinetic0;
      a.separation = std::max(a.separation, aloft::max_joint_separation(model, s));
    }
  } catch (const std::exception& e) {
    a.error = e.what();
  }
  return a;
}

struct Row {
  Kind kind;
  std::unique_ptr<Engine> engine;
  long long steps_per_sample = 1;
  std::vector<double> samples;  // s per step
  std::string error;
  Accuracy acc;
};

// One table row per engine (printed as it is done); returns a note for below the table.
std::string cost_and_accuracy(const Model& model, const std::string& label, const Options& options) {
  const State initial = aloft::swinging_state(model);
  std::vector<Row> rows;
  for (Kind k : {Kind::Aloft, Kind::Bullet, Kind::OdeStep, Kind::OdeQuick}) {
    Row r;
    r.kind = k;
    if (k == Kind::OdeStep && model.count > options.ode_step_max) {
      r.error = "skipped (dense, > " + std::to_string(options.ode_step_max) + " components)";
    } else {
      try {
        r.engine = make(k, model, initial, model.timestep);
        // Calibrate: steps per sample so that one sample takes about `budget` seconds of CPU.
        const double t0 = aloft::thread_seconds();
        long long n = 0;
        do {
          r.engine->step();
          ++n;
        } while (aloft::thread_seconds() - t0 < 0.02);
        const double per_step = (aloft::thread_seconds() - t0) / n;
        r.steps_per_sample = std::clamp<long long>(std::llround(options.budget / per_step), 1, 1000000);
      } catch (const std::exception& e) {
        r.error = e.what();
        r.engine.reset();
      }
    }
    rows.push_back(std::move(r));
  }
  // Interleaved repetitions: Aloft, Bullet, ODE step, ODE quick, Aloft, ...
  std::fprintf(stderr, "[%s] timing, %d repetitions\n", label.c_str(), options.repetitions);
  for (int rep = 0; rep < options.repetitions; ++rep) {
    for (Row& r : rows) {
      if (!r.engine) continue;
      try {
        const double t0 = aloft::thread_seconds();
        for (long long k = 0; k < r.steps_per_sample; ++k) r.engine->step();
        r.samples.push_back((aloft::thread_seconds() - t0) / r.steps_per_sample);
      } catch (const std::exception& e) {
        r.error = e.what();
        r.engine.reset();
      }
    }
  }
  for (Row& r : rows) r.engine.reset();
  if (model.count <= options.accuracy_max)
    for (Row& r : rows)
      if (r.error.empty()) {
        std::fprintf(stderr, "[%s] %s: %g s of swinging\n", label.c_str(), kind_name(r.kind), options.seconds);
        r.acc = accuracy(r.kind, model, initial, options.seconds);
      }

  const double aloft_step = rows[0].samples.empty() ? NAN : median(rows[0].samples);
  for (const Row& r : rows) {
    std::printf("| %s | %d | %s |", label.c_str(), model.count, kind_name(r.kind));
    if (r.samples.empty()) {
      std::printf(" %s | | | | | | |\n", r.error.c_str());
      std::fflush(stdout);
      continue;
    }
    const double step = median(r.samples);
    std::printf(" %.1f | %.3f | %.2f |", step * 1e6, step * 1e6 / (model.count - 1), step / aloft_step);
    if (!r.acc.run) {
      std::printf(" not run | | |\n");
    } else if (!r.acc.error.empty()) {
      std::printf(" failed: %s | | |\n", r.acc.error.c_str());
    } else {
      std::printf(" %+.1e | %.1e | %.1e |\n", r.acc.drift_end, r.acc.drift_max, r.acc.separation);
    }
    std::fflush(stdout);
  }
  std::ostringstream note;
  note << label << ": initial kinetic energy " << aloft::kinetic_energy(model, initial) << " J; steps per timing sample:";
  for (const Row& r : rows)
    if (!r.samples.empty()) note << " " << kind_name(r.kind) << " " << r.steps_per_sample;
  return note.str();
}

// ---- 3. Collisions ---------------------------------------------------------------------------------

struct SpanRun {
  double step = NAN;           // s of thread CPU per step
  double points = 0;           // contact points per step (the engine's own count)
  double deepest = 0;          // m
  double energy_change = 0;    // (E(end) - E(0)) / KE(0)
  std::string error;
};

SpanRun run_span(Kind kind, const Model& model, const State& initial, long long steps, bool collisions,
                 const std::string& label) {
  SpanRun r;
  try {
    auto engine = make(kind, model, initial, model.timestep, collisions);
    State s = initial;
    engine->read(s);
    const double kinetic0 = aloft::kinetic_energy(model, s);
    const double energy0 = kinetic0 + aloft::potential_energy(model, s);
    long long points = 0;
    const long long report_every = std::max<long long>(1, steps / 5);
    // The span is timed whole (the clock is a system call, read only here and at the progress reports):
    // counting the contact points is a read of a number the step kept.
    const double start = aloft::thread_seconds();
    for (long long k = 1; k <= steps; ++k) {
      engine->step();
      points += engine->contact_points();
      if (k % report_every == 0)
        std::fprintf(stderr, "[%s] %s %s: %lld of %lld steps, %.1f us per step so far\n", label.c_str(),
                     kind_name(kind), collisions ? "on" : "off", k, steps,
                     1e6 * (aloft::thread_seconds() - start) / k);
    }
    const double seconds = aloft::thread_seconds() - start;
    engine->read(s);
    r.step = seconds / steps;
    r.points = static_cast<double>(points) / steps;
    r.deepest = engine->deepest_overlap();
    r.energy_change = (aloft::kinetic_energy(model, s) + aloft::potential_energy(model, s) - energy0) / kinetic0;
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  return r;
}

// One row per engine: off, then on, one run each (a span is seconds to minutes, and with collisions
// the motion is chaotic, so the seeds, not repetitions, are what to vary).
void collision_cost(const Model& model, const std::string& label, int seed, long long steps) {
  const State initial = aloft::swinging_state(model, 0.5, static_cast<std::uint64_t>(seed));
  const std::string run = label + " seed " + std::to_string(seed);
  for (Kind kind : {Kind::Aloft, Kind::Bullet}) {
    const SpanRun off = run_span(kind, model, initial, steps, false, run);
    const SpanRun on = run_span(kind, model, initial, steps, true, run);
    std::printf("| %s | %d | %d | %s | %lld |", label.c_str(), model.count, seed, kind_name(kind), steps);
    if (!off.error.empty() || !on.error.empty()) {
      std::printf(" failed: %s | | | | | |\n", (off.error.empty() ? on.error : off.error).c_str());
    } else {
      std::printf(" %.1f | %.1f | %.2f | %.1f | %.3f | %+.2e |\n", off.step * 1e6, on.step * 1e6, on.step / off.step,
                  on.points, on.deepest * 1e3, on.energy_change);
    }
    std::fflush(stdout);
  }
}

// ---- Command line ----------------------------------------------------------------------------------

std::vector<int> parse_sizes(const std::string& text) {
  std::vector<int> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(std::stoi(item));
  return out;
}

void usage() {
  std::printf(
      "usage: aloft_compare [--sizes 15,127,1023,8191] [--no-preset] [--reps 5] [--seconds 10]\n"
      "                     [--budget 0.2] [--ode-step-max 200] [--accuracy-max N]\n"
      "                     [--no-trajectory] [--no-table]\n"
      "                     [--collisions [--collision-sizes 127,1023] [--collision-seeds 7]\n"
      "                      [--collision-steps N] [--bullet-contact-threshold M]]\n"
      "  --collisions: also time a span from the swinging state with collisions off and on, in Aloft\n"
      "    and Bullet (N steps; default BM_StepSpan's: 10000 up to 127 components, 5000 up to 1023,\n"
      "    2000 up to 8191, bench_models.hpp span_steps); M: Bullet's gContactBreakingThreshold (default its own, 0.02)\n");
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    try {
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) {
          usage();
          std::exit(2);
        }
        return argv[++i];
      };
      if (arg == "--sizes") options.sizes = parse_sizes(value());
      else if (arg == "--no-preset") options.preset = false;
      else if (arg == "--reps") options.repetitions = std::stoi(value());
      else if (arg == "--seconds") options.seconds = std::stod(value());
      else if (arg == "--budget") options.budget = std::stod(value());
      else if (arg == "--ode-step-max") options.ode_step_max = std::stoi(value());
      else if (arg == "--accuracy-max") options.accuracy_max = std::stod(value());
      else if (arg == "--no-trajectory") options.trajectory = false;
      else if (arg == "--no-table") options.table = false;
      else if (arg == "--collisions") options.collisions = true;
      else if (arg == "--collision-sizes") options.collision_sizes = parse_sizes(value());
      else if (arg == "--collision-seeds") options.collision_seeds = parse_sizes(value());
      else if (arg == "--collision-steps") options.collision_steps = std::stoll(value());
      else if (arg == "--bullet-contact-threshold") options.bullet_contact_threshold = std::stod(value());
      else {
        usage();
        return arg == "--help" || arg == "-h" ? 0 : 2;
      }
    } catch (const std::logic_error&) {  // std::stoi and friends: not a number, or out of range
      std::fprintf(stderr, "aloft_compare: %s takes a number (a comma-separated list for the sizes and seeds), not '%s'\n",
                   arg.c_str(), argv[i]);
      return 2;
    }
  }

  try {
    std::printf("# aloft_compare\n\n%s\nBullet %d (double precision btMultiBody, spherical joints).\n",
                aloft::compare::ode_configuration().c_str(), btGetVersion());
    std::printf("h = 1 ms, one thread, no damping, no collisions (but in the collisions section); time = thread "
                "CPU time per step, median of "
                "%d interleaved repetitions.\n",
                options.repetitions);

    const bool fish = options.preset && aloft::bench::preset_exists("steel-fish");
    std::unique_ptr<Model> fish_model;
    if (fish) fish_model = aloft::bench::preset_model("steel-fish");

    if (options.trajectory) {
      if (fish_model) {
        trajectories(*fish_model, "steel-fish");
      } else {
        auto m = aloft::bench::generated_model(15, 1);
        trajectories(*m, "generated-15 (no steel-fish preset)");
      }
    }

    if (options.table) {
      std::printf("\n## Cost and accuracy (%g s of swinging for the energy and separation columns)\n\n",
                  options.seconds);
      std::printf("| mobile | comps | engine | us/step | us/comp-step | x Aloft | dE(end)/KE0 | max|dE|/KE0 | "
                  "max sep (m) |\n|---|---|---|---|---|---|---|---|---|\n");
      std::fflush(stdout);
      std::vector<std::string> notes;
      for (int n : options.sizes) {
        std::fprintf(stderr, "[generated-%d] generating and compiling\n", n);
        auto m = aloft::bench::generated_model(n, 1);
        notes.push_back(cost_and_accuracy(*m, "generated-" + std::to_string(n), options));
      }
      if (fish_model) notes.push_back(cost_and_accuracy(*fish_model, "steel-fish", options));
      std::printf("\n");
      for (const std::string& note : notes) std::printf("- %s\n", note.c_str());
    }

    if (options.collisions) {
      if (options.bullet_contact_threshold >= 0) gContactBreakingThreshold = options.bullet_contact_threshold;
      std::printf("\n## Collisions: a span from the swinging state, off and on (Bullet's contact breaking "
                  "threshold %g)\n\n",
                  static_cast<double>(gContactBreakingThreshold));
      std::printf("Thread CPU time per step over the whole span, one run each; contact points per step with "
                  "collisions on (each engine's own count); the deepest overlap seen; the energy at the "
                  "span's end against its start, over the initial kinetic energy.\n\n");
      std::printf("| mobile | comps | seed | engine | steps | off us/step | on us/step | on / off | contact "
                  "points per step | deepest overlap (mm) | dE(end)/KE0, on |\n"
                  "|---|---|---|---|---|---|---|---|---|---|---|\n");
      std::fflush(stdout);
      for (int n : options.collision_sizes) {
        auto m = aloft::bench::generated_model(n, 1);
        const long long steps = options.collision_steps > 0 ? options.collision_steps : aloft::bench::span_steps(n);
        for (int seed : options.collision_seeds)
          collision_cost(*m, "generated-" + std::to_string(n), seed, steps);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "aloft_compare: %s\n", e.what());
    return 1;
  }
  return 0;
}
