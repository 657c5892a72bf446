#pragma once
// Broad phase: which components' world axis-aligned boxes overlap, one box per component.
//
// Two ways, the same pairs (BroadPhase.FindsExactlyThePairsThatATestOfEveryPairFinds):
//  - from kTreeMembers members on (on trees no wider than kTreeMostChildren), through the mobile's own
//    tree. A mobile's subtrees are compact in space (whatever hangs below a bar stays within reach of
//    it) and two sibling subtrees mostly hang apart. So every component's subtree gets the box around
//    its own box and its children's subtree boxes (one pass, tips first), and the pairs are found by
//    descending two subtrees only while their boxes overlap: each pair of components is met under their
//    lowest common ancestor, as the ancestor's own box against the subtree holding the other, or as two
//    sibling subtrees against each other.
//  - below that, sweep and prune along one axis (the members kept sorted by the low end of their box
//    with an insertion sort, O(n) when the order barely changes between calls). It pays for every pair
//    of boxes that overlap along that axis: on a deep mobile, long bars overlap hundreds of others along
//    any axis, and at 8191 components it was the largest single cost of the collisions-on step (17-20 %).
//    On small mobiles it is the cheaper of the two (callgrind, collisions-on steps of generated mobiles:
//    the tree +3.6 % instructions at 127 components, +2.3 % at 255, -0.3 % at 511; docs/performance.md,
//    "The broad phase through the mobile's tree").
//
// The boxes are set by the caller each call (box_of() turns a body-frame box and a pose into a world box
// grown by a margin). Nothing allocates once the scratch has grown.

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
  // `members`: the components that take part (indices < count); `axis`: the sweep's axis (0, 1 or 2;
  // widest_axis() of the rest pose is best); `parent`: each component's parent (-1 for the fixed
  // component; parent[i] < i, as compile() orders them). A parent and its child are left out (joined).
  // Empty `parent`: no tree (sweep and prune, as every component is then a root) and no pair left out.
  void reset(const std::vector<int>& members, int count, int axis, std::vector<int> parent = {});
  // A member's world box, to be set before each sweep() (non-members' boxes are empty and stay so).
  WorldBox& box(int component) { return boxes_[component]; }
  // Pairs (a, b), a < b, of members whose boxes overlap (closed boxes: touching counts), sorted, except a
  // parent and its child (their boxes always overlap, and the joint is not a contact: on a generated
  // mobile, nearly all the overlaps). Replaces `overlaps`.
  void sweep(std::vector<std::pair<int, int>>& overlaps);
  // After a sweep(), when only the boxes of `changed` (members, each once) have been set since (or were
  // passed to an earlier overlaps_of): the pairs, as sweep() gives them (a < b, sorted, a parent and its
  // child left out), of members whose boxes overlap one of `changed`'s. Replaces `overlaps`. Costs, per
  // changed box, the subtree boxes on its path to the root made again and a look down the tree (with
  // sweep and prune, a test against every member), instead of the whole mobile's sweep: how a pair list
  // is kept up to date when a few components have moved.
  void overlaps_of(const std::vector<int>& changed, std::vector<std::pair<int, int>>& overlaps);

 private:
  // Whether sweep() goes through the tree (else sweep and prune); fixed by reset().
  bool through_tree() const;
  // Whether x is a itself, its parent or one of its children: never a pair (overlaps_of's looks).
  bool self_or_joined(int a, int x) const { return x == a || parent_[x] == a || parent_[a] == x; }
  // Every member of the whole tree whose box overlaps member a's, paired with a (a itself, its parent
  // and its children left out: joined).
  void query_everything(int a, std::vector<std::pair<int, int>>& overlaps);
  // Every member of the subtree at `root` whose box overlaps `box`, paired with `a` (except root itself
  // when it is a's child: joined).
  void query(int a, const WorldBox& box, int root, std::vector<std::pair<int, int>>& overlaps);
  // Every pair of members, one in each of two disjoint subtrees, whose boxes overlap.
  void collide(int x, int y, std::vector<std::pair<int, int>>& overlaps);

  // From this many members on, the tree (see the top of this file), unless a component has more than
  // kTreeMostChildren children, or there are more roots: the tree meets every two children's subtrees of
  // a component, so many components hung from one bar (a flat mobile) would cost the square of their
  // number per call, where sweep and prune sorts them along its axis.
  static constexpr std::size_t kTreeMembers = 512;
  static constexpr int kTreeMostChildren = 16;
  void sweep_and_prune(std::vector<std::pair<int, int>>& overlaps);

  int count_ = 0;
  int axis_ = 0;
  std::vector<int> order_;             // the members; sweep and prune keeps them sorted by low end along
                                       // axis_ between calls
  struct SortedBox {
    double low[3], high[3];  // world, m, axes permuted: the sweep axis, then the next two (cyclically)
    int component;
  };
  std::vector<SortedBox> sorted_;      // sweep and prune scratch: the members' boxes in order_
  std::vector<char> member_;           // by component
  std::vector<WorldBox> boxes_;        // by component: its own box (empty for non-members)
  std::vector<WorldBox> subtree_;      // sweep scratch: the box around a component's subtree's boxes
  std::vector<int> parent_;            // by component (-1: a root)
  std::vector<int> child_begin_;       // children of i: child_[child_begin_[i] .. child_begin_[i + 1])
  std::vector<int> child_;
  std::vector<int> roots_;             // components without a parent
  std::vector<int> size_;              // components in each subtree (members or not)
  int most_children_ = 0;              // the most children any component has
  std::vector<int> query_stack_;       // scratch
  std::vector<std::pair<int, int>> pair_stack_;  // scratch
};

// The world axis (0, 1, 2) along which the points spread most: the best sweep axis.
int widest_axis(const std::vector<Vec3>& points);

}  // namespace aloft::internal
