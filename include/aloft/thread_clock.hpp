#pragma once
// The calling thread's CPU time, for timing the simulation on a machine shared with other work: wall-clock
// time also counts the time the thread waited for a core; the thread's own CPU time does not (it still
// feels shared caches). It is what Google Benchmark's CPU column measures for a single-threaded run.
// Used by `aloft bench` and the benchmark programs.

#include <time.h>

namespace aloft {

// Seconds of CPU time this thread has used (CLOCK_THREAD_CPUTIME_ID).
inline double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace aloft
