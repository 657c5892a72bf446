// Whether the contacts found for a (sub)step allow it: how fast the components in contact turn
// (contacts_turn_slowly_enough, after the half kick and the contact impulses) and how far and how much
// deeper the pieces in contact move in the step (contacts_move_slowly_enough, once the drift is done).
// Either false halves the step (Simulation::advance_by).

#include <algorithm>
#include <cmath>
#include <limits>

#include "dynamics/contact_sweep.hpp"
#include "dynamics/contact_travel.hpp"
#include "dynamics/step_workspace.hpp"

namespace aloft {

namespace {

// A step with collisions on is accepted (contacts_move_slowly_enough) when, for every contact, either
// the pieces can get at most kDeepeningPerHalfWidth times the thinnest one's half-width (and at most
// kMaxContactTravel) deeper into each other (contact_deepening_bound), or the two sides' travels (how far
// any point of each one's pieces moves) add up to no more than that, or, where neither holds, the pair's
// motion through the step, sampled (sweep_contact), takes it no deeper than the first allows.
//  - kMaxContactTravel (m): a third of the thinnest sheet of the presets (1.5 mm). Measured on the Steel
//    Fish shaken hard for 600 s: with no such limit, pieces knocked at 2-5 m/s overlapped by up to 4.2 mm
//    within a step; with 0.5 mm, by less than a micrometre (1 mm still let 1.5 mm through). (Since then,
//    with the speculative contacts and the split impulse, that test's deepest transient overlap is 0.29 mm.)
//  - kDeepeningPerHalfWidth: a piece's half-width (Contact::thinnest: a wire's radius, half a plate's
//    thickness) is how deep a neighbour can get before it is nearer the piece's far side, where the
//    contact normal would turn round and push it through. Half of that per step, on top of an overlap
//    settled within the penetration slop (0.05 mm) and pushed out by the split impulse, keeps every
//    overlap below the half-width: 0.25 mm per step against the generated mobiles' 0.5 mm threads,
//    0.5 mm against their 2 mm plates. The bound is sharp where the travel is not (a piece spinning
//    against its neighbour, or knocked away from it, travels far but goes no deeper), so either test
//    passing accepts the step. Measured from the benchmarks' swinging state, generated-1023, 5000 steps:
//    halvings 2.83 per step with the travel limit alone, 1.86 with a flat 0.25 mm limit on the deepening
//    too, 1.62 with this one; the shaken Steel Fish's deepest transient overlap 0.294, 0.263 and 0.383 mm
//    (its threads' radius is 0.6 mm, its plates 0.75-1.25 mm thick on each side). With the near parts
//    and the sampled motion (2026-12-02): 0.081 halvings per step; 0.48-0.61 mm over 24 seeds of the
//    shaking (docs/collisions.md, "Checking the motion itself").
constexpr double kMaxContactTravel = 5e-4;
constexpr double kDeepeningPerHalfWidth = 0.5;

// The largest speed (m/s) of a corner of the box [low, high] (body frame of a body at `orientation`,
// origin at its centre of mass) when the body moves at v and turns at w (world): max |v + w x r| over
// the 8 corners r. |v + w x r| is convex in r, so this bounds the speed of every point of the box.
double fastest_corner_speed(const Quat& orientation, const Vec3& v, const Vec3& w, const Vec3& low, const Vec3& high) {
  const Mat3 turn = orientation.toRotationMatrix();
  const Vec3 w_body = turn.transpose() * w;
  const Vec3 middle = turn.transpose() * v + w_body.cross(0.5 * (low + high));  // the box centre's velocity
  const Vec3 half = 0.5 * (high - low);
  const Vec3 e0 = w_body.cross(Vec3(half.x(), 0, 0)), e1 = w_body.cross(Vec3(0, half.y(), 0)),
             e2 = w_body.cross(Vec3(0, 0, half.z()));
  double fastest = 0;
  for (const double s0 : {-1.0, 1.0})
    for (const double s1 : {-1.0, 1.0})
      for (const double s2 : {-1.0, 1.0})
        fastest = std::max(fastest, (middle + s0 * e0 + s1 * e1 + s2 * e2).squaredNorm());
  return std::sqrt(fastest);
}

// The largest speed (m/s) of a corner of the box [low, high] (as above) due to the turn w alone:
// max |w x r| over the 8 corners r, which bounds |w x r| over the box (a convex function of r).
double fastest_turn_speed(const Quat& orientation, const Vec3& w, const Vec3& low, const Vec3& high) {
  const Vec3 w_body = orientation.conjugate() * w;
  double fastest = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 r(corner & 1 ? high.x() : low.x(), corner & 2 ? high.y() : low.y(), corner & 4 ? high.z() : low.z());
    fastest = std::max(fastest, w_body.cross(r).squaredNorm());
  }
  return std::sqrt(fastest);
}

}  // namespace

// With collisions on: whether every pair of components in contact turns at most kOldTurnLimit in a step
// of h at these angular velocities (save about a component's axis of least moment, below). The
// drift-error rule alone lets a fast spinner turn up to kMaxTurn (4 times more); a component a knock sends
// spinning, or that the joints' corrections speed up after detection, then sweeps past the contacts found
// at the start of the step: on the Steel Fish shaken hard, overlaps of 9-18 mm within 80 s with the
// drift-error rule alone, none above 0.4 micrometres in 120 s with this limit too. (It also keeps
// contact_deepening_bound's second-order terms small; that bound holds up to kMaxTurn as well, test
// ContactTravel.BoundsTheOverlapAfterTheDriftOfTheFastestTurnAStepTakes.) A component in
// no contact needs no such limit: the detection margin, h (|v| + |w| reach), covers its whole sweep, so
// anything it could reach in the step is a contact of its own. (Until 2026-11-24 the limit held for every
// component: generated-1023, 5000 steps from the swinging state, 1.62 -> 1.56 halvings per step without
// it for the components in no contact.) A turn about the axis a slender component lies along (its
// principal axis of least moment) moves nothing of a wire on that axis but its surface, about itself: so
// the limit is on the rest of the turn, h |w - (w . a) a| <= kOldTurnLimit, where the turn about the axis
// moves the pieces in contact little, h |w . a| rho <= kMaxContactTravel, rho the farthest corner of the
// box around their near part (Contact::near_low_a ...) from the axis. Those spins are what the limit
// halved at generated-8191: light wires (moments 6e-11 against 2e-8 kg m^2) turning 0.06-0.1 rad per step
// about their axes and 0.01-0.03 across them: this lets 111 of the 147 rejections of `aloft_step_profile
// 8191 2000 1 swinging:7` through (259 of 326 for seed 1; docs/performance.md, "2026-12-05, night").
// Always true for the shortest step the subdivision allows (it must make progress).
bool Simulation::contacts_turn_slowly_enough(double h, const std::vector<Vec3>& angular) const {
  if (at_finest_step(h)) return true;
  // Component i of a contact, with the box (principal frame, m; empty when not known) around its near part.
  const auto turns_slowly = [&](int i, const Vec3& near_low, const Vec3& near_high) {
    if (i == 0 || h * angular[i].norm() <= kOldTurnLimit) return true;
    if (!(near_low.x() <= near_high.x())) return false;
    int axis = 0;  // of least moment
    const Vec3& moments = model_.principal_moments[i];
    for (int k = 1; k < 3; ++k)
      if (moments[k] < moments[axis]) axis = k;
    const Vec3 w = state_.orientation[i].conjugate() * angular[i];  // principal frame
    const double about_axis = w[axis];
    if (!(h * std::hypot(w[(axis + 1) % 3], w[(axis + 2) % 3]) <= kOldTurnLimit)) return false;
    // The box's farthest corner from the axis: its extent across it.
    const auto farthest = [&](int k) { return std::max(std::abs(near_low[k]), std::abs(near_high[k])); };
    const double rho = std::hypot(farthest((axis + 1) % 3), farthest((axis + 2) % 3));
    return h * std::abs(about_axis) * rho <= kMaxContactTravel;
  };
  for (const Contact& c : work_->contacts)
    if (!turns_slowly(c.a, c.near_low_a, c.near_high_a) || !turns_slowly(c.b, c.near_low_b, c.near_high_b))
      return false;
  return true;
}

// With collisions on, once the step's drift is done (rattle's steps 2 and 2b): whether the contacts found
// for this step allow the drift just taken from state_: every body moved by h times its half-step velocity
// work.next.velocity and turned by h times its drift angular velocity w_m = work.drift_map
// work.next.angular, and, when `pushed`, also moved by h times the overlap push's pseudo-velocity
// work.pseudo (its turn after the drift's). These are the step's final motions: the contact impulses, the
// joints' corrections and the contacts' corrections after them, and the push. (Until 2026-12-02 this was
// checked on the velocities right after the contact impulses, which the joints' corrections and the push
// then changed: on the shaken Steel Fish, pairs ended up to 0.84 mm deep where their check allowed 0.4
// mm, mostly by the push, which is solved for the contacts' points and normals at the start of the step.)
// A contact is a constraint at one point with one normal, from the closest features at the start of the
// step; a plate edge sweeping several millimetres per step past a 2 mm wire can pierce it away from that
// point before the next step sees it. Every pair in contact must turn little
// (contacts_turn_slowly_enough), and each contact must either
//   - travel little: the farthest any point of the near parts of a's pieces (Contact::near_low_a ...)
//     moves and the farthest any of b's does add up to no more than the deepening allowed below, or
//   - deepen little: its pieces can get at most kDeepeningPerHalfWidth of the thinnest one's half-width
//     (and at most kMaxContactTravel) deeper into each other (contact_deepening_bound), or, where neither
//     bound does for some contact of a pair,
//   - the pair's motion through the step, sampled (sweep_contact), takes it no deeper than that.
// Always true for the shortest step the subdivision allows (it must make progress).
bool Simulation::contacts_move_slowly_enough(double h, bool pushed) const {
  const StepWorkspace& work = *work_;
  if (at_finest_step(h)) return true;
  if (!contacts_turn_slowly_enough(h, work.next.angular)) return false;
  // Body i's motion in the step: velocity v (the push's included), the drift's turn rate w_m and the
  // push's w_p. A turn by h w_m and then by h w_p is one by h (w_m + w_p) plus (h^2 / 2) w_p x w_m to
  // second order (Baker-Campbell-Hausdorff): the bound below takes w_m + w_p, and that difference as the
  // precession it allows for (ContactSide::precession: how far the turn departs from h times the angular
  // velocity given). Points move by at most h (|w_m| + |w_p|) times their distance from the centre of mass.
  struct Motion {
    Vec3 velocity = Vec3::Zero(), drift = Vec3::Zero(), push = Vec3::Zero();
  };
  const auto motion = [&](int i) {
    Motion m;
    if (i == 0) return m;  // the fixed component does not move
    m.velocity = work.next.velocity[i];
    m.drift = work.drift_map[i] * work.next.angular[i];
    if (pushed) {
      m.velocity += work.pseudo[i].head<3>();
      m.push = work.pseudo[i].tail<3>();
    }
    return m;
  };
  const auto farthest_corner = [](const Vec3& low, const Vec3& high) {
    return low.cwiseAbs().cwiseMax(high.cwiseAbs()).norm();
  };
  const auto side = [&](int i, double contact_reach, const Vec3& low, const Vec3& high) {
    const Motion m = motion(i);
    ContactSide s;
    s.position = state_.position[i];
    s.orientation = state_.orientation[i];
    s.velocity = m.velocity;
    s.angular = m.drift + m.push;
    s.precession = m.push.cross(m.drift);
    s.reach = std::min(work.detector->reach(i), contact_reach);
    s.near_low = low;
    s.near_high = high;
    return s;
  };
  // How far any point of one side's pieces in contact travels (m), from the speed of their fastest point:
  // at most |v| + |w| times the pieces' reach from the centre of mass (travel_by_reach), and at most the
  // fastest corner of the box around them, |v + w x corner| (travel_by_box; sharper for a piece turning
  // about an axis through or near it, as a plate spinning on its thread; to first order in the turn;
  // infinite where no box is known). Any other piece of the pair that could come near within the step is
  // within the detection margin, which the component's whole reach sets, so it is a contact of its own,
  // checked here too.
  const auto travel_by_reach = [&](const Contact& c, int k) {
    const int i = k == 0 ? c.a : c.b;
    if (i == 0) return 0.0;
    const Motion m = motion(i);
    const double reach = std::min(work.detector->reach(i), k == 0 ? c.reach_a : c.reach_b);
    return h * (m.velocity.norm() + (m.drift.norm() + m.push.norm()) * reach);
  };
  const auto travel_by_box = [&](const Contact& c, int k) {
    const int i = k == 0 ? c.a : c.b;
    const Vec3& low = k == 0 ? c.near_low_a : c.near_low_b;
    const Vec3& high = k == 0 ? c.near_high_a : c.near_high_b;
    if (i == 0 || !(low.x() <= high.x())) return std::numeric_limits<double>::infinity();
    const Motion m = motion(i);
    return h * (fastest_corner_speed(state_.orientation[i], m.velocity, m.drift, low, high) +
                m.push.norm() * farthest_corner(low, high));
  };
  // What a contact may get deeper in one step (m): kDeepeningPerHalfWidth of its pieces' thinnest
  // half-width, and at most kMaxContactTravel.
  const auto allowed_deepening = [](const Contact& c) {
    return std::min(kMaxContactTravel, kDeepeningPerHalfWidth * c.thinnest);
  };
  // The pieces can come closer by at most the sum of how far the two sides travel: when that is within
  // what the contact may deepen, so is the deepening. The cheap bound first, the boxes' corners only
  // where it is not enough. (Until 2026-12-06 each side alone was held to kMaxContactTravel, which let the
  // two come 2 kMaxContactTravel closer: 1 mm, against the generated mobiles' 0.5 mm threads. On
  // generated-1023 after the breeze, a thread and its neighbour, 0.08 mm apart, met at 0.7 m/s within one
  // step that both sides' travels allowed, and the next step began 0.62 mm deep: 1.25 times the thread's
  // radius. docs/collisions.md, "How far pieces in contact may move per step".)
  const auto travels_little = [&](const Contact& c) {
    const double allowed = allowed_deepening(c);
    const double by_reach[2] = {travel_by_reach(c, 0), travel_by_reach(c, 1)};
    if (by_reach[0] + by_reach[1] <= allowed) return true;
    return std::min(by_reach[0], travel_by_box(c, 0)) + std::min(by_reach[1], travel_by_box(c, 1)) <= allowed;
  };
  // The bound on how much deeper the pieces get, where it covers them all: every nearby piece pair of
  // the two components is a contact (c.complete), each within a known box.
  const auto deepens_little = [&](const Contact& c) {
    if (!c.complete || !(c.near_low_a.x() <= c.near_high_a.x()) || !(c.near_low_b.x() <= c.near_high_b.x()))
      return false;
    return contact_deepening_bound(c, side(c.a, c.reach_a, c.near_low_a, c.near_high_a),
                                   side(c.b, c.reach_b, c.near_low_b, c.near_high_b), h, true) <= allowed_deepening(c);
  };
  // The pair's motion as the step moved it, and how far any point of each near part moved: at most
  // h (|v| + max |w_m x r| + |w_p| |r|) over the near box's corners r (|w x r| is convex in r, and turning
  // the arm r about w does not change it), or h (|v| + (|w_m| + |w_p|) reach) where no box is known.
  const auto swept = [&](int i, double contact_reach, const Vec3& low, const Vec3& high) {
    const Motion m = motion(i);
    SweptBody body;
    body.fixed = i == 0;
    body.position = state_.position[i];
    body.orientation = state_.orientation[i];
    body.velocity = m.velocity;
    body.drift_angular = m.drift;
    body.push_angular = m.push;
    const double turning =
        low.x() <= high.x()
            ? fastest_turn_speed(state_.orientation[i], m.drift, low, high) + m.push.norm() * farthest_corner(low, high)
            : (m.drift.norm() + m.push.norm()) * std::min(work.detector->reach(i), contact_reach);
    body.travel = h * (m.velocity.norm() + turning);
    return body;
  };
  const std::vector<Contact>& contacts = work.contacts;  // sorted by (a, b)
  for (std::size_t first = 0, last; first < contacts.size(); first = last) {
    // The contacts of one pair: [first, last).
    bool bounded = true;
    double start_overlap = 0;
    for (last = first; last < contacts.size() && contacts[last].a == contacts[first].a &&
                       contacts[last].b == contacts[first].b;
         ++last) {
      const Contact& c = contacts[last];
      bounded = bounded && (travels_little(c) || deepens_little(c));
      start_overlap = std::max(start_overlap, -c.distance);
    }
    if (bounded) continue;
    const Contact& c = contacts[first];  // the pair's near boxes, reach and thinnest are the same in each
    const double allowed = allowed_deepening(c);
    const SweepResult sweep =
        sweep_contact(*work.detector, c.a, swept(c.a, c.reach_a, c.near_low_a, c.near_high_a), c.b,
                      swept(c.b, c.reach_b, c.near_low_b, c.near_high_b), h, start_overlap, allowed, c.thinnest);
    if (!sweep.shallow) return false;
  }
  return true;
}

}  // namespace aloft
