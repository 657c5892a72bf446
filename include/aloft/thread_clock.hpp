#pragma once
// The calling thread's CPU time, for timing the simulation on a machine shared with other work: wall-clock
// time also counts the time the thread waited for a core; the thread's own CPU time does not (it still
// feels shared caches). It is what Google Benchmark's CPU column measures for a single-threaded run.
// Used by `aloft bench` and the benchmark programs.

#include <time.h>

#include <algorithm>

namespace aloft {

// Seconds of CPU time this thread has used (CLOCK_THREAD_CPUTIME_ID).
inline double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The cost of one thread_seconds() read (s): the median, over 5 runs, of 1000 reads back to back. It is
// a system call (no vDSO for a thread's CPU clock): about 1.6 us on the development machine, as much as
// a Steel Fish step.
inline double thread_clock_read_cost() {
  double costs[5];
  for (double& cost : costs) {
    constexpr int kReads = 1000;
    const double start = thread_seconds();
    for (int i = 0; i < kReads; ++i) thread_seconds();
    cost = (thread_seconds() - start) / (kReads + 1);
  }
  std::sort(costs, costs + 5);
  return costs[2];
}

// Work timed apart inside a timed span (the wind's loads inside a span of steps), so that the span's
// figure can leave it out, by the thread's CPU clock (the steady clock would count, as the work's, the
// time the thread waited for a core). Each apart() reads the clock twice; the part of those reads that
// falls outside the work's interval would otherwise land in the span's figure, so taken_from_span()
// counts both reads whole (read_cost each).
class ApartTimer {
 public:
  ApartTimer() : read_cost_(thread_clock_read_cost()) {}

  // Runs `work` and counts its CPU time apart.
  template <class Work>
  void apart(Work&& work) {
    const double start = thread_seconds();
    work();
    seconds_ += thread_seconds() - start;
    ++count_;
  }
  // CPU time (s) of the work timed apart so far, the clock reads included: what a span that held it
  // must give up. Differences of two readings give a part of a run.
  double taken_from_span() const { return seconds_ + static_cast<double>(count_) * read_cost_; }
  // The work's own time (s), the reads' cost taken out (one read's cost falls inside each interval).
  double work_seconds() const { return seconds_ - static_cast<double>(count_) * read_cost_; }

 private:
  double read_cost_;
  double seconds_ = 0;
  long long count_ = 0;
};

}  // namespace aloft
