// CollisionDetector: pruning once, then per call a broad phase over the components that take part in a
// candidate pair and an exact narrow phase on the convex pieces of the pairs that pass it.
//
// Broad phase. Each component has a body-frame box enclosing its pieces, placed in the world and grown
// by its own speculative margin
//     m_i = base_margin / 2 + step * (|v_i| + |w_i| * reach_i),
// so a pair's boxes overlap whenever its shapes could be closer than m_a + m_b (the contract's margin).
// The broad phase (broad_phase.hpp: sweep and prune, or the boxes through the mobile's tree from 512
// components on) over the components that have shapes gives the overlapping pairs; PairFilter drops the
// joined ones and those the reach test proves never touch, a binary search the pairs touching at rest.
//
// Narrow phase. For each pair (in increasing (a, b)), each pair of pieces whose enclosing spheres come
// within the margin goes to piece_contact(); a pair keeps at most kMaxContactsPerPair contacts, the
// deepest, in piece order. Contacts come out sorted by (a, b), so the same state gives the same contacts
// in the same order.
//
// Coherence. Between calls the pieces move little, and most piece pairs the narrow phase looks at are
// apart by more than the margin, step after step (a plate beside its sibling). For those, piece_contact()
// leaves a lower bound of their distance. Each component carries an odometer: the sum, over calls, of how
// far any point of it moved since the call before (|dx| + 2 sin(angle / 2) reach, exact bound for a rigid
// motion). A piece pair measured at distance d is apart by at least d - (what both odometers added since),
// so while that exceeds the margin (and the distance's own error, kCoherenceSlack), it cannot be in
// contact and is not measured again. This skips only pairs that would give no contact: the contacts are
// the same as without it. The bounds live in a direct-mapped table (a slot per hash of the piece pair,
// overwritten on a clash), sized once: no allocation, and a clash only costs a measurement.

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "aloft/collision.hpp"
#include "aloft/model.hpp"
#include "collision/broad_phase.hpp"
#include "collision/narrow_phase.hpp"
#include "collision/near_part.hpp"
#include "collision/prune.hpp"

namespace aloft {

namespace {
constexpr std::size_t kMaxContactsPerPair = 4;
// The error of a measured distance that is not a contact (m, relative and absolute), a margin of safety
// on top of bounds that are already certified: GJK's lower bound (GjkResult::lower), the closed forms'
// distances at rounding.
constexpr double kCoherenceRelativeSlack = 1e-6;
constexpr double kCoherenceSlack = 1e-9;

// One remembered piece-pair distance.
struct DistanceBound {
  std::uint64_t key = ~std::uint64_t{0};  // which piece pair (none yet)
  double distance = 0;                    // m: lower bound of the signed distance when measured
  double odometer_a = 0, odometer_b = 0;  // the components' odometers then (m)
};
}  // namespace

using internal::ComponentGeometry;
using internal::ConvexPiece;
using internal::PieceContact;
using internal::Pose;

namespace {
// A component's share of a pair's margin (m; see the contract of find_contacts).
double component_margin(const ComponentGeometry& g, const Vec3& velocity, const Vec3& angular, double step,
                        double base_margin) {
  return 0.5 * base_margin + step * (velocity.norm() + angular.norm() * g.reach);
}
}  // namespace

struct CollisionDetector::Impl {
  std::vector<ComponentGeometry> geometry;
  internal::PairFilter filter;
  CollisionPairs pairs;
  std::vector<int> members;        // components with shapes
  internal::BroadPhase broad;

  // Coherence (see the top of this file): per component the pose of the last call and the odometer (m).
  std::vector<Quat> last_orientation;
  std::vector<Vec3> last_position;
  std::vector<double> odometer;
  bool placed_before = false;
  std::vector<DistanceBound> bounds;  // size a power of two
  bool coherence = true;              // skip pairs by the remembered distances (set_coherence)
  std::uint64_t max_pieces = 1;       // pieces of the component with the most

  // Per-call scratch, indexed by component (sized once).
  std::vector<Pose> pose;
  std::vector<double> margin;      // the component's own speculative margin, m
  std::vector<std::pair<int, int>> overlaps;
  std::vector<Vec3> piece_center;  // world centres of a's pieces for the current pair
  struct Found {
    PieceContact contact;
    const ConvexPiece *piece_a, *piece_b;
    int order;  // the how-manieth of the pair's contacts found (piece order)
  };
  std::vector<Found> found;

  Impl(const Model& model, std::vector<ComponentGeometry> g)
      : geometry(std::move(g)), filter(model, geometry), pairs(internal::prune_pairs(model, geometry, filter)) {}

  bool is_candidate(int a, int b) const {
    return !filter.joined(a, b) && filter.may_touch(a, b) &&
           !std::binary_search(pairs.touching_at_rest.begin(), pairs.touching_at_rest.end(), std::pair{a, b});
  }

  void place(const State& state, double step, double base_margin) {
    for (int i : members) {
      const ComponentGeometry& g = geometry[i];
      if (placed_before) {
        // |q1 . q2| = cos(angle / 2); a point at distance r from the centre moves by 2 sin(angle / 2) r.
        const double c = std::min(1.0, std::abs(last_orientation[i].dot(state.orientation[i])));
        const double chord = 2.0 * std::sqrt(std::max(0.0, 1.0 - c * c));
        odometer[i] += (state.position[i] - last_position[i]).norm() + chord * g.reach;
      }
      last_orientation[i] = state.orientation[i];
      last_position[i] = state.position[i];
      pose[i] = {state.orientation[i].toRotationMatrix(), state.position[i]};
      margin[i] = component_margin(g, state.velocity[i], state.angular[i], step, base_margin);
      broad.box(i) = internal::box_of(pose[i], g.box_center, g.box_half, margin[i]);
    }
    placed_before = true;
  }

  std::size_t slot(std::uint64_t key) const {
    key ^= key >> 33;  // a mix (splitmix64's finaliser) spreads neighbouring pairs over the table
    key *= 0xff51afd7ed558ccdULL;
    key ^= key >> 33;
    return static_cast<std::size_t>(key & (bounds.size() - 1));
  }

  void narrow(int a, int b, std::vector<Contact>& contacts) {
    const ComponentGeometry &ga = geometry[a], &gb = geometry[b];
    const double pair_margin = margin[a] + margin[b];
    piece_center.resize(ga.pieces.size());
    for (std::size_t k = 0; k < ga.pieces.size(); ++k) piece_center[k] = pose[a].to_world(ga.pieces[k].bound_center);
    found.clear();
    PieceContact c;
    for (std::size_t l = 0; l < gb.pieces.size(); ++l) {
      const ConvexPiece& y = gb.pieces[l];
      const Vec3 cy = pose[b].to_world(y.bound_center);
      for (std::size_t k = 0; k < ga.pieces.size(); ++k) {
        const ConvexPiece& x = ga.pieces[k];
        const double reach = x.bound_radius + y.bound_radius + pair_margin;
        if ((piece_center[k] - cy).squaredNorm() > reach * reach) continue;
        const std::uint64_t key =
            ((static_cast<std::uint64_t>(a) * geometry.size() + static_cast<std::uint64_t>(b)) * max_pieces + k) *
                max_pieces + l;
        DistanceBound& bound = bounds[slot(key)];
        if (coherence && bound.key == key) {
          const double apart = bound.distance - (odometer[a] - bound.odometer_a) - (odometer[b] - bound.odometer_b);
          if (apart - kCoherenceRelativeSlack * bound.distance - kCoherenceSlack > pair_margin) continue;
        }
        if (internal::piece_contact(x, pose[a], y, pose[b], pair_margin, c)) {
          found.push_back({c, &x, &y, static_cast<int>(found.size())});
          bound.key = ~std::uint64_t{0};
        } else {
          bound = {key, c.distance, odometer[a], odometer[b]};
        }
      }
    }
    // Every contact of the pair carries a box around, and the largest reach of, the parts of the pieces
    // found near each other that lie within the pair's margin of their partner (near_part.hpp: only
    // those can meet it within the step), and the smallest half-width of those pieces, over all of them,
    // including any the cut below drops (their travel must be bounded too).
    double reach_a = 0, reach_b = 0, thinnest = INFINITY;
    Vec3 low_a = Vec3::Constant(INFINITY), high_a = Vec3::Constant(-INFINITY);
    Vec3 low_b = low_a, high_b = high_a;
    const auto farthest_corner = [](const Vec3& low, const Vec3& high) {
      return low.cwiseAbs().cwiseMax(high.cwiseAbs()).norm();
    };
    for (const Found& f : found) {
      Vec3 la, ha, lb, hb;
      internal::near_part_box(*f.piece_a, pose[a], *f.piece_b, pose[b], pair_margin, la, ha);
      internal::near_part_box(*f.piece_b, pose[b], *f.piece_a, pose[a], pair_margin, lb, hb);
      reach_a = std::max(reach_a, std::min(f.piece_a->reach, farthest_corner(la, ha)));
      reach_b = std::max(reach_b, std::min(f.piece_b->reach, farthest_corner(lb, hb)));
      thinnest = std::min({thinnest, f.piece_a->half_width, f.piece_b->half_width});
      low_a = low_a.cwiseMin(la), high_a = high_a.cwiseMax(ha);
      low_b = low_b.cwiseMin(lb), high_b = high_b.cwiseMax(hb);
    }
    const bool complete = found.size() <= kMaxContactsPerPair;
    if (found.size() > kMaxContactsPerPair) {
      // The deepest, kept in piece order: then a look with a wider margin, which finds more shallow
      // ones, keeps the same contacts in the same order (keep_within_margin).
      std::stable_sort(found.begin(), found.end(),
                       [](const Found& p, const Found& q) { return p.contact.distance < q.contact.distance; });
      found.resize(kMaxContactsPerPair);
      std::sort(found.begin(), found.end(), [](const Found& p, const Found& q) { return p.order < q.order; });
    }
    for (const Found& f : found)
      contacts.push_back({a, b, f.contact.point, f.contact.normal, f.contact.distance, reach_a, reach_b, low_a,
                          high_a, low_b, high_b, thinnest, complete});
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
  // (Sweep and prune, for small mobiles: along the world axis the rest pose spreads most along.)
  d.broad.reset(d.members, model.count, internal::widest_axis(rest_points), model.parent);
  d.pose.resize(model.count);
  d.margin.assign(model.count, 0);
  d.last_orientation.assign(model.count, Quat::Identity());
  d.last_position.assign(model.count, Vec3::Zero());
  d.odometer.assign(model.count, 0.0);
  for (const ComponentGeometry& g : d.geometry) d.max_pieces = std::max<std::uint64_t>(d.max_pieces, g.pieces.size());
  // 16 slots per component with shapes, 1024 to 65536 (32 bytes each, 2 MiB at most): room for the
  // piece pairs near each other.
  std::size_t slots = 1024;
  while (slots < 16 * d.members.size() && slots < 65536) slots *= 2;
  d.bounds.resize(slots);
}

CollisionDetector::~CollisionDetector() = default;
CollisionDetector::CollisionDetector(CollisionDetector&&) noexcept = default;
CollisionDetector& CollisionDetector::operator=(CollisionDetector&&) noexcept = default;

const CollisionPairs& CollisionDetector::pairs() const { return impl_->pairs; }

double CollisionDetector::reach(int component) const { return impl_->geometry[component].reach; }

double CollisionDetector::margin(int component, const Vec3& velocity, const Vec3& angular, double step,
                                 double base_margin) const {
  return component_margin(impl_->geometry[component], velocity, angular, step, base_margin);
}

void CollisionDetector::set_coherence(bool on) { impl_->coherence = on; }

double CollisionDetector::signed_distance(int a, const Vec3& position_a, const Quat& orientation_a, int b,
                                          const Vec3& position_b, const Quat& orientation_b, double near) const {
  const Impl& d = *impl_;
  const Pose pose_a{orientation_a.toRotationMatrix(), position_a}, pose_b{orientation_b.toRotationMatrix(), position_b};
  double least = near;
  internal::PieceContact c;
  for (const ConvexPiece& x : d.geometry[a].pieces) {
    const Vec3 center_x = pose_a.to_world(x.bound_center);
    for (const ConvexPiece& y : d.geometry[b].pieces) {
      const double reach = x.bound_radius + y.bound_radius + near;
      if ((center_x - pose_b.to_world(y.bound_center)).squaredNorm() > reach * reach) continue;
      // Below `near` the distance is the narrow phase's measurement; otherwise a lower bound >= near.
      if (internal::piece_contact(x, pose_a, y, pose_b, near, c)) least = std::min(least, c.distance);
    }
  }
  return least;
}

void CollisionDetector::find_contacts(const State& state, double step, double base_margin,
                                      std::vector<Contact>& contacts) {
  Impl& d = *impl_;
  contacts.clear();
  d.place(state, step, base_margin);
  d.broad.sweep(d.overlaps);
  for (const auto& [a, b] : d.overlaps)
    if (d.is_candidate(a, b)) d.narrow(a, b, contacts);
}

void CollisionDetector::keep_within_margin(const std::vector<Contact>& found, const State& state, double step,
                                           double base_margin, std::vector<Contact>& kept) const {
  const Impl& d = *impl_;
  kept.clear();
  for (const Contact& c : found) {
    const double margin =
        component_margin(d.geometry[c.a], state.velocity[c.a], state.angular[c.a], step, base_margin) +
        component_margin(d.geometry[c.b], state.velocity[c.b], state.angular[c.b], step, base_margin);
    if (c.distance < margin) kept.push_back(c);
  }
}

}  // namespace aloft
