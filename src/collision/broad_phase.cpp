// Overlapping boxes: sweep and prune, or through the mobile's tree (see broad_phase.hpp).

#include "collision/broad_phase.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace aloft::internal {

namespace {

// A box that overlaps nothing, and that merging into anything leaves it unchanged.
WorldBox empty_box() {
  const double inf = std::numeric_limits<double>::infinity();
  return {Vec3::Constant(inf), Vec3::Constant(-inf)};
}

// Closed boxes: touching counts as overlapping (as the sweep and prune did). The six comparisons are
// combined without branches (`|` of ints, not `||`): a pair's boxes overlap unpredictably.
inline bool overlap(const WorldBox& a, const WorldBox& b) {
  const int apart = int{a.low.x() > b.high.x()} | int{b.low.x() > a.high.x()} | int{a.low.y() > b.high.y()} |
                    int{b.low.y() > a.high.y()} | int{a.low.z() > b.high.z()} | int{b.low.z() > a.high.z()};
  return apart == 0;
}

inline void emit(int a, int b, std::vector<std::pair<int, int>>& overlaps) {
  overlaps.emplace_back(std::min(a, b), std::max(a, b));
}

}  // namespace

void BroadPhase::reset(const std::vector<int>& members, int count, int axis, std::vector<int> parent) {
  count_ = count;
  axis_ = axis;
  order_ = members;  // (sorted along axis_ by the first sweep_and_prune)
  member_.assign(count, 0);
  for (int i : members) member_[i] = 1;
  boxes_.assign(count, empty_box());
  subtree_.assign(count, empty_box());
  parent_ = parent.empty() ? std::vector<int>(count, -1) : std::move(parent);
  for (int i = 0; i < count; ++i)
    if (parent_[i] >= i) throw std::invalid_argument("BroadPhase: a component's parent must come before it");
  // Children in compressed rows; roots apart.
  child_begin_.assign(count + 1, 0);
  roots_.clear();
  for (int i = 0; i < count; ++i) {
    if (parent_[i] >= 0) ++child_begin_[parent_[i] + 1];
    else roots_.push_back(i);
  }
  most_children_ = 0;
  for (int i = 0; i < count; ++i) most_children_ = std::max(most_children_, child_begin_[i + 1]);
  for (int i = 0; i < count; ++i) child_begin_[i + 1] += child_begin_[i];
  child_.assign(child_begin_[count], 0);
  std::vector<int> next(child_begin_.begin(), child_begin_.end() - 1);
  for (int i = 0; i < count; ++i)
    if (parent_[i] >= 0) child_[next[parent_[i]]++] = i;
  // Subtree sizes, tips first (parent[i] < i).
  size_.assign(count, 1);
  for (int i = count - 1; i >= 0; --i)
    if (parent_[i] >= 0) size_[parent_[i]] += size_[i];
}

void BroadPhase::query(int a, const WorldBox& box, int root, std::vector<std::pair<int, int>>& overlaps) {
  if (!overlap(box, subtree_[root])) return;
  query_stack_.clear();
  query_stack_.push_back(root);
  while (!query_stack_.empty()) {
    const int x = query_stack_.back();  // its subtree box overlaps `box`
    query_stack_.pop_back();
    if (member_[x] && parent_[x] != a && overlap(box, boxes_[x])) emit(a, x, overlaps);
    for (int k = child_begin_[x]; k < child_begin_[x + 1]; ++k)
      if (overlap(box, subtree_[child_[k]])) query_stack_.push_back(child_[k]);
  }
}

void BroadPhase::collide(int x, int y, std::vector<std::pair<int, int>>& overlaps) {
  // Split the larger of the two subtrees into its root's own box and its children's subtrees; every pair
  // with one member in each subtree is met exactly once.
  if (!overlap(subtree_[x], subtree_[y])) return;
  pair_stack_.clear();
  pair_stack_.emplace_back(x, y);
  while (!pair_stack_.empty()) {
    auto [p, q] = pair_stack_.back();  // their subtree boxes overlap
    pair_stack_.pop_back();
    if (size_[p] < size_[q]) std::swap(p, q);
    for (int k = child_begin_[p]; k < child_begin_[p + 1]; ++k)
      if (overlap(subtree_[child_[k]], subtree_[q])) pair_stack_.emplace_back(child_[k], q);
    // (query() uses its own stack; the pairs pushed above wait.) p and q's subtree are unrelated: the
    // joined test in query() never applies.
    if (member_[p]) query(p, boxes_[p], q, overlaps);
  }
}

void BroadPhase::sweep_and_prune(std::vector<std::pair<int, int>>& overlaps) {
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

bool BroadPhase::through_tree() const {
  return order_.size() >= kTreeMembers && most_children_ <= kTreeMostChildren &&
         roots_.size() <= static_cast<std::size_t>(kTreeMostChildren);
}

void BroadPhase::sweep(std::vector<std::pair<int, int>>& overlaps) {
  overlaps.clear();
  if (!through_tree()) {
    sweep_and_prune(overlaps);
    return;
  }
  // Subtree boxes, tips first: each component's own box, grown by its children's subtree boxes.
  for (int i = 0; i < count_; ++i) subtree_[i] = boxes_[i];
  for (int i = count_ - 1; i >= 0; --i) {
    const int p = parent_[i];
    if (p < 0) continue;
    subtree_[p].low = subtree_[p].low.cwiseMin(subtree_[i].low);
    subtree_[p].high = subtree_[p].high.cwiseMax(subtree_[i].high);
  }
  // Each pair under its lowest common ancestor p: p's own box against each child's subtree (p's own
  // children left out: joined), and every two children's subtrees against each other. The roots are
  // children of a common ancestor above them all.
  for (int p = 0; p < count_; ++p) {
    const int begin = child_begin_[p], end = child_begin_[p + 1];
    for (int k = begin; k < end; ++k) {
      if (member_[p]) query(p, boxes_[p], child_[k], overlaps);
      for (int l = k + 1; l < end; ++l) collide(child_[k], child_[l], overlaps);
    }
  }
  for (std::size_t k = 0; k < roots_.size(); ++k)
    for (std::size_t l = k + 1; l < roots_.size(); ++l) collide(roots_[k], roots_[l], overlaps);
  std::sort(overlaps.begin(), overlaps.end());
}

void BroadPhase::query_everything(int a, std::vector<std::pair<int, int>>& overlaps) {
  const WorldBox& box = boxes_[a];
  query_stack_.clear();
  for (const int root : roots_)
    if (overlap(box, subtree_[root])) query_stack_.push_back(root);
  while (!query_stack_.empty()) {
    const int x = query_stack_.back();  // its subtree box overlaps a's box
    query_stack_.pop_back();
    if (member_[x] && !self_or_joined(a, x) && overlap(box, boxes_[x])) emit(a, x, overlaps);
    for (int k = child_begin_[x]; k < child_begin_[x + 1]; ++k)
      if (overlap(box, subtree_[child_[k]])) query_stack_.push_back(child_[k]);
  }
}

void BroadPhase::overlaps_of(const std::vector<int>& changed, std::vector<std::pair<int, int>>& overlaps) {
  overlaps.clear();
  if (through_tree()) {
    // The subtree boxes made again, tight as sweep() makes them (each around its component's box and its
    // children's subtree boxes), along the path from each changed component to its root, up to the first
    // that comes out the same (its ancestors' are then right too: a changed ancestor's path is walked
    // from that ancestor).
    for (const int a : changed) {
      for (int p = a; p >= 0; p = parent_[p]) {
        WorldBox around = boxes_[p];
        for (int k = child_begin_[p]; k < child_begin_[p + 1]; ++k) {
          around.low = around.low.cwiseMin(subtree_[child_[k]].low);
          around.high = around.high.cwiseMax(subtree_[child_[k]].high);
        }
        if (around.low == subtree_[p].low && around.high == subtree_[p].high) break;
        subtree_[p] = around;
      }
    }
    for (const int a : changed) query_everything(a, overlaps);
  } else {
    for (const int a : changed)
      for (const int x : order_)
        if (!self_or_joined(a, x) && overlap(boxes_[a], boxes_[x])) emit(a, x, overlaps);
  }
  // Two changed components that overlap each other are found from both.
  std::sort(overlaps.begin(), overlaps.end());
  overlaps.erase(std::unique(overlaps.begin(), overlaps.end()), overlaps.end());
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
