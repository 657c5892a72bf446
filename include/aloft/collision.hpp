#pragma once
// Collision detection for a mobile: which pairs of components may ever touch (decided once, from the
// model), and, for a pose, the contacts between them.
//
//   prune_pairs         once per model: every pair of components, minus the pairs joined by a joint,
//                       minus the pairs that can never touch (the reach test of the method notes, or a
//                       sharper sound one), minus the pairs already touching in the designed pose (two
//                       pieces hung from one point; reported so the artist knows).
//   CollisionDetector   per step: broad phase over the remaining pairs (bounding volumes, so a large
//                       mobile does not pay for all pairs), then exact narrow-phase tests per shape pair
//                       (sphere-sphere, wire-wire, wire-sphere in closed form; plates, boxes and mesh
//                       pieces through GJK/EPA on convex pieces), each giving points, normals and
//                       signed distances.
//
// Contacts are *speculative*: a pair is reported when its shapes are closer than a margin that covers
// how far the two components can move towards each other in one step, so the response can stop a fast
// ball before it passes through a thin plate (no tunnelling) instead of after.

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "aloft/math.hpp"
#include "aloft/state.hpp"

namespace aloft {

struct Model;

// The pairs of components that collision detection looks at, decided once per model.
//
// In a deep mobile the reach test keeps most pairs (any ancestor's joint can swing a whole subtree
// round), and a mobile of 8191 components has 33.5 million pairs: so `candidates` is listed only for
// mobiles of up to kListedComponents components, and counted always. The detector never walks the list:
// it asks the same sound test per pair that its broad phase finds close.
struct CollisionPairs {
  static constexpr int kListedComponents = 2048;
  std::vector<std::pair<int, int>> candidates;        // (a, b), a < b, sorted: may touch; tested every step
                                                      // (empty when !listed)
  std::vector<std::pair<int, int>> touching_at_rest;  // a < b, sorted: touching when designed; left out
  long long candidate_count = 0; // pairs that may touch (candidates.size() when listed)
  long long joined = 0;          // pairs left out because a joint joins them (parent-child)
  long long never_touch = 0;     // pairs left out by the sound reach test
  long long total = 0;           // n (n - 1) / 2 over all components, the fixed one included:
                                 // total == candidate_count + joined + never_touch + touching_at_rest
  bool listed = true;            // candidates listed (count <= kListedComponents components)
};

// Pair pruning (method notes section 4). Sound: a pair it leaves out can never come into contact in
// any pose the joints allow.
CollisionPairs prune_pairs(const Model& model);

// One contact between two components at a pose.
struct Contact {
  int a = -1, b = -1;            // components, a < b
  Vec3 point = Vec3::Zero();     // world, m: midway between the two closest (or deepest) points
  Vec3 normal = Vec3::UnitY();   // world, unit, pointing from b towards a: a separates along +normal
  double distance = 0;           // m: signed gap along the normal; < 0 when the shapes overlap (depth)
  // m: the largest distance from a's (b's) centre of mass to the near part of its pieces in contact
  // (below), which bounds how far those points travel in a step (|v| + |w| reach); infinite when not
  // known (the component's reach then bounds it).
  double reach_a = INFINITY, reach_b = INFINITY;
  // A box enclosing the near part of the convex pieces of a (b) found within the margin of the other
  // component's: the points of each such piece within the pair's margin of its partner piece, the only
  // ones that can meet it within the step (collision/near_part.hpp; the margin bounds how far any point
  // moves towards the other component). In a's (b's) body frame (principal axes, origin at the centre of
  // mass; m): the fastest of those points at velocities v, w is at one of its corners, |v + w x corner|
  // (Simulation's limits on how far pieces in contact travel and how much deeper they get). Empty
  // (low > high) when not known.
  Vec3 near_low_a = Vec3::Constant(INFINITY), near_high_a = Vec3::Constant(-INFINITY);
  Vec3 near_low_b = Vec3::Constant(INFINITY), near_high_b = Vec3::Constant(-INFINITY);
  // m: the smallest half-width (half the smallest width: a wire's radius, half a plate's thickness) of
  // the pieces of a and b found within the margin: how deep a contact of the pair can get before it is
  // nearer the far side of a piece than the near one. Infinite when not known.
  double thinnest = INFINITY;
  // Whether every pair of convex pieces of a and b found within the margin is a contact of the pair:
  // false when the pair had more than the detector keeps (it keeps the deepest few), so that a piece
  // pair within the margin has no contact of its own (Simulation then bounds the pair's travel in full).
  bool complete = true;
};

class CollisionDetector {
 public:
  explicit CollisionDetector(const Model& model);  // prunes, builds convex pieces and bounding volumes
  ~CollisionDetector();
  CollisionDetector(CollisionDetector&&) noexcept;
  CollisionDetector& operator=(CollisionDetector&&) noexcept;

  const CollisionPairs& pairs() const;
  // Largest distance (m) from component i's centre of mass to its surface; 0 for one without shapes.
  double reach(int component) const;
  // Component i's share of a pair's margin (m) when find_contacts is called with `step` and
  // `base_margin` and i moves at `velocity`, turns at `angular` (world): base_margin / 2 + step (|v| +
  // |w| reach). keep_within_margin gives what find_contacts would when no component's share is wider
  // than in the call `found` came from.
  double margin(int component, const Vec3& velocity, const Vec3& angular, double step, double base_margin) const;
  // Whether piece pairs measured apart are skipped while the components' motion since cannot have
  // closed the gap (on by default; detector.cpp, "Coherence"). It never changes the contacts found, only
  // the time taken: off is for checking that, and for measuring what it saves.
  void set_coherence(bool on);
  // How the pair list of coherence was kept up to date so far (detector.cpp, "Coherence"): the calls
  // that made it afresh, and those that looked again only at the pairs of the few components that had
  // moved past their skins. (Diagnostics and tests; with coherence off every call makes it afresh.)
  struct PairListCounts {
    long long made = 0, relisted = 0;
  };
  PairListCounts pair_list_counts() const;

  // The signed distance (m, < 0 when they overlap: minus the depth) between the shapes of components a
  // and b placed at the given poses (centre of mass, orientation of the principal frame; world), exact
  // (as find_contacts measures it) where it is below `near` (> 0), and otherwise a lower bound of at least
  // `near`. Looks at every pair of their convex pieces whose enclosing spheres come within `near`; the
  // fixed component's pose is whatever is passed. For Simulation's check of a contact's motion through a
  // step (dynamics/contact_sweep.hpp).
  double signed_distance(int a, const Vec3& position_a, const Quat& orientation_a, int b, const Vec3& position_b,
                         const Quat& orientation_b, double near) const;

  // Contacts of `state` whose signed distance is below
  //     base_margin + step * (speed bound of a + speed bound of b),
  // where a component's speed bound is |v| + |w| * (its largest distance from its centre of mass to
  // its surface). `step` in s, base_margin in m. Replaces the contents of `contacts`; at most a few
  // contacts per pair (one per pair of convex pieces that come close). Deterministic: the same state
  // gives the same contacts in the same order, whatever states the detector saw before (it remembers
  // distances between calls only to skip pairs that cannot touch). Does not allocate once warmed up.
  void find_contacts(const State& state, double step, double base_margin, std::vector<Contact>& contacts);
  // Of `found`, what find_contacts(state, step, base_margin) would give, when `found` came from a call
  // at the same pose whose margins were all at least as wide: the contacts below this margin, in the
  // same order (a pair's deepest are the same whatever the margin). Their reach, near boxes, `thinnest`
  // and `complete` stay those of the wider call (reach and boxes at least as large, `thinnest` at most
  // as large, `complete` false where the narrower look might say true). Lets a caller whose velocities
  // changed after a wider look skip looking again.
  void keep_within_margin(const std::vector<Contact>& found, const State& state, double step, double base_margin,
                          std::vector<Contact>& kept) const;
  // What find_contacts(state, step, base_margin) would give, where `found` came from a call at the same
  // pose whose margins were at least as wide for every component i with wider[i] == 0: the pairs of two
  // such components are picked from `found` as keep_within_margin picks them, and only the pairs with a
  // component whose margin is wider now are looked at again. (After a knock, a few components are faster
  // than the look before assumed; looking at the whole mobile again cost as much as the first look.)
  void find_contacts_again(const std::vector<Contact>& found, const State& state, double step, double base_margin,
                           const std::vector<char>& wider, std::vector<Contact>& contacts);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace aloft
