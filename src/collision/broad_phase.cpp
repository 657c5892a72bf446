// Sweep and prune over world boxes (see broad_phase.hpp).

#include "collision/broad_phase.hpp"

#include <algorithm>

namespace aloft::internal {

void BroadPhase::reset(std::vector<int> members, int count, int axis, std::vector<int> parent) {
  order_ = std::move(members);
  boxes_.assign(count, WorldBox{});
  axis_ = axis;
  parent_ = parent.empty() ? std::vector<int>(count, -1) : std::move(parent);
}

void BroadPhase::sweep(std::vector<std::pair<int, int>>& overlaps) {
  // Insertion sort by (low end, index): ties broken by index, so the order is deterministic.
  auto before = [&](int x, int y) {
    const double lx = boxes_[x].low[axis_], ly = boxes_[y].low[axis_];
    return lx < ly || (lx == ly && x < y);
  };
  for (std::size_t k = 1; k < order_.size(); ++k) {
    const int v = order_[k];
    std::size_t j = k;
    for (; j > 0 && before(v, order_[j - 1]); --j) order_[j] = order_[j - 1];
    order_[j] = v;
  }
  // The boxes copied in sweep order, their coordinates permuted so that the sweep axis comes first, so
  // that the scan below reads memory in order with fixed offsets: with long boxes (a bar across a mobile
  // overlaps many others along any axis) most of the time goes into rejecting pairs, 19 for each overlap
  // on generated-1023 swinging. The rejection is branch-free (which side fails is unpredictable).
  const int u = (axis_ + 1) % 3, w = (axis_ + 2) % 3;  // the other two axes
  sorted_.resize(order_.size());
  for (std::size_t k = 0; k < order_.size(); ++k) {
    const WorldBox& b = boxes_[order_[k]];
    sorted_[k] = {{b.low[axis_], b.low[u], b.low[w]}, {b.high[axis_], b.high[u], b.high[w]}, order_[k]};
  }
  overlaps.clear();
  const SortedBox* box = sorted_.data();     // (not re-read through the vector after each emplace_back,
  const std::size_t count = sorted_.size();  // which may alias it)
  for (std::size_t k = 0; k < count; ++k) {
    const SortedBox bi = box[k];
    for (std::size_t m = k + 1; m < count; ++m) {
      const SortedBox& bj = box[m];
      if (bj.low[0] > bi.high[0]) break;
      const bool apart = (bi.low[1] > bj.high[1]) | (bj.low[1] > bi.high[1]) | (bi.low[2] > bj.high[2]) |
                         (bj.low[2] > bi.high[2]);
      if (apart) continue;
      const int low = std::min(bi.component, bj.component), high = std::max(bi.component, bj.component);
      if (parent_[high] == low) continue;  // joined
      overlaps.emplace_back(low, high);
    }
  }
  std::sort(overlaps.begin(), overlaps.end());
}

int widest_axis(const std::vector<Vec3>& points) {
  if (points.empty()) return 0;
  Vec3 low = points[0], high = points[0];
  for (const Vec3& p : points) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  int axis = 0;
  (high - low).maxCoeff(&axis);
  return axis;
}

}  // namespace aloft::internal
