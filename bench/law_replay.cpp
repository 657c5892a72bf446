// aloft_law_replay: the contact law (src/dynamics/contact_law.cpp) timed on solves recorded from a
// simulation (aloft_step_profile --record-law FILE), so that two versions of the law can be compared on
// the same inputs: with collisions on, a change to the law changes the trajectory, and two spans time two
// different tangles (docs/performance.md, "The contact law on recorded solves").
//
//   aloft_law_replay [--repeat R] FILE
//     --repeat R: solve each record R times (default 3) and take the median of its CPU times
//
// Prints, by how each solve ended (converged with friction; friction dropped at the contacts that kept
// changing; dropped at every contact), the solves, their mean size and sweeps and their share of the
// time; the law's work (sweeps times m^2, what a sweep's cost grows with); the contacts left without
// friction; and whether each solve gave the impulses the recording holds, bit for bit (the same law on
// the same machine does), or how far it is from them (relative to the largest impulse of either).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "aloft/contact_law_record.hpp"
#include "aloft/thread_clock.hpp"
#include "dynamics/contact_law.hpp"

namespace {

struct Outcome {
  const char* name;
  long solves = 0;
  double contacts = 0, sweeps = 0, seconds = 0;
};

}  // namespace

int main(int argc, char** argv) {
  using namespace aloft;
  long repeat = 3;
  if (argc == 4 && std::string(argv[1]) == "--repeat") {
    char* end = nullptr;
    repeat = std::strtol(argv[2], &end, 10);
    if (*argv[2] == '\0' || *end != '\0' || repeat <= 0) {
      std::fprintf(stderr, "aloft_law_replay: --repeat takes a whole number > 0, not '%s'\n", argv[2]);
      return 2;
    }
    argv += 2;
    argc -= 2;
  }
  if (argc != 2) {
    std::fprintf(stderr, "usage: aloft_law_replay [--repeat R] FILE (written by aloft_step_profile --record-law)\n");
    return 2;
  }
  std::vector<ContactLawRecord> records;
  try {
    records = read_contact_law_records(argv[1]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "aloft_law_replay: %s\n", e.what());
    return 1;
  }
  if (records.empty()) {
    std::fprintf(stderr, "aloft_law_replay: %s holds no solves\n", argv[1]);
    return 1;
  }

  Outcome outcomes[3] = {{"converged with friction"}, {"friction dropped at some"}, {"friction dropped at all"}};
  double work = 0, total_seconds = 0, largest_difference = 0;
  long frictionless = 0, with_friction = 0, identical = 0, largest_at = 0, contacts = 0;
  int largest_m = 0;
  std::vector<double> times(static_cast<std::size_t>(repeat));
  Eigen::VectorXd P;
  for (std::size_t index = 0; index < records.size(); ++index) {
    const ContactLawRecord& r = records[index];
    const int m = r.contacts();
    ContactLawResult result;
    for (double& t : times) {
      const double before = thread_seconds();
      result = solve_contact_law(r, P);
      t = thread_seconds() - before;
    }
    std::nth_element(times.begin(), times.begin() + repeat / 2, times.end());
    const double seconds = times[static_cast<std::size_t>(repeat / 2)];
    Outcome& o = outcomes[result.friction_dropped ? 2 : result.frictionless_contacts > 0 ? 1 : 0];
    ++o.solves;
    o.contacts += m;
    o.sweeps += result.iterations;
    o.seconds += seconds;
    total_seconds += seconds;
    work += static_cast<double>(result.iterations) * m * m;
    frictionless += result.frictionless_contacts;
    for (int k = 0; k < m; ++k) with_friction += r.friction[k] > 0;
    contacts += m;
    largest_m = std::max(largest_m, m);
    if (P == r.impulses) {
      ++identical;
    } else {
      const double scale = std::max({r.impulses.cwiseAbs().maxCoeff(), P.cwiseAbs().maxCoeff(), 1e-300});
      const double difference = (P - r.impulses).cwiseAbs().maxCoeff() / scale;
      if (!(difference <= largest_difference)) {
        largest_difference = difference;
        largest_at = static_cast<long>(index) + 1;
      }
    }
  }

  const double solves = static_cast<double>(records.size());
  std::printf("%s: %zu solves, %.1f contacts each (at most %d); %.3f ms in all (the median of %ld times per "
              "solve), %.1f us per solve\n",
              argv[1], records.size(), contacts / solves, largest_m, 1e3 * total_seconds, repeat,
              1e6 * total_seconds / solves);
  for (const Outcome& o : outcomes) {
    const double n = std::max(1.0, static_cast<double>(o.solves));
    std::printf("  %-25s %6ld solves, %6.1f contacts and %6.1f sweeps each, %5.1f %% of the time\n", o.name,
                o.solves, o.contacts / n, o.sweeps / n, 100.0 * o.seconds / std::max(total_seconds, 1e-300));
  }
  std::printf("  work (sweeps x m^2): %.6g; contacts left without friction: %ld of %ld with friction\n", work,
              frictionless, with_friction);
  if (identical == static_cast<long>(records.size()))
    std::printf("  impulses: every solve as recorded, bit for bit\n");
  else
    std::printf("  impulses: %ld of %zu solves as recorded bit for bit; the largest difference %.3g of the "
                "largest impulse of either (solve %ld)\n",
                identical, records.size(), largest_difference, largest_at);
  return 0;
}
