#pragma once
// Wall-clock time read from the steady clock (never set back), for what a person waits for: progress
// lines, the viewer's pacing, the share of a run's time a stage took. For timing the simulation on a
// shared machine, use the thread's CPU clock (aloft/thread_clock.hpp).

#include <chrono>

namespace aloft {

using WallClock = std::chrono::steady_clock;

// Seconds since `start` (a WallClock::now() reading).
inline double seconds_since(WallClock::time_point start) {
  return std::chrono::duration<double>(WallClock::now() - start).count();
}

}  // namespace aloft
