// CollisionDetector: pruning once, then per call a broad phase over the components that take part in a
// candidate pair and an exact narrow phase on the convex pieces of the pairs that pass it.
//
// Broad phase. Each component has a body-frame box enclosing its pieces, placed in the world and grown
// by its own speculative margin
//     m_i = base_margin / 2 + step * (|v_i| + |w_i| * reach_i),
// so a pair's boxes overlap whenever its shapes could be closer than m_a + m_b (the contract's margin).
// Sweep and prune (broad_phase.hpp) over the components that have shapes gives the overlapping pairs;
// PairFilter drops the joined ones and those the reach test proves never touch, a binary search the
// pairs touching at rest.
//
// Narrow phase. For each pair (in increasing (a, b)), each pair of pieces whose enclosing spheres come
// within the margin goes to piece_contact(); a pair keeps at most kMaxContactsPerPair contacts, the
// deepest, in piece order. Contacts come out sorted by (a, b), so the same state gives the same contacts
// in the same order.

#include <algorithm>
#include <cmath>

#include "aloft/collision.hpp"
#include "aloft/model.hpp"
#include "collision/broad_phase.hpp"
#include "collision/narrow_phase.hpp"
#include "collision/prune.hpp"

namespace aloft {

namespace {
constexpr std::size_t kMaxContactsPerPair = 4;
}  // namespace

using internal::ComponentGeometry;
using internal::ConvexPiece;
using internal::PieceContact;
using internal::Pose;

struct CollisionDetector::Impl {
  std::vector<ComponentGeometry> geometry;
  internal::PairFilter filter;
  CollisionPairs pairs;
  std::vector<int> members;        // components with shapes
  internal::BroadPhase broad;

  // Per-call scratch, indexed by component (sized once).
  std::vector<Pose> pose;
  std::vector<double> margin;      // the component's own speculative margin, m
  std::vector<std::pair<int, int>> overlaps;
  std::vector<Vec3> piece_center;  // world centres of a's pieces for the current pair
  std::vector<PieceContact> found;

  Impl(const Model& model, std::vector<ComponentGeometry> g)
      : geometry(std::move(g)), filter(model, geometry), pairs(internal::prune_pairs(model, geometry, filter)) {}

  bool is_candidate(int a, int b) const {
    return !filter.joined(a, b) && filter.may_touch(a, b) &&
           !std::binary_search(pairs.touching_at_rest.begin(), pairs.touching_at_rest.end(), std::pair{a, b});
  }

  void place(const State& state, double step, double base_margin) {
    for (int i : members) {
      const ComponentGeometry& g = geometry[i];
      pose[i] = {state.orientation[i].toRotationMatrix(), state.position[i]};
      const double speed = state.velocity[i].norm() + state.angular[i].norm() * g.reach;
      margin[i] = 0.5 * base_margin + step * speed;
      broad.box(i) = internal::box_of(pose[i], g.box_center, g.box_half, margin[i]);
    }
  }

  void narrow(int a, int b, std::vector<Contact>& contacts) {
    const ComponentGeometry &ga = geometry[a], &gb = geometry[b];
    const double pair_margin = margin[a] + margin[b];
    piece_center.resize(ga.pieces.size());
    for (std::size_t k = 0; k < ga.pieces.size(); ++k) piece_center[k] = pose[a].to_world(ga.pieces[k].bound_center);
    found.clear();
    PieceContact c;
    for (const ConvexPiece& y : gb.pieces) {
      const Vec3 cy = pose[b].to_world(y.bound_center);
      for (std::size_t k = 0; k < ga.pieces.size(); ++k) {
        const ConvexPiece& x = ga.pieces[k];
        const double reach = x.bound_radius + y.bound_radius + pair_margin;
        if ((piece_center[k] - cy).squaredNorm() > reach * reach) continue;
        if (internal::piece_contact(x, pose[a], y, pose[b], pair_margin, c)) found.push_back(c);
      }
    }
    if (found.size() > kMaxContactsPerPair) {
      std::stable_sort(found.begin(), found.end(),
                       [](const PieceContact& p, const PieceContact& q) { return p.distance < q.distance; });
      found.resize(kMaxContactsPerPair);
    }
    for (const PieceContact& f : found) contacts.push_back({a, b, f.point, f.normal, f.distance});
  }
};

CollisionDetector::CollisionDetector(const Model& model)
    : impl_(std::make_unique<Impl>(model, internal::build_model_geometry(model))) {
  Impl& d = *impl_;
  std::vector<Vec3> rest_points;
  for (int i = 0; i < model.count; ++i) {
    if (d.geometry[i].pieces.empty()) continue;
    d.members.push_back(i);
    rest_points.push_back(model.rest_position[i]);
  }
  // Sweep along the world axis the rest pose spreads most along.
  d.broad.reset(d.members, model.count, internal::widest_axis(rest_points));
  d.pose.resize(model.count);
  d.margin.assign(model.count, 0);
}

CollisionDetector::~CollisionDetector() = default;
CollisionDetector::CollisionDetector(CollisionDetector&&) noexcept = default;
CollisionDetector& CollisionDetector::operator=(CollisionDetector&&) noexcept = default;

const CollisionPairs& CollisionDetector::pairs() const { return impl_->pairs; }

double CollisionDetector::reach(int component) const { return impl_->geometry[component].reach; }

void CollisionDetector::find_contacts(const State& state, double step, double base_margin,
                                      std::vector<Contact>& contacts) {
  Impl& d = *impl_;
  contacts.clear();
  d.place(state, step, base_margin);
  d.broad.sweep(d.overlaps);
  for (const auto& [a, b] : d.overlaps)
    if (d.is_candidate(a, b)) d.narrow(a, b, contacts);
}

}  // namespace aloft
