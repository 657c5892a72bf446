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
// Coherence. Between calls the pieces move little. Each component carries an odometer: the sum, over
// calls, of how far any point of it moved since the call before (|dx| + 2 sin(angle / 2) reach, exact
// bound for a rigid motion). Two things rest on it:
//  - The pair list. The broad phase runs on boxes grown by each component's margin plus a skin, and its
//    candidate pairs are kept from call to call. A pair left out was farther apart than the two grown
//    margins, so it can come within the margins of a later call only if a component moved by more than
//    its skin, or its margin grew by more, since the list was made: until then the list holds every pair
//    that can give a contact, and the broad phase and the filter are not run again. The skin is a few
//    steps of each component's own motion (kSkinSteps), at least kSkinMin. When only a few components
//    have moved past their skins (a knock), only their pairs are looked for again, from their new boxes
//    against everyone's listed ones (relist); the others' pairs stay as they were.
//  - Distances. Most piece pairs the narrow phase looks at are apart by more than the margin, step after
//    step (a plate beside its sibling). For those, piece_contact() leaves a lower bound of their
//    distance, kept with the pair. A piece pair measured at distance d is apart by at least d - (what both
//    odometers added since), so while that exceeds the margin (and the distance's own error,
//    kCoherenceSlack), it cannot be in contact and is not measured again; and while the least of those
//    bounds over a pair's pieces does, the pair is not looked at at all.
// Both skip only pairs that would give no contact: the contacts are the same as without them (a fresh
// detector, or one with set_coherence(false), which runs the broad phase on the margins alone at every
// call and measures every piece pair).

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

// The skin of a component's box in the pair list (see the top of this file): kSkinSteps times how far it
// moves in a step at its present speed (its margin less the base margin's half), at least kSkinMin (m).
// The list is made again when some component has moved, or its margin has grown, by more than its skin:
// a component moving steadily lasts kSkinSteps steps; a larger skin lasts longer but puts more pairs in
// the list, each looked at (cheaply, while far) at every call. Callgrind, from the benchmarks' swinging
// state (aloft_step_profile N STEPS 1 swinging, the same trajectory whatever the skin), instructions:
//   generated-8191, 1000 steps: 2 steps and 0.5 mm 33.84 G; 4 and 0.5 mm 33.72 G; 4 and 1 mm 33.72 G;
//   8 and 2 mm 34.61 G;
//   generated-1023, 5000 steps: 4 and 1 mm 50.01 G; 8 and 2 mm 49.63 G.
// The larger mobile, which the list helps most, decides: 4 steps and 1 mm.
constexpr double kSkinSteps = 4;
constexpr double kSkinMin = 1e-3;
// When more than 1 / kRelistFraction of the components have moved past their skins, the whole pair list
// is made afresh; when fewer, only their pairs are looked for again (update_list). Callgrind,
// `aloft_step_profile 1023 5000 1 swinging:7` (the same contacts and trajectory whatever the fraction):
// the whole list at every call that needs one 35.97 G instructions; 1/8 35.56 G; 1/4 35.55 G; 1/2
// 37.61 G (a relist of many costs more than a sweep). A swinging mobile moves its components past their
// skins together, every few steps (all were listed at once): those calls still make the list afresh.
constexpr std::size_t kRelistFraction = 8;

// One remembered piece-pair distance: a lower bound of the signed distance when measured (m), -infinity
// when none is known (never measured, or in contact), and the two components' odometers then (m).
struct DistanceBound {
  double distance = -INFINITY;
  double odometer_a = 0, odometer_b = 0;
};

// A candidate pair of the list: its components, where its piece pairs' bounds start (pieces of a times
// pieces of b of them, b's piece outer), and a lower bound of the pair's distance (the least over its
// piece pairs; -infinity when unknown) with the odometers it was taken at.
struct CandidatePair {
  int a = 0, b = 0;
  std::uint32_t bounds = 0;
  double lower = -INFINITY;
  double odometer_a = 0, odometer_b = 0;
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
  bool coherence = true;              // keep the pair list and skip pairs by their distances (set_coherence)
  // The pair list, sorted by (a, b), and its piece pairs' distance bounds; per component, the odometer,
  // margin and skin when the list was made (m). The bounds live in one pool: a pair that stays in the
  // list keeps its range, a new pair's range is added at the end, and a dropped pair's range is left
  // unused until take_list packs the pool (when it is more than twice the ranges in use).
  std::vector<CandidatePair> list, next_list;
  std::vector<DistanceBound> bounds, next_bounds;
  std::vector<double> listed_odometer, listed_margin, skin;
  bool listed = false;
  PairListCounts list_counts;

  // Per-call scratch, indexed by component (sized once).
  std::vector<Pose> pose;
  std::vector<double> margin;      // the component's own speculative margin, m
  std::vector<std::pair<int, int>> overlaps, fresh_overlaps;
  std::vector<int> stale;          // update_list's: the components to list again
  std::vector<char> is_stale;      // relist's: by component, whether in `stale` (all 0 between calls)
  std::vector<Vec3> piece_center;  // world centres of a's pieces for the current pair
  // The pieces' enclosing spheres, all components' in one array (component i's are
  // sphere[first_sphere[i]] to sphere[first_sphere[i + 1]], in piece order): the narrow phase's first
  // test reads only these. (Read from the pieces themselves, each component's in its own allocation,
  // the loads missed the cache: perf on generated-8191 put 58 % of narrow()'s own time on them.)
  struct PieceSphere {
    Vec3 center;    // body frame, m
    double radius;  // m
  };
  std::vector<PieceSphere> sphere;
  std::vector<std::uint32_t> first_sphere;
  struct Found {
    PieceContact contact;
    const ConvexPiece *piece_a, *piece_b;
    int order;  // the how-manieth of the pair's contacts found (piece order)
  };
  std::vector<Found> found;

  Impl(const Model& model, std::vector<ComponentGeometry> g)
      : geometry(std::move(g)), filter(model, geometry), pairs(internal::prune_pairs(model, geometry, filter)) {
    first_sphere.reserve(geometry.size() + 1);
    for (const ComponentGeometry& component : geometry) {
      first_sphere.push_back(static_cast<std::uint32_t>(sphere.size()));
      for (const ConvexPiece& piece : component.pieces) sphere.push_back({piece.bound_center, piece.bound_radius});
    }
    first_sphere.push_back(static_cast<std::uint32_t>(sphere.size()));
  }

  bool is_candidate(int a, int b) const {
    return !filter.joined(a, b) && filter.may_touch(a, b) &&
           !std::binary_search(pairs.touching_at_rest.begin(), pairs.touching_at_rest.end(), std::pair{a, b});
  }

  void place(const State& state, double step, double base_margin) {
    for (int i : members) {
      const ComponentGeometry& g = geometry[i];
      margin[i] = component_margin(g, state.velocity[i], state.angular[i], step, base_margin);
      // Not moved since the last call (the look after a knock, at the same pose): the pose, and the
      // odometer, stay as they are.
      if (placed_before && state.position[i] == last_position[i] && state.orientation[i].coeffs() == last_orientation[i].coeffs())
        continue;
      if (placed_before) {
        // |q1 . q2| = cos(angle / 2); a point at distance r from the centre moves by 2 sin(angle / 2) r.
        const double c = std::min(1.0, std::abs(last_orientation[i].dot(state.orientation[i])));
        const double chord = 2.0 * std::sqrt(std::max(0.0, 1.0 - c * c));
        odometer[i] += (state.position[i] - last_position[i]).norm() + chord * g.reach;
      }
      last_orientation[i] = state.orientation[i];
      last_position[i] = state.position[i];
      pose[i] = {state.orientation[i].toRotationMatrix(), state.position[i]};
    }
    placed_before = true;
  }

  // Brings the pair list up to this call's poses and margins, so that it holds every pair that can give
  // a contact. It still holds every pair of components that have not moved, nor had their margin grow,
  // by more than their skin since they were last listed: only the pairs of those that have (`stale`)
  // are looked for again (relist). When many have, or the list is not kept (coherence off), it is made
  // afresh (make_list).
  void update_list(double base_margin) {
    if (!listed || !coherence) {
      make_list(base_margin);
      return;
    }
    stale.clear();
    const std::size_t most = members.size() / kRelistFraction;  // stale components a relist is for
    for (int i : members) {
      if (odometer[i] - listed_odometer[i] + std::max(0.0, margin[i] - listed_margin[i]) <= skin[i]) continue;
      if (stale.size() == most) {
        make_list(base_margin);
        return;
      }
      stale.push_back(i);
    }
    if (!stale.empty()) relist(base_margin);
  }

  // Component i's box in the list: at this call's pose, grown by its margin and a new skin (with
  // coherence off, the margin alone), and the odometer and margin it is listed at.
  [[gnu::always_inline]] void list_component(int i, double base_margin) {
    const ComponentGeometry& g = geometry[i];
    skin[i] = coherence ? std::max(kSkinMin, kSkinSteps * (margin[i] - 0.5 * base_margin)) : 0.0;
    broad.box(i) = internal::box_of(pose[i], g.box_center, g.box_half, margin[i] + skin[i]);
    listed_odometer[i] = odometer[i];
    listed_margin[i] = margin[i];
  }

  // Makes the pair list at this call's poses: the broad phase over every component.
  void make_list(double base_margin) {
    ++list_counts.made;
    for (int i : members) list_component(i, base_margin);
    broad.sweep(overlaps);
    take_list(overlaps);
  }

  // The pair list with the stale components listed again: their pairs from the broad phase on their new
  // boxes against everyone's box in the list, the other pairs as they were. (A pair of two components
  // that are not stale, left out of the list, was apart by more than their grown margins when the later
  // of the two was listed, and neither has moved by more than its skin since.)
  void relist(double base_margin) {
    ++list_counts.relisted;
    for (int i : stale) {
      list_component(i, base_margin);
      is_stale[i] = 1;
    }
    broad.overlaps_of(stale, fresh_overlaps);
    overlaps.clear();
    std::size_t f = 0;  // the first of fresh_overlaps not yet merged (both sorted by (a, b))
    for (const CandidatePair& pair : list) {
      if (is_stale[pair.a] || is_stale[pair.b]) continue;
      const std::pair<int, int> kept{pair.a, pair.b};
      for (; f < fresh_overlaps.size() && fresh_overlaps[f] < kept; ++f) overlaps.push_back(fresh_overlaps[f]);
      overlaps.push_back(kept);
    }
    overlaps.insert(overlaps.end(), fresh_overlaps.begin() + static_cast<std::ptrdiff_t>(f), fresh_overlaps.end());
    for (int i : stale) is_stale[i] = 0;
    take_list(overlaps);
  }

  // The pair list from the broad phase's overlapping pairs (sorted), less those the filter drops, with
  // the remembered distances of the pairs already in the old list (their ranges of the pool, as they are).
  void take_list(const std::vector<std::pair<int, int>>& candidates) {
    next_list.clear();
    std::size_t old = 0, in_use = 0;
    for (const auto& [a, b] : candidates) {
      while (old < list.size() && (list[old].a < a || (list[old].a == a && list[old].b < b))) ++old;
      const bool kept = old < list.size() && list[old].a == a && list[old].b == b;
      if (!kept && !is_candidate(a, b)) continue;
      const std::size_t count = pieces_of(a, b);
      if (kept) {
        next_list.push_back(list[old]);
      } else {
        next_list.push_back(CandidatePair{a, b, static_cast<std::uint32_t>(bounds.size())});
        bounds.resize(bounds.size() + count);
      }
      in_use += count;
    }
    std::swap(list, next_list);
    if (bounds.size() > 2 * in_use) pack_bounds();
    listed = true;
  }

  // The number of piece pairs (and so of distance bounds) of components a and b.
  std::size_t pieces_of(int a, int b) const { return geometry[a].pieces.size() * geometry[b].pieces.size(); }

  // The pool of distance bounds with only the list's ranges, in the list's order.
  void pack_bounds() {
    next_bounds.clear();
    for (CandidatePair& pair : list) {
      const std::size_t count = pieces_of(pair.a, pair.b);
      const auto from = bounds.begin() + pair.bounds;
      pair.bounds = static_cast<std::uint32_t>(next_bounds.size());
      next_bounds.insert(next_bounds.end(), from, from + static_cast<std::ptrdiff_t>(count));
    }
    std::swap(bounds, next_bounds);
  }

  // Whether every piece pair of a pair of the list is still apart by more than the pair's margin: its
  // least remembered bound, less what both odometers gained since, exceeds it (coherence on).
  bool still_apart(const CandidatePair& pair) const {
    return coherence && pair.lower - (odometer[pair.a] - pair.odometer_a) - (odometer[pair.b] - pair.odometer_b) >
                            margin[pair.a] + margin[pair.b];
  }

  // The contacts of a pair of the list, and its piece pairs' distance bounds brought up to date.
  void narrow(CandidatePair& pair, std::vector<Contact>& contacts) {
    const int a = pair.a, b = pair.b;
    const double pair_margin = margin[a] + margin[b];
    const PieceSphere* sphere_a = sphere.data() + first_sphere[a];
    const PieceSphere* sphere_b = sphere.data() + first_sphere[b];
    const std::size_t pieces_a = first_sphere[a + 1] - first_sphere[a];
    const std::size_t pieces_b = first_sphere[b + 1] - first_sphere[b];
    piece_center.resize(pieces_a);
    for (std::size_t k = 0; k < pieces_a; ++k) piece_center[k] = pose[a].to_world(sphere_a[k].center);
    found.clear();
    PieceContact c;
    double lower = INFINITY;  // the least lower bound of the piece pairs' distances, now
    DistanceBound* bound = bounds.data() + pair.bounds;
    for (std::size_t l = 0; l < pieces_b; ++l) {
      const Vec3 cy = pose[b].to_world(sphere_b[l].center);
      for (std::size_t k = 0; k < pieces_a; ++k, ++bound) {
        const double spheres = (piece_center[k] - cy).norm() - sphere_a[k].radius - sphere_b[l].radius;
        if (spheres > pair_margin) {
          lower = std::min(lower, spheres - kCoherenceRelativeSlack * spheres - kCoherenceSlack);
          continue;
        }
        if (coherence) {
          const double apart = bound->distance - (odometer[a] - bound->odometer_a) - (odometer[b] - bound->odometer_b) -
                                kCoherenceRelativeSlack * std::abs(bound->distance) - kCoherenceSlack;
          if (apart > pair_margin) {
            lower = std::min(lower, apart);
            continue;
          }
        }
        const ConvexPiece &x = geometry[a].pieces[k], &y = geometry[b].pieces[l];
        if (internal::piece_contact(x, pose[a], y, pose[b], pair_margin, c)) {
          found.push_back({c, &x, &y, static_cast<int>(found.size())});
          bound->distance = -INFINITY;
          lower = -INFINITY;
        } else {
          *bound = {c.distance, odometer[a], odometer[b]};
          lower = std::min(lower, c.distance - kCoherenceRelativeSlack * std::abs(c.distance) - kCoherenceSlack);
        }
      }
    }
    pair.lower = lower;
    pair.odometer_a = odometer[a];
    pair.odometer_b = odometer[b];
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
  d.listed_odometer.assign(model.count, 0.0);
  d.listed_margin.assign(model.count, 0.0);
  d.skin.assign(model.count, 0.0);
  d.is_stale.assign(model.count, 0);
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

CollisionDetector::PairListCounts CollisionDetector::pair_list_counts() const { return impl_->list_counts; }

void CollisionDetector::set_coherence(bool on) {
  impl_->coherence = on;
  impl_->listed = false;
}

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
  d.update_list(base_margin);
  for (CandidatePair& pair : d.list) {
    if (!d.still_apart(pair)) d.narrow(pair, contacts);
  }
}

void CollisionDetector::find_contacts_again(const std::vector<Contact>& found, const State& state, double step,
                                            double base_margin, const std::vector<char>& wider,
                                            std::vector<Contact>& contacts) {
  Impl& d = *impl_;
  contacts.clear();
  d.place(state, step, base_margin);  // the same pose: the odometers stay
  d.update_list(base_margin);
  std::size_t next = 0;  // the first of `found` not before the pair (both sorted by (a, b))
  for (CandidatePair& pair : d.list) {
    const auto before = [&](const Contact& c) { return c.a < pair.a || (c.a == pair.a && c.b < pair.b); };
    while (next < found.size() && before(found[next])) ++next;
    const double pair_margin = d.margin[pair.a] + d.margin[pair.b];
    if (!wider[pair.a] && !wider[pair.b]) {
      for (; next < found.size() && found[next].a == pair.a && found[next].b == pair.b; ++next)
        if (found[next].distance < pair_margin) contacts.push_back(found[next]);
      continue;
    }
    if (!d.still_apart(pair)) d.narrow(pair, contacts);
  }
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
