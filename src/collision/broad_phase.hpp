#pragma once
// Broad phase: sweep and prune over world axis-aligned boxes, one per component.
//
// The boxes are set by the caller each call (box_of() turns a body-frame box and a pose into a world box
// grown by a margin). The members are kept sorted by the low end of their box along `axis` with an
// insertion sort, which is O(n) when the order barely changes between calls (a mobile moves little per
// step); sweeping then yields the pairs whose boxes overlap on all three axes, sorted by (a, b).

#include <utility>
#include <vector>

#include "collision/narrow_phase.hpp"

namespace aloft::internal {

struct WorldBox {
  Vec3 low = Vec3::Zero(), high = Vec3::Zero();  // world, m
};

// World box of the body-frame box (centre, half extents) at `pose`, grown by `margin` (m) on every side.
inline WorldBox box_of(const Pose& pose, const Vec3& center, const Vec3& half, double margin) {
  const Vec3 c = pose.to_world(center);
  const Vec3 h = pose.rotation.cwiseAbs() * half + Vec3::Constant(margin);
  return {c - h, c + h};
}

class BroadPhase {
 public:
  // `members`: the components that take part (indices < count); `axis`: 0, 1 or 2; `parent`: each
  // component's parent (indices < count; empty: none are left out as joined).
  void reset(std::vector<int> members, int count, int axis, std::vector<int> parent = {});
  WorldBox& box(int component) { return boxes_[component]; }
  // Pairs (a, b), a < b, of members whose boxes overlap, sorted, except a parent and its child (their
  // boxes always overlap, and the joint is not a contact: on a generated mobile, nearly all the
  // overlaps). Replaces `overlaps`.
  void sweep(std::vector<std::pair<int, int>>& overlaps);

 private:
  int axis_ = 0;
  std::vector<int> order_;       // members, sorted by low end along axis_ (kept between calls)
  std::vector<WorldBox> boxes_;  // by component
  std::vector<int> parent_;      // by component (-1: none given)
  struct SortedBox {
    double low[3], high[3];  // world, m, axes permuted: the sweep axis, then the next two (cyclically)
    int component;
  };
  std::vector<SortedBox> sorted_;  // sweep scratch: the members' boxes in order_ (sized once)
};

// The world axis (0, 1, 2) along which the points spread most: the best sweep axis.
int widest_axis(const std::vector<Vec3>& points);

}  // namespace aloft::internal
