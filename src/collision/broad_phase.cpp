// Sweep and prune over world boxes (see broad_phase.hpp).

#include "collision/broad_phase.hpp"

#include <algorithm>

namespace aloft::internal {

void BroadPhase::reset(std::vector<int> members, int count, int axis) {
  order_ = std::move(members);
  boxes_.assign(count, WorldBox{});
  axis_ = axis;
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
  overlaps.clear();
  for (std::size_t k = 0; k < order_.size(); ++k) {
    const int i = order_[k];
    const WorldBox& bi = boxes_[i];
    for (std::size_t m = k + 1; m < order_.size(); ++m) {
      const int j = order_[m];
      const WorldBox& bj = boxes_[j];
      if (bj.low[axis_] > bi.high[axis_]) break;
      if ((bi.low.array() > bj.high.array()).any() || (bj.low.array() > bi.high.array()).any()) continue;
      overlaps.emplace_back(std::min(i, j), std::max(i, j));
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
