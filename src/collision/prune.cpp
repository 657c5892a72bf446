// Pair pruning (method notes section 4), decided once per model.
//
// Reach. For a moving component x, far[x] is the largest distance from its joint to any point of its
// shapes (exact for the convex pieces), and seg[x] the distance on its parent P between P's own joint
// and the joint of x (0 when P is the fixed hook). For a chain hanging from an attachment point p of an
// ancestor A, A -> c1 -> c2 -> ... -> x (c1 a child of A, joined to A at p), every point of x lies
// within
//     R = seg[c2] + ... + seg[x] + far[x] = (S[x] - S[c1]) + far[x],   S = prefix sums of seg,
// of p, whatever the joint angles (triangle inequality along the chain). With ball joints every
// straightened chain is a reachable pose, so this is as sharp as a test from reaches alone can be.
//
// Two components a < b with lowest common ancestor A:
//   - b's parent is a: joined by a joint ("the joint does not count as a contact"): left out.
//   - A == a (a is an ancestor of b, through its child c1 attached at q): a's geometry is rigid with q,
//     so they never touch when the distance from q to a's shapes exceeds R_b + clearance. (It rarely
//     does: q is usually on a; kept otherwise, which is the sound side.)
//   - otherwise a and b hang from different children c1, c2 of A, attached at p and q on A (p == q when
//     both chains hang from one joint): never touch when |p - q| > R_a + R_b + clearance.
// A component with no shapes touches nothing.
//
// Touching at rest: pairs that pass the test but whose shapes are within kRestTouchDistance in the
// designed pose are listed and left out (they would be in contact from the first step, e.g. two pieces
// hung from one point). Found with the broad phase at rest, then the narrow phase.

#include "collision/prune.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "aloft/geometry.hpp"
#include "collision/broad_phase.hpp"
#include "collision/narrow_phase.hpp"

namespace aloft::internal {

namespace {

constexpr double kNoShape = -1e300;  // key of a component with no shapes: reaches nothing

// Smallest distance (m) from a body-frame point to the shapes of a component (0 on or inside one).
double distance_to_component(const std::vector<BodyShape>& shapes, const Vec3& point) {
  double best = std::numeric_limits<double>::infinity();
  for (const BodyShape& s : shapes) best = std::min(best, distance_to_shape(s.shape, point));
  return best;
}

Pose rest_pose(const Model& model, int i) {
  return {model.rest_orientation[i].toRotationMatrix(), model.rest_position[i]};
}

// Do the shapes of a and b come within kRestTouchDistance of each other in the rest pose?
bool touching_at_rest(const Model& model, const std::vector<ComponentGeometry>& geometry, int a, int b) {
  const Pose pa = rest_pose(model, a), pb = rest_pose(model, b);
  PieceContact contact;
  for (const ConvexPiece& x : geometry[a].pieces) {
    for (const ConvexPiece& y : geometry[b].pieces) {
      if ((pa.to_world(x.bound_center) - pb.to_world(y.bound_center)).norm() >
          x.bound_radius + y.bound_radius + kRestTouchDistance)
        continue;
      if (piece_contact(x, pa, y, pb, kRestTouchDistance, contact)) return true;
    }
  }
  return false;
}

}  // namespace

std::vector<ComponentGeometry> build_model_geometry(const Model& model) {
  std::vector<ComponentGeometry> geometry;
  geometry.reserve(model.count);
  for (int i = 0; i < model.count; ++i) geometry.push_back(build_component_geometry(model.shapes[i]));
  return geometry;
}

PairFilter::PairFilter(const Model& model, const std::vector<ComponentGeometry>& geometry)
    : parent_(model.parent), children_(model.children) {
  const int n = model.count;
  depth_.assign(n, 0);
  end_.resize(n);
  S_.assign(n, 0);
  key_.assign(n, kNoShape);
  gap_to_parent_.assign(n, std::numeric_limits<double>::infinity());
  attach_.assign(n, Vec3::Zero());
  for (int x = 0; x < n; ++x) end_[x] = x + 1;
  for (int x = n - 1; x >= 1; --x) end_[parent_[x]] = std::max(end_[parent_[x]], end_[x]);
  for (int x = 1; x < n; ++x) {
    const int p = parent_[x];
    depth_[x] = depth_[p] + 1;
    attach_[x] = model.joint_in_parent[x];
    S_[x] = p == 0 ? 0.0 : S_[p] + (model.joint_in_parent[x] - model.joint_in_child[p]).norm();
    if (!geometry[x].pieces.empty()) key_[x] = geometry[x].farthest_distance(model.joint_in_child[x]) + S_[x];
    if (!geometry[p].pieces.empty()) gap_to_parent_[x] = distance_to_component(model.shapes[p], attach_[x]);
  }
}

bool PairFilter::may_touch(int a, int b) const {
  // Climb to the lowest common ancestor, remembering the child of it on each side (-1: none).
  int x = a, y = b, cx = -1, cy = -1;
  while (depth_[x] > depth_[y]) cx = x, x = parent_[x];
  while (depth_[y] > depth_[x]) cy = y, y = parent_[y];
  while (x != y) cx = x, x = parent_[x], cy = y, y = parent_[y];
  if (cx == -1) return key_[b] - S_[cy] + kPruneClearance >= gap_to_parent_[cy];  // a is b's ancestor
  if (cy == -1) return key_[a] - S_[cx] + kPruneClearance >= gap_to_parent_[cx];  // b is a's ancestor
  const double gap = (attach_[cx] - attach_[cy]).norm();
  return key_[a] + key_[b] >= gap + S_[cx] + S_[cy] - kPruneClearance;
}

long long PairFilter::count_never_touch() const {
  const int n = static_cast<int>(parent_.size());
  long long never = 0;
  std::vector<double> sorted;  // keys of one subtree, descending
  for (int A = 0; A < n; ++A) {
    const std::vector<int>& kids = children_[A];
    for (int c1 : kids)
      for (int y = c1 + 1; y < end_[c1]; ++y)
        if (!(key_[y] - S_[c1] + kPruneClearance >= gap_to_parent_[c1])) ++never;
    for (std::size_t i = 0; i < kids.size(); ++i) {
      for (std::size_t j = i + 1; j < kids.size(); ++j) {
        const int c1 = kids[i], c2 = kids[j];
        const double threshold = (attach_[c1] - attach_[c2]).norm() + S_[c1] + S_[c2] - kPruneClearance;
        sorted.assign(key_.begin() + c2, key_.begin() + end_[c2]);
        std::sort(sorted.begin(), sorted.end(), std::greater<>());
        for (int x = c1; x < end_[c1]; ++x) {
          const double need = threshold - key_[x];
          never += sorted.end() - std::partition_point(sorted.begin(), sorted.end(),
                                                       [&](double k) { return k >= need; });
        }
      }
    }
  }
  return never;
}

CollisionPairs prune_pairs(const Model& model, const std::vector<ComponentGeometry>& geometry,
                           const PairFilter& filter) {
  const int n = model.count;
  CollisionPairs result;
  result.total = static_cast<long long>(n) * (n - 1) / 2;
  result.joined = n - 1;

  // Touching at rest: the broad phase at rest with the touching distance as margin, then exact tests.
  std::vector<int> members;
  std::vector<Vec3> rest_points;
  for (int i = 0; i < n; ++i) {
    if (geometry[i].pieces.empty()) continue;
    members.push_back(i);
    rest_points.push_back(model.rest_position[i]);
  }
  BroadPhase broad;
  broad.reset(members, n, widest_axis(rest_points), model.parent);  // (joined pairs left out here too)
  for (int i : members)
    broad.box(i) = box_of(rest_pose(model, i), geometry[i].box_center, geometry[i].box_half,
                          0.5 * kRestTouchDistance);
  std::vector<std::pair<int, int>> close;
  broad.sweep(close);
  for (const auto& [a, b] : close) {
    if (!filter.joined(a, b) && filter.may_touch(a, b) && touching_at_rest(model, geometry, a, b))
      result.touching_at_rest.emplace_back(a, b);
  }

  const long long touching = static_cast<long long>(result.touching_at_rest.size());
  result.listed = n <= CollisionPairs::kListedComponents;
  if (result.listed) {
    // Every pair through the same per-pair test the detector uses: list and counts agree exactly.
    for (int b = 1; b < n; ++b) {
      for (int a = 0; a < b; ++a) {
        if (filter.joined(a, b)) continue;
        if (!filter.may_touch(a, b)) {
          ++result.never_touch;
        } else if (!std::binary_search(result.touching_at_rest.begin(), result.touching_at_rest.end(),
                                       std::pair{a, b})) {
          result.candidates.emplace_back(a, b);
        }
      }
    }
    std::sort(result.candidates.begin(), result.candidates.end());
  } else {
    result.never_touch = filter.count_never_touch();
  }
  result.candidate_count = result.total - result.joined - result.never_touch - touching;
  return result;
}

}  // namespace aloft::internal

namespace aloft {

CollisionPairs prune_pairs(const Model& model) {
  const std::vector<internal::ComponentGeometry> geometry = internal::build_model_geometry(model);
  return internal::prune_pairs(model, geometry, internal::PairFilter(model, geometry));
}

}  // namespace aloft
