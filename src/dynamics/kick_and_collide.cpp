// rattle()'s step 1: the first half kick (applied forces and the guessed joint impulses), checked
// against the step-size rule as each body is kicked, then, with collisions on, the detection and the
// contacts' impulses solved with the joints.

#include <algorithm>
#include <cmath>

#include "common/cpu_dispatch.hpp"
#include "dynamics/step_workspace.hpp"

namespace aloft {

namespace {

// Contacts are looked for within this distance (m) plus what the pair can close in one step. Half a
// millimetre keeps a resting contact (which settles to within the penetration slop, 0.05 mm) in the
// list from one step to the next without testing pieces that are far apart.
constexpr double kContactMargin = 5e-4;
// The detection at the start of a step looks this much (m) further from each component than its margin,
// so that when the impulses change the velocities, the contacts within the new margins can be picked
// from what it found instead of detecting again, as long as no component's margin grew by more (see
// kick_and_collide).
constexpr double kRecheckSlack = 1e-4;
// The most contact solves in a step (the first, and one more each time the look after a solve's impulses
// finds another list or a contact left out closing): a knock is passed on across up to this many pairs
// within the step (a row of 5 pieces). A pair it closes beyond that waits for the next step; the last
// look's list is what the step's motion check holds to what a step may deepen a contact (rattle:
// contacts_move_slowly_enough).
constexpr int kMaxSolvesPerLook = 4;

// A later solve of the step's contacts (ContactResponse::resolve, `again`) added to the step's report:
// what the step leaves unsolved, and the largest overlaps, are the last list's.
void add_later_solve(ContactStepReport& report, const ContactStepReport& again) {
  report.contacts = again.contacts;
  report.dropped = again.dropped;
  report.solves += again.solves;
  report.solved += again.solved;
  report.reused += again.reused;
  report.iterations += again.iterations;
  report.active += again.active;
  report.sticking += again.sticking;
  report.sliding += again.sliding;
  report.restitution_dropped = report.restitution_dropped || again.restitution_dropped;
  report.friction_dropped = report.friction_dropped || again.friction_dropped;
  report.frictionless = std::max(report.frictionless, again.frictionless);
  report.energy_change += again.energy_change;
  report.deepest = std::max(report.deepest, again.deepest);
  report.deepest_relative = std::max(report.deepest_relative, again.deepest_relative);
}

}  // namespace

// rattle()'s step 1 (and the contacts): the first half kick, with (guess) or without the joint impulses
// guessed from the last steps, then the contacts' impulses. False, leaving the step to be halved, when
// the step-size rule or contacts_turn_slowly_enough finds h too long for the velocities it made.
ALOFT_CPU_DISPATCH bool Simulation::kick_and_collide(double h, bool guess, ContactStepReport& contact_report, bool& has_pseudo) {
  const int n = model_.count;
  const std::vector<int>& parent = model_.parent;
  StepWorkspace& work = *work_;
  const State& now = state_;
  State& next = work.next;
  TreeSolver& solver = work.solver;
  const std::vector<Vec3>& r = solver.child_arm();    // at the factored pose
  const std::vector<Vec3>& s = solver.parent_arm();
  const std::vector<Mat3>& inertia = solver.world_inertia();
  const std::vector<Mat3>& inverse_inertia = solver.world_inverse_inertia();

  // 1. Half kick: applied impulses (h/2) f at the current state plus a guess of the joint impulses P,
  //    which act on the child as (P, r x P) and on the parent as -(P, s x P). Children come first
  //    (parent[i] < i, the bodies in decreasing order), so each body's sum is complete when it is kicked
  //    (one pass: kick_sum collects what the children's guesses give their parents). The guess, when the
  //    last two steps had this length: P = M_n + (P_n - M_n-1), where P_n is the last step's first-kick
  //    impulse and M_n, M_n-1 the second-kick (velocity projection) impulses of the last two steps. M_n
  //    acts at this step's pose, where P will; P_n and M_n-1 both acted at the last step's start, and
  //    their difference (what closing the joints at the end of a drift needs beyond making the velocities
  //    tangent: the curvature of the joints' paths) changes slowly. Measured against extrapolating P
  //    (2 P_n - P_n-1), which it replaced: Newton corrections per step 1.14 -> 0.96 on the Steel Fish,
  //    3.00 -> 2.02 on generated-1023 after the breeze (docs/performance.md). When only the last step had
  //    this length (the second step of a run, or the second after the step length changed), P = M_n:
  //    the same guess without the difference, which needs two steps. (Until 2026-11-25 it was P_n, the
  //    last first-kick impulse, which acted at the last pose; after the first step of a run, which has no
  //    guess, that gap was 3380 times the tolerance on generated-65535 and took 3 corrections, against 1
  //    with M_n, and the corrections' impulses stay in the difference term of the steps after:
  //    generated-127, 1000 steps from the swinging state, 1.19 -> 1.12 tree solves per step.)
  //    Otherwise the last step's P scaled to this step's length. After a step with contact impulses,
  //    P = M_n too: that step's P_n holds the corrections that closed the joints its knocks had opened
  //    (the contact impulses keep the joints together to first order in h only: a knock changing the spin
  //    w of a body by dw opens its joint by about h^2 |w| |dw| times the arm in the drift), and the
  //    knocks of one step are not those of the next: on generated-1023 (seed 7 below), of 24,442 pairs
  //    with a normal impulse in a (sub)step, 12,489 had none in the one before. Carried on as curvature,
  //    those corrections opened the joints of the next step instead. Measured with
  //    `aloft_step_profile 1023 5000 1 swinging:SEED` (seeds 7, 1, 2, 3), Newton corrections after the
  //    drift per step 2.96, 4.29, 0.86, 2.95 -> 1.99, 2.29, 0.83, 2.23 (docs/performance.md, "2026-12-02,
  //    later"); with the difference term of the last step without contact impulses instead of none,
  //    2.33, 3.79, 0.87, 2.87; with M_n only at the joints of the bodies in contact and of their children,
  //    2.75, 4.32 (the corrections spread through the tree). On the shaken Steel Fish, whose contacts
  //    last longer, it costs 3 % more corrections (2.157 -> 2.226 per step, median of 40 seeds). Each
  //    body's new angular velocity is checked against the step-size rule as it is made (spins_ok), while
  //    the body's data are at hand.
  const bool predict = guess && work.older_step == work.impulse_step && work.impulse_step == h &&
                       !work.impulse_after_contacts;
  const bool project = guess && !predict && work.impulse_step == h;
  const double warm = guess && work.impulse_step > 0 ? h / work.impulse_step : 0.0;
  std::vector<Vec6>& sum = work.kick_sum;
  const StepSizeRule& rule = work.step_rule;
  bool spins_ok = true;
  for (int i = n - 1; i >= 1; --i) {
    const Vec3 impulse = predict   ? Vec3(work.projection[i] + (work.impulse[i] - work.older_projection[i]))
                         : project ? work.projection[i]
                                   : Vec3(warm * work.impulse[i]);
    work.step_impulse[i] = impulse;
    const Vec3 momentum = damped() ? Vec3(inertia[i] * now.angular[i]) : Vec3::Zero();
    Vec6 kick = (0.5 * h) * applied_wrench(now, i, momentum) + sum[i];
    sum[i].setZero();
    kick.head<3>() += impulse;
    kick.tail<3>() += r[i].cross(impulse);
    const int p = parent[i];
    if (p != 0) {
      sum[p].head<3>() -= impulse;
      sum[p].tail<3>() -= s[i].cross(impulse);
    }
    next.velocity[i] = now.velocity[i] + kick.head<3>() * (1.0 / model_.mass[i]);
    next.angular[i] = now.angular[i] + inverse_inertia[i] * kick.tail<3>();
    if (spins_ok) spins_ok = rule.accepts_body(i, h, next.angular[i], inertia[i], inverse_inertia[i], r, s);
  }

  // Collisions: impulses on the half-step velocities for the contacts at the current pose, solved with
  //    the joints, and the split-impulse pseudo-velocity that pushes overlaps apart in the drift below.
  has_pseudo = false;
  contact_report = ContactStepReport{};
  if (collisions_) {
    // A step that will be halved as too long for its spins (checked again below, after the impulses) is
    // not worth a detection whose margins its speeds would make huge.
    if (!spins_ok) return reject_spin(h);
    work.response.start_step();
    // Detection margins come from the velocities the drift will use: the half-step ones.
    State& probe = work.probe;
    for (int i = 0; i < n; ++i) {
      probe.position[i] = now.position[i];
      probe.orientation[i] = now.orientation[i];
      probe.velocity[i] = next.velocity[i];
      probe.angular[i] = next.angular[i];
    }
    // Looking kRecheckSlack further from every component than its margin (when the last look found
    // contacts, so that this one's impulses will likely call for looking again): `nearby`; the contacts
    // within the margins themselves are picked from it.
    const double slack = work.last_look_found ? kRecheckSlack : 0.0;
    work.detector->find_contacts(probe, h, kContactMargin + 2 * slack, work.nearby);
    work.detector->keep_within_margin(work.nearby, probe, h, kContactMargin, work.contacts);
    // Components in contact that already turn too fast for h: not worth solving the contacts.
    if (!contacts_turn_slowly_enough(h, probe.angular)) {
      work.outcome = StepWorkspace::Outcome::kContactTurn;
      return false;
    }
    const bool resolved = !work.contacts.empty();  // the impulses below change the velocities
    if (resolved)
      contact_report =
          work.response.resolve(now, solver, work.contacts, h, next.velocity, next.angular, work.pseudo, has_pseudo);
    // A knock can send a component off faster than its margin assumed: look again with the new
    // velocities, and if that finds other contacts, solve them all (what was solved needs nothing more).
    // `nearby` holds every contact of each pair within the sum of its components' looked_margin. While
    // no component's margin outgrows that, the contacts within the new margins are picked from it:
    // `aloft_step_profile` after the breeze, collisions on, needed the detector again for 38 of 979 looks
    // on generated-127 (1000 steps) and 23 of 354 on generated-1023 (100 steps), with the first look
    // kRecheckSlack further than the margins; with a slack of 0.05 mm for 57 and 29, with 0.25 mm for 10
    // and 9 (a wider first look costs more); with the slack only after a look whose contacts had
    // impulses, for 405 and 26. Where some margins do outgrow it, only the pairs of those components are
    // looked at again (find_contacts_again), kRecheckSlack further than their margins too, and `nearby`
    // becomes what that finds.
    // Solved again, all of them, also when the list is the same but one the solve left out as apart now
    // closes: the impulses knocked one of its components towards the other. (Until 2026-12-06 only another
    // list was: on generated-1023 after the breeze, a thread 0.08 mm from its neighbour, separating at
    // 1 mm/s and so left out, was knocked towards it at 0.71 m/s by its other contacts' impulses and began
    // the next step 0.62 mm deep, past the thread's radius. docs/collisions.md, "A contact the knock
    // closes".) And the look and the solve again after every solve whose impulses changed the
    // velocities, up to kMaxSolvesPerLook solves: a knock passed along a row of pieces reaches one more
    // pair with each solve, and a piece it sends off fast is looked at again. (Until the fourth session of
    // 2026-12-06 a step solved twice at most and looked again only after its first solve:
    // Collisions.AKnockIsPassedOnWithinTheStep, 4 balls on, and Collisions.AKnockPassedOnIsLookedAtAgain.)
    work.last_look_found = !work.contacts.empty();
    for (int solves = 1; contact_report.active > 0; ++solves) {
      bool covered = true;  // no component's margin is wider now than its pairs in `nearby` were looked for with
      for (int i = 1; i < n; ++i) {
        if (solves == 1)  // the first look's margins (probe has its velocities until now)
          work.looked_margin[i] =
              work.detector->margin(i, probe.velocity[i], probe.angular[i], h, kContactMargin + 2 * slack);
        probe.velocity[i] = next.velocity[i];
        probe.angular[i] = next.angular[i];
        work.wider[i] =
            work.detector->margin(i, probe.velocity[i], probe.angular[i], h, kContactMargin) > work.looked_margin[i];
        covered = covered && !work.wider[i];
      }
      if (!covered) {
        // A pair with a wider component is looked for again to its components' margins plus kRecheckSlack
        // each; the others keep their contacts in the old `nearby` within those sums, which is complete
        // to the smaller of the two looked_margin sums.
        work.detector->find_contacts_again(work.nearby, probe, h, kContactMargin + 2 * kRecheckSlack, work.wider,
                                           work.recheck);
        std::swap(work.nearby, work.recheck);
        for (int i = 1; i < n; ++i) {
          const double reach =
              work.detector->margin(i, probe.velocity[i], probe.angular[i], h, kContactMargin + 2 * kRecheckSlack);
          work.looked_margin[i] = work.wider[i] ? reach : std::min(work.looked_margin[i], reach);
        }
      }
      work.detector->keep_within_margin(work.nearby, probe, h, kContactMargin, work.recheck);
      const auto same_pair = [](const Contact& x, const Contact& y) { return x.a == y.a && x.b == y.b; };
      const bool other = work.recheck.size() != work.contacts.size() ||
                         !std::equal(work.recheck.begin(), work.recheck.end(), work.contacts.begin(), same_pair);
      if (other) std::swap(work.contacts, work.recheck);
      if (solves == kMaxSolvesPerLook ||
          !(other || work.response.closes_left_out(now, work.contacts, h, next.velocity, next.angular)))
        break;
      const ContactStepReport again =
          work.response.resolve(now, solver, work.contacts, h, next.velocity, next.angular, work.pseudo, has_pseudo,
                                /*again=*/true);
      add_later_solve(contact_report, again);
      if (again.active == 0) break;  // the velocities are as they were: nothing more to look for
    }
    // The step-size rule once more, on the velocities the contact impulses made. (The contacts' list may
    // be empty again by now: a knock can send the pair apart beyond the recheck's margins.)
    if (resolved) spins_ok = rule.accepts(h, next.angular, inertia, inverse_inertia, r, s);
  }

  // The step-size rule on the velocities the drift will use.
  if (!spins_ok) return reject_spin(h);
  // The impulses may have knocked a component in contact faster than the check above allowed. (How far
  // the pieces in contact move is checked once the joints are closed, on the drift's final velocities:
  // contacts_move_slowly_enough, in rattle.)
  if (collisions_ && !contacts_turn_slowly_enough(h, next.angular)) {
    work.outcome = StepWorkspace::Outcome::kContactTurn;
    return false;
  }
  return true;
}

}  // namespace aloft
