// ContactTally: per pair of components, the steps in which they touched (include/aloft/contact_tally.hpp).

#include "aloft/contact_tally.hpp"

#include <algorithm>

namespace aloft {

ContactTally::Pair& ContactTally::count(int a, int b, double time) {
  const long long key = (static_cast<long long>(a) << 32) + b;
  const auto [found, added] = index_of_.try_emplace(key, static_cast<int>(pairs_.size()));
  if (added) {
    Pair pair;
    pair.a = a;
    pair.b = b;
    pair.first = time;
    pairs_.push_back(pair);
    counted_at_.push_back(0);
  }
  const auto k = static_cast<std::size_t>(found->second);
  Pair& pair = pairs_[k];
  if (counted_at_[k] != steps_) {
    counted_at_[k] = steps_;
    ++pair.steps;
    pair.last = time;
  }
  return pair;
}

void ContactTally::add_step(const std::vector<Contact>& contacts, const std::vector<std::pair<int, int>>& pushed,
                            double time) {
  ++steps_;
  bool any = !pushed.empty();
  for (const auto& [a, b] : pushed) count(a, b, time);
  for (const Contact& c : contacts) {
    if (!(c.distance <= kTouchingGap)) continue;
    any = true;
    Pair& pair = count(c.a, c.b, time);
    pair.deepest = std::max(pair.deepest, -c.distance);
  }
  steps_touching_ += any;
}

void ContactTally::components_touching_since(double since, int count, std::vector<std::uint8_t>& touching) const {
  touching.assign(static_cast<std::size_t>(count), 0);
  for (const Pair& p : pairs_)
    if (p.last >= since) touching[static_cast<std::size_t>(p.a)] = touching[static_cast<std::size_t>(p.b)] = 1;
}

std::vector<ContactTally::Pair> ContactTally::pairs() const {
  std::vector<Pair> sorted = pairs_;
  std::sort(sorted.begin(), sorted.end(), [](const Pair& x, const Pair& y) {
    if (x.steps != y.steps) return x.steps > y.steps;
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  });
  return sorted;
}

}  // namespace aloft
