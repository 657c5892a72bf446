#pragma once
// A long run's progress on stderr (`aloft simulate`, `aloft render`): on a terminal one line rewritten in
// place, at most four times a second; otherwise (a log file, a pipe) one line per tenth of the run.

#include <string>

#include "aloft/wall_clock.hpp"

namespace aloft::cli {

class ProgressReport {
 public:
  // `verb` says what the run does ("simulating"). Nothing is shown when !enabled, nor during the first
  // `quiet_seconds` of the run, so that short runs print nothing.
  ProgressReport(bool enabled, long long total, std::string verb, double quiet_seconds);

  // Whether a line is due now that `done` of the `total` are done; if so, the caller shows it.
  bool due(long long done) const;
  // The line for `done`: the percentage, then `detail` (e.g. "frame 12 of 300"), then the time left
  // (on a terminal) or elapsed (otherwise).
  void show(long long done, const std::string& detail);
  // Clears the terminal's line, if one was drawn.
  void finish();
  // Seconds since the report was made (wall clock).
  double elapsed() const;

 private:
  bool enabled_;
  long long total_;
  std::string verb_;
  double quiet_seconds_;
  bool terminal_;
  WallClock::time_point start_ = WallClock::now();
  double last_shown_ = -1;  // s, on a terminal
  int tenths_shown_ = 0;    // otherwise
  bool drawn_ = false;      // a terminal line is on the screen
};

}  // namespace aloft::cli
