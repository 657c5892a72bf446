#pragma once
// Which pairs of components touched during a run, how often and how deeply: what an artist wants to know
// before cutting metal (which pieces knock together in this wind?), and what `aloft simulate` reports.
// Fed each step's contacts (Simulation::contacts(): the detector's, at the start of the step's last
// (sub)step) and the pairs its impulses pushed apart (Simulation::pushed_pairs()), it counts per pair the
// steps in which the two touched: were pushed apart, or were within kTouchingGap of each other. (The
// first alone misses pieces that rest against each other with no impulse in a step; the second, a knock
// stopped and turned back by a speculative contact before its pieces were that close at a step's start.)

#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "aloft/collision.hpp"

namespace aloft {

class ContactTally {
 public:
  // m: pieces this close (or overlapping) touch. Twice the overlap a resting contact is left with
  // (the response's penetration slop, 0.05 mm); a knock stopped short of its gap by the speculative
  // contacts shows up at the next step's start, within it.
  static constexpr double kTouchingGap = 1e-4;

  struct Pair {
    int a = -1, b = -1;           // components, a < b
    long long steps = 0;          // steps in which they touched
    double first = 0, last = 0;   // s: the end times of the first and the last of those steps
    double deepest = 0;           // m: the largest overlap seen between them (>= 0)
  };

  // The contacts and the pushed pairs (a < b) of the step that ended at `time` (s). A pair counts once
  // per step however many contacts and impulses it had.
  void add_step(const std::vector<Contact>& contacts, const std::vector<std::pair<int, int>>& pushed, double time);

  // Every pair that touched, the most often first (ties: by a, then b).
  std::vector<Pair> pairs() const;
  // The steps in which some pair touched.
  long long steps_touching() const { return steps_touching_; }
  // Per component (`touching` resized to `count`): 1 for both of every pair whose last touch was at or
  // after `since` (s), else 0. (The viewer's and the renderer's glow on touching pieces.)
  void components_touching_since(double since, int count, std::vector<std::uint8_t>& touching) const;

 private:
  // The pair (a, b), added if new, counted in this step (steps_) if not yet.
  Pair& count(int a, int b, double time);

  std::vector<Pair> pairs_;                           // in the order first seen
  std::vector<long long> counted_at_;                 // per pair: the last step (add_step call) it counted in
  std::unordered_map<long long, int> index_of_;       // a * 2^32 + b -> index in pairs_
  long long steps_ = 0;                               // add_step calls so far
  long long steps_touching_ = 0;
};

}  // namespace aloft
