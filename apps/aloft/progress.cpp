// A long run's progress on stderr (progress.hpp).

#include "progress.hpp"

#include <cstdio>
#include <utility>

#include "common.hpp"

namespace aloft::cli {

namespace {

// Seconds between two lines on a terminal.
constexpr double kRedrawSeconds = 0.25;

int tenths(long long done, long long total) { return static_cast<int>(10 * done / total); }

}  // namespace

ProgressReport::ProgressReport(bool enabled, long long total, std::string verb, double quiet_seconds)
    : enabled_(enabled && total > 0),
      total_(total),
      verb_(std::move(verb)),
      quiet_seconds_(quiet_seconds),
      terminal_(is_terminal(stderr)) {}

double ProgressReport::elapsed() const { return seconds_since(start_); }

bool ProgressReport::due(long long done) const {
  if (!enabled_) return false;
  const double seconds = elapsed();
  if (seconds < quiet_seconds_) return false;
  return terminal_ ? seconds - last_shown_ >= kRedrawSeconds : tenths(done, total_) > tenths_shown_;
}

void ProgressReport::show(long long done, const std::string& detail) {
  const double seconds = elapsed();
  const double percent = 100.0 * static_cast<double>(done) / static_cast<double>(total_);
  if (terminal_) {
    last_shown_ = seconds;
    const double left = done > 0 ? seconds * static_cast<double>(total_ - done) / static_cast<double>(done) : 0;
    std::fprintf(stderr, "\r\033[K  %s: %3.0f%%  %s  %.0f s left", verb_.c_str(), percent, detail.c_str(), left);
    std::fflush(stderr);
    drawn_ = true;
  } else {
    tenths_shown_ = tenths(done, total_);
    std::fprintf(stderr, "aloft: %s: %.0f%% (%s, %.0f s elapsed)\n", verb_.c_str(), percent, detail.c_str(), seconds);
  }
}

void ProgressReport::finish() {
  if (drawn_) std::fprintf(stderr, "\r\033[K");
  drawn_ = false;
}

}  // namespace aloft::cli
