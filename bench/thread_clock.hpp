#pragma once
// The calling thread's CPU time, for the benchmark programs' own timings (what Google Benchmark's CPU
// column measures for a single-threaded run).

#include <time.h>

namespace aloft::bench {

// Seconds of CPU time this thread has used (CLOCK_THREAD_CPUTIME_ID).
inline double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace aloft::bench
