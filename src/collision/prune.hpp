#pragma once
// Pair pruning internals, shared by prune_pairs() and CollisionDetector (which builds the convex pieces
// once and asks PairFilter about each pair its broad phase finds close).

#include <utility>
#include <vector>

#include "aloft/collision.hpp"
#include "collision/convex_pieces.hpp"

namespace aloft::internal {

// A pruned pair stays at least this far apart (m) in every pose the joints allow: the reach test
// prunes only when the reaches fall short of the attachment gap by this much.
inline constexpr double kPruneClearance = 1e-3;

// Two components whose shapes come this close (m) or overlap in the designed rest pose are "touching
// at rest" (designed coincidences such as two pieces hung from one point, up to round-off).
inline constexpr double kRestTouchDistance = 1e-4;

std::vector<ComponentGeometry> build_model_geometry(const Model& model);

// The sound reach test of prune.cpp, per pair, in O(depth) (a walk to the lowest common ancestor).
class PairFilter {
 public:
  PairFilter(const Model& model, const std::vector<ComponentGeometry>& geometry);
  // a < b. True when a joint joins them (b's parent is a).
  bool joined(int a, int b) const { return parent_[b] == a; }
  // a < b, not joined. False when the reach test proves they never come within kPruneClearance.
  bool may_touch(int a, int b) const;

  // Counts over all pairs, by sorting reaches per pair of sibling subtrees (O(n depth log n)).
  long long count_never_touch() const;

 private:
  std::vector<int> parent_, depth_, end_;  // end_: the subtree of x is [x, end_[x]) (depth-first order)
  std::vector<double> S_;                  // sum of joint-to-joint distances from below the top chain link
  std::vector<double> key_;                // far + S (kNoShape when the component has no shapes)
  std::vector<double> gap_to_parent_;      // distance from x's attachment point to its parent's shapes
  std::vector<Vec3> attach_;               // x's attachment point in its parent's body frame
  std::vector<std::vector<int>> children_;
};

CollisionPairs prune_pairs(const Model& model, const std::vector<ComponentGeometry>& geometry,
                           const PairFilter& filter);

}  // namespace aloft::internal
