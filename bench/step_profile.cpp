// aloft_step_profile: a fixed, repeatable stepping run for profilers (valgrind --tool=callgrind counts
// instructions deterministically, so two builds can be compared on a busy machine) and a quick CPU-time
// figure. The mobile is set swinging by the same breeze as `aloft bench` (0.2 g for 300 steps), or
// starts from the benchmarks' swinging state (aloft/state.hpp: swinging_state, as BM_Step and
// BM_StepSpan do) or from rest (one step is taken first for those two, for the first factorization),
// then `steps` steps are taken inside timed_steps(), the function to give callgrind's --toggle-collect.
//
//   aloft_step_profile [--every N] [--record-law FILE [--record-every N] [--record-min M]] [--wind V0]
//                      MOBILE STEPS [collisions 0|1] [rest|breeze|swinging[:SEED]] [joint tolerance, m]
//     --every N: also print, after every N steps, the same figures for those N steps alone (how a run's
//       cost changes along it: a generated mobile with collisions tangles, and its late steps cost many
//       times its early ones; docs/performance.md), with the energy, the fastest spin and the deepest
//       overlap at the block's end
//     --record-law FILE: write the contact law's solves of the timed steps to FILE
//       (aloft/contact_law_record.hpp), to be solved again by aloft_law_replay: every N-th (default 1) of
//       those with M contacts or more (default 1)
//     --wind V0: the steps after the start (the first one included) blown by the paper's wind, v0 m/s
//       steady, placed as `aloft bench --wind` places it (aloft/blown_steps.hpp: the mobile as it moves in
//       its main use); the wind's own work is timed apart and printed, not counted in the step's figures
//     MOBILE: a mobile file (.json) or a component count for generate_mobile (seed 1)
//     SEED: of the swinging state's random spins (default 7, the benchmarks'); with collisions on, the
//       knocks make the motion chaotic, so comparing two builds over a few seeds says more than over one
//     joint tolerance: Simulation::set_joint_tolerance for the timed steps (default: the step's rule)
//
// The swinging start costs no breeze, so the largest mobiles can be run under callgrind's cache
// simulation (--cache-sim=yes) in minutes.
//
// Prints the thread CPU time per step and per moving component-step, the step halvings and tree solves
// per step, and a checksum of the final state (equal on two runs of one build); then, per step, how the
// (sub)steps went (Simulation::step_statistics): the tries and those taken, the rejections by their
// cause, the Newton corrections by phase, the contact passes (and how many bodies the sparse ones drift)
// and overlap pushes, and, with collisions
// on, the (sub)steps whose contact law dropped friction (CollisionStatistics::friction_dropped) and those
// that dropped it at some contacts only (friction_dropped_in_part), the contact law's solves, their size
// (contacts per solve: the law and the collision matrix cost O(m^2) in it) and sweeps, and the closing
// contacts left unsolved beyond ContactResponse::kMaxContacts (CollisionStatistics::law_solves ...), all
// of the (sub)steps taken.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <optional>
#include <string>
#include <utility>

#include "aloft/bench_start.hpp"
#include "aloft/blown_steps.hpp"
#include "aloft/contact_law_record.hpp"
#include "aloft/model.hpp"
#include "aloft/simulation.hpp"
#include "aloft/state.hpp"
#include "aloft/thread_clock.hpp"
#include "bench_models.hpp"

namespace {

// The steps callgrind's --toggle-collect times, each blown first when there is a wind (its work timed
// apart by BlownSteps).
__attribute__((noinline)) bool timed_steps(aloft::BlownSteps& steps_of, long steps) {
  for (long k = 0; k < steps; ++k)
    if (!steps_of.step()) return false;
  return true;
}

// What the simulation counted at one point of a run (Simulation::step_statistics and
// collision_statistics); print_rates gives the differences between two, per step.
struct Counts {
  aloft::StepStatistics steps;
  aloft::CollisionStatistics collisions;
};

Counts counts_of(const aloft::Simulation& sim) { return {sim.step_statistics(), sim.collision_statistics()}; }

// Prints the per-step figures of `steps` steps between `before` and `after`, each line starting with
// `indent`.
void print_rates(const char* indent, const Counts& before, const Counts& after, long steps) {
  using aloft::StepStatistics;
  using aloft::CollisionStatistics;
  const auto per_step = [&](long long StepStatistics::*count) {
    return static_cast<double>(after.steps.*count - before.steps.*count) / steps;
  };
  const auto collision_count = [&](long long CollisionStatistics::*count) {
    return static_cast<double>(after.collisions.*count - before.collisions.*count);
  };
  std::printf("%sper step: %.3f (sub)steps tried, %.3f taken, %.3f kicks retried; rejected: %.3f spin (turn %.3f, anchor "
              "%.3f, drift %.3f over), %.3f contact turn, %.3f joints, %.3f contact motion\n",
              indent, per_step(&StepStatistics::attempts), per_step(&StepStatistics::accepted),
              per_step(&StepStatistics::kicks_retried), per_step(&StepStatistics::rejected_spin),
              per_step(&StepStatistics::spin_turn_over), per_step(&StepStatistics::spin_anchor_over),
              per_step(&StepStatistics::spin_drift_over), per_step(&StepStatistics::rejected_contact_turn),
              per_step(&StepStatistics::rejected_joints), per_step(&StepStatistics::rejected_contact_motion));
  const double sparse = per_step(&StepStatistics::sparse_corrections);
  const double sparse_passes = per_step(&StepStatistics::sparse_contact_passes);
  std::printf("%sper step: Newton corrections %.3f after the drift, %.3f after contact passes, %.3f under "
              "pushes (%.3f of them sparse, visiting %.0f bodies each); %.3f contact passes (%.3f of them "
              "sparse, drifting %.0f bodies each), %.3f pushes, %.3f friction dropped (and %.3f at some contacts), "
              "%.2f contact impulses\n",
              indent, per_step(&StepStatistics::joint_corrections), per_step(&StepStatistics::contact_pass_corrections),
              per_step(&StepStatistics::push_corrections), sparse,
              sparse > 0 ? per_step(&StepStatistics::sparse_bodies) / sparse : 0.0,
              per_step(&StepStatistics::contact_passes), sparse_passes,
              sparse_passes > 0 ? per_step(&StepStatistics::sparse_contact_pass_bodies) / sparse_passes : 0.0,
              per_step(&StepStatistics::pushes),
              collision_count(&CollisionStatistics::friction_dropped) / steps,
              collision_count(&CollisionStatistics::friction_dropped_in_part) / steps,
              collision_count(&CollisionStatistics::impulses) / steps);
  const double solves = collision_count(&CollisionStatistics::law_solves);
  std::printf("%sper step: %.3f contact-law solves, for %.1f contacts and %.1f sweeps each; %.3f closing contacts "
              "left unsolved (beyond the most a solve takes)\n",
              indent, solves / steps, solves > 0 ? collision_count(&CollisionStatistics::law_contacts) / solves : 0.0,
              solves > 0 ? collision_count(&CollisionStatistics::law_sweeps) / solves : 0.0,
              collision_count(&CollisionStatistics::contacts_left) / steps);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace aloft;
  long every = 0;  // --every N: steps per block of the per-block report (0: none)
  std::string record_path;  // --record-law FILE: the contact law's solves written there
  long record_every = 1, record_min = 1;  // --record-every N, --record-min M
  double wind_v0 = 0;  // --wind V0: the timed steps in the paper's wind (m/s; 0: none)
  while (argc > 2 && std::string(argv[1]).starts_with("--")) {
    const std::string option = argv[1];
    const auto whole = [&](long& value) {
      char* end = nullptr;
      value = std::strtol(argv[2], &end, 10);
      if (*argv[2] != '\0' && *end == '\0' && value > 0) return true;
      std::fprintf(stderr, "aloft_step_profile: %s takes a whole number > 0, not '%s'\n", option.c_str(), argv[2]);
      return false;
    };
    if (option == "--every") {
      if (!whole(every)) return 2;
    } else if (option == "--record-every") {
      if (!whole(record_every)) return 2;
    } else if (option == "--record-min") {
      if (!whole(record_min)) return 2;
    } else if (option == "--record-law") {
      record_path = argv[2];
    } else if (option == "--wind") {
      char* end = nullptr;
      wind_v0 = std::strtod(argv[2], &end);
      if (*argv[2] == '\0' || *end != '\0' || !acceptable_wind_speed(wind_v0) || wind_v0 == 0) {
        std::fprintf(stderr, "aloft_step_profile: --wind takes a speed v0 in m/s, above 0 and at most %g, not '%s'\n",
                     kFastestWind, argv[2]);
        return 2;
      }
    } else {
      std::fprintf(stderr, "aloft_step_profile: unknown option '%s'\n", option.c_str());
      return 2;
    }
    argc -= 2;
    argv += 2;
  }
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: aloft_step_profile [--every N] [--record-law FILE [--record-every N] [--record-min M]] "
                 "[--wind V0] MOBILE(.json or component count) STEPS [collisions 0|1] [rest|breeze|swinging[:SEED]] "
                 "[joint tolerance, m]\n");
    return 2;
  }
  const std::string what = argv[1];
  const long steps = std::atol(argv[2]);
  const bool collisions = argc > 3 && std::atoi(argv[3]) != 0;
  const std::string start_name = argc > 4 ? argv[4] : "breeze";
  const std::optional<BenchStart> start = parse_bench_start(start_name);
  if (!start) {
    std::fprintf(stderr,
                 "aloft_step_profile: the start is 'rest', 'breeze', 'swinging' or 'swinging:SEED' (SEED a whole "
                 "number), not '%s'\n",
                 start_name.c_str());
    return 2;
  }
  const bool swinging = start->from == BenchStart::From::kSwinging;
  const bool breeze = start->from == BenchStart::From::kBreeze;
  const double joint_tolerance = argc > 5 ? std::atof(argv[5]) : 0.0;
  if (!(joint_tolerance >= 0)) {
    std::fprintf(stderr, "aloft_step_profile: the joint tolerance is a length >= 0 (m), not '%s'\n", argv[5]);
    return 2;
  }
  try {
    Model model;
    if (what.size() > 5 && what.substr(what.size() - 5) == ".json") {
      model = load_mobile(what);
    } else {
      model = std::move(*bench::generated_model(std::atoi(what.c_str())));  // seed 1
    }
    Simulation sim(model, swinging ? swinging_state(model, 0.5, start->seed) : rest_state(model));
    sim.set_collisions(collisions);
    if (breeze) {
      set_breeze(model, sim.loads());  // as `aloft bench`
      for (int k = 0; k < kBreezeSteps; ++k)
        if (!sim.step()) throw std::runtime_error(sim.failure()->message);
      sim.loads().clear();
    }
    BlownSteps blown(model, sim, wind_v0);  // plain steps when wind_v0 is 0
    if (!breeze && !blown.step())  // the first factorization (the wind's first step, if any)
      throw std::runtime_error(sim.failure()->message);
    sim.set_joint_tolerance(joint_tolerance);
    // The timed steps' contact-law solves, every record_every-th of those with at least record_min
    // contacts, written to record_path (the copies and the writing are timed with the steps).
    std::ofstream record_file;
    long solves_seen = 0, solves_recorded = 0;
    if (!record_path.empty()) {
      record_file.open(record_path, std::ios::binary | std::ios::trunc);
      if (!record_file) throw std::runtime_error("cannot write " + record_path);
      write_contact_law_header(record_file);
      sim.record_contact_laws([&](const ContactLawRecord& record) {
        if (record.contacts() < record_min || solves_seen++ % record_every != 0) return;
        write_contact_law_record(record_file, record);
        ++solves_recorded;
      });
    }
    const long long halvings = sim.subdivisions(), iterations = sim.joint_iterations();
    const Counts before = counts_of(sim);
    // The timed steps, in blocks of `every` when asked (each block printed as it ends; the steps and the
    // checksum are the same either way).
    double seconds = 0;
    for (long done = 0; done < steps;) {
      const long block = every > 0 ? std::min(every, steps - done) : steps;
      const Counts block_start = counts_of(sim);
      const long long block_halvings = sim.subdivisions();
      const double clock_start = thread_seconds();
      const double wind_start = blown.wind_seconds();
      if (!timed_steps(blown, block)) throw std::runtime_error(sim.failure()->message);
      const double block_seconds = thread_seconds() - clock_start - (blown.wind_seconds() - wind_start);
      seconds += block_seconds;
      if (every > 0) {
        // Where the motion stands at the block's end: the mobile's energy (the swing loses it to damping
        // and knocks; it must never grow), the fastest spin (what the step-size rule halves the step for:
        // on the large generated mobiles, light bars whirled about their pivots by knocks), and the
        // deepest overlap a step has started from so far.
        const State& now = sim.state();
        int fastest = 1;
        for (int i = 2; i < model.count; ++i)
          if (now.angular[i].squaredNorm() > now.angular[fastest].squaredNorm()) fastest = i;
        const double kinetic = kinetic_energy(model, now);
        std::printf("steps %ld-%ld: %.1f us/step, %.3f halvings per step; then energy %.6f J (kinetic %.6f), "
                    "fastest spin %.1f rad/s ('%s', %.3g kg), deepest overlap so far %.3g mm (%.2f of its pair's "
                    "thinnest half-width)\n",
                    done, done + block, 1e6 * block_seconds / block,
                    static_cast<double>(sim.subdivisions() - block_halvings) / block,
                    kinetic + potential_energy(model, now), kinetic, now.angular[fastest].norm(),
                    model.names[fastest].c_str(), model.mass[fastest], 1e3 * sim.collision_statistics().deepest,
                    sim.collision_statistics().deepest_relative);
        print_rates("    ", block_start, counts_of(sim), block);
        std::fflush(stdout);
      }
      done += block;
    }
    const double subdivided = static_cast<double>(sim.subdivisions() - halvings);
    double checksum = 0;
    for (int i = 1; i < model.count; ++i)
      checksum += sim.state().position[i].sum() + sim.state().orientation[i].coeffs().sum() + sim.state().angular[i].sum();
    std::printf("%s: %.3f us/step, %.4f us per component-step, %.3f halvings and %.2f solves per step; checksum %.17g\n",
                what.c_str(), 1e6 * seconds / steps, 1e6 * seconds / steps / (model.count - 1), subdivided / steps,
                (static_cast<double>(sim.joint_iterations() - iterations) + steps + subdivided) / steps, checksum);
    print_rates("  ", before, counts_of(sim), steps);
    if (blown.v0() > 0)
      std::printf("  wind: v0 = %g m/s; its occlusion refreshes and loads took %.3f us per step, left out of the "
                  "figures above\n",
                  blown.v0(), 1e6 * blown.wind_work_seconds() / blown.steps_blown());
    if (!record_path.empty()) {
      record_file.close();
      if (!record_file) throw std::runtime_error("could not finish writing " + record_path);
      std::printf("recorded %ld of the %ld contact-law solves of %ld contacts or more in %s (the time above "
                  "includes the recording)\n",
                  solves_recorded, solves_seen, record_min, record_path.c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "aloft_step_profile: %s\n", e.what());
    return 1;
  }
  return 0;
}
