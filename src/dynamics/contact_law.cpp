#include "dynamics/contact_law.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/LU>

#include "aloft/contact_law_record.hpp"

namespace aloft {

namespace {

// Gauss-Seidel stops when no impulse changed by more than this fraction of the largest impulse, or no
// contact velocity changed in a sweep by more than this fraction of the largest velocity or target
// (whichever comes first); a single contact is exact after one pass (checked by the second). The second
// test ends what the first cannot: where the contacts' rows are dependent (a wire lying on a plate at
// several points, 3 rows each, against the pair's 6 relative freedoms) K is singular or nearly so, and
// Gauss-Seidel can go on moving the impulses along (or near) K's null space, which changes no velocity
// and no motion (G^T n = 0), after the velocities have settled. On generated-127 swinging with collisions
// (BM_StepCollisions, --benchmark_min_time=0.3), 883 of 11,091 solves ran into the cap (200 then) with the
// impulse test alone (341,225 sweeps in all), 188 of 11,276 with both (157,628 sweeps). Those left are
// contacts sliding against each other whose slip directions keep changing (impulses still changing by
// 1e-5..0.8 of their size after 200 sweeps): they take the normal law's impulses (solve_contact_law).
// The cap was raised from 200 to 400 with the forecast below, which ends the hopeless solves early: on
// the same inputs (generated-1023 swinging, 5000 steps, seeds 7, 1, 2, 3, each solve made by both
// versions) the solves that fall back went from 1779, 2096, 1667, 3254 to 1497, 1709, 1452, 2741, and
// the law's time to 0.51-0.63 of what it was.
constexpr double kRelativeChange = 1e-13;
constexpr int kMaxSweeps = 400;
// The frictionless normal law is a convex problem whose Gauss-Seidel converges, but slowly where the
// contacts are nearly dependent: in the collisions-on spans of aloft_step_profile it ran into its cap
// of 200 sweeps in 1800 of 3252 solves (generated-1023, swinging, 5000 steps) and 5165 of 6525
// (generated-8191 after the breeze, 1000 steps, most with 128 contacts). So a few sweeps find the
// contacts that push, and the impulses of those are then solved for exactly (solve_normal_law); only
// where that does not give the law's solution do the sweeps go on, up to the cap, as before.
constexpr int kMaxNormalSweeps = 200;
constexpr int kNormalSweepsBeforeExact = 8;   // sweeps before the first exact solve
constexpr int kNormalSweepsBetweenExact = 4;  // sweeps between exact solves that did not hold
constexpr int kMaxExactSolves = 6;
// An exact solve holds when every contact meets the law (law_violation) within this fraction of the
// largest speed or target: 1e-10 of speeds of mm/s to m/s is at most 1e-10 m/s, where the sweeps' own
// stopping rule (1e-13 change per sweep) leaves a few orders more after slow sweeps.
constexpr double kExactResidual = 1e-10;
// Pivots of the active contacts' matrix below this fraction of its largest are taken as zero (its
// rows dependent: two contacts between the same bodies, a loop closed through a joint): the solve then
// gives one of the impulses that meet the targets, if any does. 1e-12, as for one contact's block.
constexpr double kSingularPivot = 1e-12;

// A solve that will not converge within kMaxSweeps stops early: after each sweep from the
// kForecastWindow-th on, the rate at which the sweep's change (the smaller of its two relative measures,
// above) fell over the last kForecastWindow sweeps is extrapolated, and if even at that rate it would not
// reach kRelativeChange by kMaxSweeps, the solve takes the frictionless fallback now instead of after its
// last sweep (the fallback does not depend on where Gauss-Seidel stopped). Five solves that did not
// converge at generated-1023, examined, each had one cluster of 6-8 strongly coupled contacts that did not
// converge alone (the one traced: a limit cycle, a contact trading sticking for sliding with a period of
// 20 sweeps); the cycling landings of ContactLaw.DependentContactsMeetTheLaw are given up after 31-37
// sweeps instead of at the cap. Measured before it was built, on the sweeps of 9560 solves
// (aloft_step_profile 1023 3000 1 swinging:7 and :1, with the cap at 200 then): the forecast over 30
// sweeps at twice that cap would have given up 17 of the 8385 that converged, and saved 45 % of the
// sweeps' work (each weighted by m^2).
constexpr int kForecastWindow = 30;

// When Gauss-Seidel with friction does not converge, the contacts whose impulse changed, in the last
// kRecentSweeps sweeps or more, by at least kUnsettledFraction of the largest such change are solved again
// without friction, the others with theirs (solve_contact_law); only if that does not converge either is
// friction dropped at every contact. The solves that do not converge are a cluster of a few strongly
// coupled contacts cycling between sticking and sliding while the rest have settled (see
// kForecastWindow); a contact coupled to the cluster changes with it, in proportion to the coupling.
constexpr int kRecentSweeps = 10;
constexpr double kUnsettledFraction = 1e-3;

// The sweeps' changes, kept for the forecast.
class ConvergenceForecast {
 public:
  // Records the change of sweep `sweep` (1, 2, ...); true when, at the rate of the last kForecastWindow
  // sweeps, it would not reach kRelativeChange by sweep kMaxSweeps.
  bool hopeless(int sweep, double change) {
    const double before = history_[sweep % kForecastWindow];
    history_[sweep % kForecastWindow] = change;
    if (sweep <= kForecastWindow || !(change > kRelativeChange)) return false;
    if (!(before > 0) || !std::isfinite(before) || !std::isfinite(change)) return false;
    if (change >= before) return true;  // no progress in kForecastWindow sweeps
    const double sweeps_per_factor = kForecastWindow / std::log(before / change);  // sweeps per factor e
    return sweep + sweeps_per_factor * std::log(change / kRelativeChange) > kMaxSweeps;
  }

 private:
  std::array<double, kForecastWindow> history_{};
};

// A slip speed (m/s) below this has no reliable direction; the sticking impulse's direction is used.
constexpr double kSlipDirectionFloor = 1e-9;

// A contact block whose smallest eigenvalue is below this fraction of its largest is treated as singular
// (rank-deficient): e.g. two bodies whose relative motion at the point is confined to a plane. 1e-12 is
// ~1e4 times double rounding of the block's entries, far below any physical stiffness ratio.
constexpr double kSingularBlock = 1e-12;

using Vec3d = Eigen::Vector3d;
using Mat3d = Eigen::Matrix3d;

// The impulse that changes the contact velocity by `change` through the (symmetric, positive
// semi-definite) block K: K^-1 change, or, when K is singular, the least-squares impulse of least norm
// (K's pseudo-inverse): the part of `change` no impulse can produce is left out instead of being bought
// with an unbounded impulse. Formed once per contact and solve, when the contact first needs it (the
// block does not change between Gauss-Seidel sweeps; a contact that separates without an impulse in every
// sweep, most of a tangle's, never does), as a matrix, K^-1 by LDL^T solves of the unit vectors or the
// pseudo-inverse, so that a sweep's solve is one 3x3 product.
class BlockSolver {
 public:
  // K^-1 change for this contact's block K (the same K at every call).
  Vec3d solve(const Mat3d& K, const Vec3d& change) {
    if (!formed_) form(K);
    return inverse_ * change;
  }

 private:
  void form(const Mat3d& K) {
    formed_ = true;
    const Eigen::LDLT<Mat3d> ldlt(K);
    const Vec3d pivots = ldlt.vectorD().cwiseAbs();
    if (ldlt.info() == Eigen::Success && pivots.minCoeff() > kSingularBlock * pivots.maxCoeff()) {
      inverse_ = ldlt.solve(Mat3d::Identity());
      return;
    }
    Eigen::SelfAdjointEigenSolver<Mat3d> eigen;
    eigen.computeDirect(K);
    const Mat3d& vectors = eigen.eigenvectors();
    const Vec3d& values = eigen.eigenvalues();
    const double cutoff = kSingularBlock * values.cwiseAbs().maxCoeff();
    Vec3d inverse_values;
    for (int k = 0; k < 3; ++k) inverse_values[k] = values[k] > cutoff ? 1.0 / values[k] : 0.0;
    inverse_ = vectors * inverse_values.asDiagonal() * vectors.transpose();
  }

  bool formed_ = false;
  Mat3d inverse_;  // K^-1, or K's pseudo-inverse when K is singular (once formed_)
};

// Sliding against the slip the impulse leaves (Coulomb's law): the impulse P = p (1, -mu e) on the
// cone's edge, e = (cos a, sin a) a unit vector of the contact's tangent plane, whose normal row meets the
// target, u'_n = target, and whose friction opposes the slip after it, u'_t = u_free_t + (K P)_t =
// |u'_t| e: one equation in the angle a, g(a) = e x u'_t(a) = 0, with e . u'_t >= 0 and p > 0. (Until
// 2026-12-03 the friction opposed the slip before the impulse, u_free_t. Where K couples the tangential
// rows, or the normal to them, that impulse jumps at the edge of the cone, from the sticking impulse on
// the cone to one along -u_free_t, so a contact near it can trade sticking for sliding with no impulse
// in between that meets the law, and Gauss-Seidel cycles (docs/performance.md, "2026-12-03, later").
// Against the slip after the impulse, sliding starts where sticking ends: the slip starts at zero, in
// the direction the sticking impulse's friction opposes.)
struct SlipAlong {
  bool valid = false;  // (K d)_n > 0 for d = (1, -mu e): pushing along d moves the contact apart
  double p = 0;        // N s: the normal impulse
  double g = 0;        // m/s: e x u'_t
  double slope = 0;    // m/s per rad: dg/da
  double along = 0;    // m/s: e . u'_t, the slip after the impulse
};

SlipAlong slip_along(const Mat3d& K, const Vec3d& u_free, double target, double mu, const Eigen::Vector2d& e) {
  SlipAlong out;
  // K d and K dd/da, with d = (1, -mu c, -mu s) and dd/da = (0, mu s, -mu c), from K's columns.
  const Vec3d Kd = K.col(0) - mu * (e.x() * K.col(1) + e.y() * K.col(2));
  const Vec3d Kd_prime = mu * (e.y() * K.col(1) - e.x() * K.col(2));
  if (!(Kd.x() > 1e-9 * K(0, 0))) return out;
  out.valid = true;
  out.p = (target - u_free.x()) / Kd.x();
  const double p_prime = -out.p * Kd_prime.x() / Kd.x();
  const Eigen::Vector2d v = u_free.tail<2>() + out.p * Kd.tail<2>();
  const Eigen::Vector2d v_prime = p_prime * Kd.tail<2>() + out.p * Kd_prime.tail<2>();
  out.g = e.x() * v.y() - e.y() * v.x();
  out.along = e.x() * v.x() + e.y() * v.y();
  out.slope = -out.along + e.x() * v_prime.y() - e.y() * v_prime.x();
  return out;
}

bool acceptable(const SlipAlong& at) { return at.valid && at.p > 0 && at.along >= 0; }

// The sliding impulse's direction e (see SlipAlong), by Newton's method on the angle from `start` (a unit
// vector; from the last sweep's direction it takes 2-3 steps), or, where that finds no root with the slip
// along e, the root nearest `start` of a scan of the circle in kSlipScan steps, each bracket refined by
// Newton's method kept inside it (about 0.5 % of the sliding solves in the 1023 span from the swinging
// state). False when no direction fits.
constexpr int kSlipScan = 32;
constexpr int kSlipNewtonIterations = 12;
constexpr double kSlipAngleTolerance = 1e-14;  // rad: a Newton step below this ends the iteration

bool sliding_direction(const Mat3d& K, const Vec3d& u_free, double target, double mu, const Eigen::Vector2d& start,
                       Eigen::Vector2d& e, SlipAlong& at) {
  e = start;
  for (int it = 0; it < kSlipNewtonIterations; ++it) {
    at = slip_along(K, u_free, target, mu, e);
    if (!at.valid || !(at.slope != 0)) break;
    const double step = at.g / at.slope;  // rad
    if (!std::isfinite(step)) break;
    if (std::abs(step) <= kSlipAngleTolerance) {
      if (acceptable(at)) return true;
      break;
    }
    // Turn e by -step (to within O(step^3), which keeps the convergence quadratic).
    e = Eigen::Vector2d(e.x() + step * e.y(), e.y() - step * e.x()).normalized();
  }
  const double start_angle = std::atan2(start.y(), start.x());
  const auto at_angle = [&](double angle) {
    return slip_along(K, u_free, target, mu, Eigen::Vector2d(std::cos(angle), std::sin(angle)));
  };
  bool found = false;
  double best_distance = 0;
  double previous_angle = start_angle - std::numbers::pi;
  SlipAlong previous = at_angle(previous_angle);
  for (int i = 1; i <= kSlipScan; ++i) {
    const double next_angle = start_angle - std::numbers::pi + 2.0 * std::numbers::pi * i / kSlipScan;
    const SlipAlong next = at_angle(next_angle);
    if (previous.valid && next.valid && (previous.g > 0) != (next.g > 0)) {
      // Newton's method kept inside the bracket [low, high], bisecting where its step would leave it.
      double low = previous_angle, high = next_angle, g_low = previous.g, root = 0.5 * (low + high);
      for (int it = 0; it < 100 && high - low > kSlipAngleTolerance; ++it) {
        const SlipAlong there = at_angle(root);
        if (!there.valid) break;
        if ((there.g > 0) == (g_low > 0)) {
          low = root;
          g_low = there.g;
        } else {
          high = root;
        }
        // Not finite where the slope is zero: then it fails the bracket test and the step bisects.
        const double newton = root - there.g / there.slope;
        const double step = std::abs(newton - root);
        root = newton > low && newton < high ? newton : 0.5 * (low + high);
        if (step <= kSlipAngleTolerance) break;
      }
      const SlipAlong there = at_angle(root);
      const double distance = std::abs(std::remainder(root - start_angle, 2.0 * std::numbers::pi));
      if (acceptable(there) && (!found || distance < best_distance)) {
        best_distance = distance;
        e = Eigen::Vector2d(std::cos(root), std::sin(root));
        at = there;
        found = true;
      }
    }
    previous = next;
    previous_angle = next_angle;
  }
  return found;
}

// How a contact's impulse meets the law: none (separating), sticking, sliding on the cone's edge, or
// a normal impulse alone (no friction, or a jam: friction along no direction fits).
enum class Mode : char { kNone, kSticking, kSliding, kNormalOnly };

// The impulse of one contact (in its basis) given the velocity it would have without its own impulse,
// and how it meets the law (`mode`). `slide` (unit, tangent basis): the direction the contact slipped
// along in the last sweep (zero if it did not slide), where the sliding solve starts; set to this
// one's (zero if it does not slide).
Vec3d contact_impulse(const Mat3d& K, BlockSolver& block, const Vec3d& u_free, const ContactLawRow& row,
                      Mode& mode, Eigen::Vector2d& slide) {
  mode = Mode::kNone;
  const Eigen::Vector2d previous = slide;
  slide.setZero();
  const double knn = K(0, 0);
  if (!(knn > 0)) return Vec3d::Zero();                // nothing can move at this point
  if (u_free.x() >= row.target_normal) return Vec3d::Zero();  // separating fast enough: no impulse

  // Mirtich's prediction: the impulse that makes the contact stick (normal target met, no slip).
  const Vec3d wanted(row.target_normal, 0, 0);
  const Vec3d stick = block.solve(K, wanted - u_free);
  const double tangential = stick.tail<2>().norm();
  if (std::isfinite(tangential) && stick.x() > 0 && tangential <= row.friction * stick.x()) {
    mode = Mode::kSticking;
    return stick;
  }

  if (row.friction > 0 && std::isfinite(tangential)) {
    // Sliding, from the last sweep's direction, or else from where sliding starts: against the sticking
    // impulse's friction (or along the slip before the impulse where sticking needs no friction).
    Eigen::Vector2d start = previous;
    if (!(start.squaredNorm() > 0)) {
      start = tangential > 0 ? Eigen::Vector2d(-stick.tail<2>() / tangential) : Eigen::Vector2d(u_free.tail<2>());
      if (!(start.norm() > kSlipDirectionFloor)) start = Eigen::Vector2d::UnitX();
      start.normalize();
    }
    Eigen::Vector2d e;
    SlipAlong at;
    if (sliding_direction(K, u_free, row.target_normal, row.friction, start, e, at)) {
      mode = Mode::kSliding;
      slide = e;
      return at.p * Vec3d(1.0, -row.friction * e.x(), -row.friction * e.y());
    }
  }
  // No friction, or friction along no direction fits (a jam): a frictionless normal impulse, which
  // always exists.
  mode = Mode::kNormalOnly;
  return Vec3d((row.target_normal - u_free.x()) / knn, 0, 0);
}

// Newton's method on the contacts whose impulses still change most, kPolishCluster of the largest change
// of the last sweep or more (of those that push: P_n > 0), in the modes that sweep gave them, the other
// impulses held: a sticking contact's velocity meets (target, 0, 0); a sliding one's normal velocity meets
// the target and its friction is mu P_n against the slip after the impulse, P_t + mu P_n s = 0 with s =
// u'_t / |u'_t|; one with a normal impulse alone meets the target with P_t = 0. The Jacobian is factored
// once (rank-revealing: the contacts' rows are often dependent) and kept for up to kPolishIterations steps
// (a chord method). `velocity` is u + K P. Gives the result in P (false where no contact is in the
// cluster or the result is not finite); whether it meets the law is for the sweep after it to tell.
// Why: the sweeps that do not converge within a few tens each had a cluster of a few strongly coupled
// contacts converging slowly (Gauss-Seidel's change falling by 0.94 per sweep, say) while the rest had
// settled; Newton's method on that cluster alone ends it. Measured on the same inputs, 4960 solves
// written out from the span of aloft_step_profile 1023 5000 1 swinging (every second one;
// docs/performance.md, "2026-12-03, later"): falling back to the frictionless law, 981 with the old law
// (friction against the slip before the impulse, no Newton), 836 with this law and no Newton, 422 with
// it (12.3 sweeps per solve against 34.5), and 389 for Newton on every contact that pushes, at 2.1 times
// the CPU time of this cluster's (1.42 times the old law's).
constexpr int kPolishFirstSweep = 8;
constexpr int kPolishEvery = 4;  // sweeps between polishes
constexpr int kMaxPolishes = 6;
constexpr int kPolishIterations = 8;
constexpr double kPolishCluster = 1e-2;
constexpr double kPolishStepTolerance = 1e-10;  // of the largest impulse: a chord step below this ends it
constexpr double kPolishRank = 1e-12;  // pivots below this fraction of the largest are taken as zero
// The Jacobian of a cluster of kPolishLuContacts contacts or more is factored by LU with partial pivoting
// where that is safe, its reciprocal condition number (LU's estimate, 1-norm) at least
// kPolishLuConditioning, and by the complete orthogonal decomposition (rank-revealing: the least-norm
// step) otherwise. LU costs about half the decomposition's multiply-adds and works in blocks. Measured on
// 761 solves recorded from the 8191 tangle and 998 from the 1023 one (docs/performance.md, "2026-12-07"):
// the law's instructions -24 % and -12 % (callgrind), the same outcomes (one solve of the 761 lost its
// friction at every contact, as it does with the decomposition alone when its steps are scaled by
// 1 + 1e-13: that solve's path is that sensitive). With a bound of 1e-4 almost every polish fell back (a
// tangle's contacts are nearly dependent) and then paid for both factorizations. Smaller clusters keep
// the decomposition alone: they hold 0.2 % and 14 % of the factorizations' work on those recordings, and
// the presets' clusters (at most 10 contacts on the Steel Fish shaken for 10 minutes) keep their motion
// bit for bit.
constexpr int kPolishLuContacts = 12;
constexpr double kPolishLuConditioning = 1e-8;
// A polish refines the impulses the sweeps are converging to. One that leaves some impulse more than
// kPolishGrowth times the largest of the sweep before it has stepped along a nearly singular direction
// of its Jacobian (three or more contacts between the same two bodies have more rows than the pair has
// relative freedoms, and the sliding rows can make the Jacobian nearly singular where K is not quite)
// and is refused; the sweeps go on from where they were. Such a step need not change the velocities
// much (it lies near K's null space), so the sweep after it could call it converged: on the Steel Fish
// shaken hard (t = 68.2 s of the test's shaking), three contacts between two arms ended at 6.8e10 N s,
// with one of them still approaching at 0.04 m/s against a target of 0.008 m/s, and an energy change of
// -6.8e5 J from round-off alone (ContactLaw.APolishThatThrowsTheImpulsesOutOfScaleIsRefused; before, a
// later such solve gave 6.8e21 N s and velocities of 1e7 m/s, in a substep the step's checks then
// rejected).
// Measured on 10,699 solves written out from `aloft_step_profile 1023 5000 1 swinging:7` and solved again
// (docs/performance.md, "2026-12-06, second session"): of about 19,400 polishes, 675 made some impulse
// more than 100 times the sweep's largest (at most 5.4e18 times); refusing them, the solves took 149,003
// sweeps against 148,572, dropped friction at every contact in 19 solves against 51 (and at some in 616
// against 596), and the largest normal velocity short of its target fell from 1.2e-6 to 1.2e-8 m/s.
// (Limits of 1e3 and 10: 148,609 and 151,631 sweeps, 26 and 14 solves without friction.)
constexpr double kPolishGrowth = 100;
// After the kMaxPolishes polishes of the schedule above, a solve whose contacts have all kept their modes
// (none, sticking, sliding, normal only) for kSettledSweeps sweeps, and that many since the last polish,
// is polished again, up to kMaxSettledPolishes more times. With the modes settled the law is smooth
// where Gauss-Seidel is, and its convergence is linear, at times very slow: one solve recorded at
// generated-8191 (aloft_law_replay, docs/performance.md, "2026-12-06, seventh session"), solved with the
// cycling rule below alone, went from 1e-6 to 1e-13 at 0.965 per sweep, 300 sweeps after the schedule's
// last polish, where Newton's method on the slowest contacts, in those modes, ends it. Measured on 798
// solves recorded from `aloft_step_profile 8191 2000 1 swinging:1` (every 20th of 20 contacts or more)
// and 1270 from `1023 5000 1 swinging:1` (every 10th of 5 or more), with kCyclingModeChanges below: the
// law's work (sweeps x m^2) -39 % and -16 %, its time -10 % and -12 % (the extra factorizations cost
// part of what their sweeps save), the contacts left without friction 8046 -> 3386 and 1388 -> 686.
constexpr int kSettledSweeps = 4;
constexpr int kMaxSettledPolishes = 6;

// A contact whose mode has changed kCyclingModeChanges times after the first two sweeps is cycling (one
// traced at generated-8191: two contacts trading sticking for sliding with a period of 4 sweeps, from the
// 9th sweep on, while the rest settled): it loses its friction for the rest of the solve and the sweeps
// go on. Until the seventh session of 2026-12-06 such a solve ran on until the forecast gave it up (31
// sweeps at least) and was solved again with no friction at every contact that had changed by
// kUnsettledFraction of the largest change (21 contacts in the one traced, against the 2 that cycled).
// On the recordings above, alone (without the settled polishes), 1.10 times the work and 7106 contacts
// left without friction against 8046; of the 595 solves at 8191 that converged without it, 12 had a
// contact change mode 4 times or more.
constexpr int kCyclingModeChanges = 4;

bool polish_law(const Eigen::MatrixXd& K, const Eigen::VectorXd& velocity, const std::vector<ContactLawRow>& rows,
                const std::vector<Mode>& mode, const std::vector<double>& change, Eigen::VectorXd& P) {
  const int m = static_cast<int>(rows.size());
  double largest = 0;
  for (int k = 0; k < m; ++k)
    if (P[3 * k] > 0) largest = std::max(largest, change[k]);
  std::vector<int> cluster;
  for (int k = 0; k < m; ++k)
    if (P[3 * k] > 0 && change[k] >= kPolishCluster * largest) cluster.push_back(k);
  const int c = static_cast<int>(cluster.size());
  if (c == 0) return false;
  Eigen::MatrixXd K_cc(3 * c, 3 * c);
  Eigen::VectorXd u_c(3 * c), P_c(3 * c);
  for (int i = 0; i < c; ++i) {
    u_c.segment<3>(3 * i) = velocity.segment<3>(3 * cluster[i]);
    P_c.segment<3>(3 * i) = P.segment<3>(3 * cluster[i]);
    for (int j = 0; j < c; ++j) K_cc.block<3, 3>(3 * i, 3 * j) = K.block<3, 3>(3 * cluster[i], 3 * cluster[j]);
  }
  u_c.noalias() -= K_cc * P_c;  // the cluster's velocities without its own impulses
  // The law's residual F at impulses Q (m/s: a sliding contact's friction rows, in N s, are scaled by its
  // K_nn) and, when J is given, its Jacobian dF/dQ.
  const auto residual = [&](const Eigen::VectorXd& Q, Eigen::VectorXd& F, Eigen::MatrixXd* J) {
    const Eigen::VectorXd v = u_c + K_cc * Q;
    if (J) *J = K_cc;
    for (int i = 0; i < c; ++i) {
      const int k = cluster[i];
      F.segment<3>(3 * i) = v.segment<3>(3 * i) - Vec3d(rows[k].target_normal, 0, 0);
      const double scale = K_cc(3 * i, 3 * i);
      if (mode[k] == Mode::kNormalOnly) {
        F.segment<2>(3 * i + 1) = scale * Q.segment<2>(3 * i + 1);
        if (J) {
          J->middleRows<2>(3 * i + 1).setZero();
          (*J)(3 * i + 1, 3 * i + 1) = (*J)(3 * i + 2, 3 * i + 2) = scale;
        }
        continue;
      }
      const Eigen::Vector2d slip = v.segment<2>(3 * i + 1);
      const double r = slip.norm();
      if (mode[k] != Mode::kSliding || !(r > kSlipDirectionFloor)) continue;  // sticking (or no slip to follow)
      const double mu = rows[k].friction, pn = Q[3 * i];
      const Eigen::Vector2d s = slip / r;
      F.segment<2>(3 * i + 1) = scale * (Q.segment<2>(3 * i + 1) + mu * pn * s);
      if (!J) continue;
      // d(P_t + mu P_n s)/dQ = e_t + mu s e_n^T + mu P_n (I - s s^T) / r dv_t/dQ, dv_t/dQ = K's tangential rows.
      const Eigen::Matrix2d projector = (Eigen::Matrix2d::Identity() - s * s.transpose()) * (mu * pn / r);
      J->middleRows<2>(3 * i + 1) = projector * K_cc.middleRows<2>(3 * i + 1);
      (*J)(3 * i + 1, 3 * i + 1) += 1.0;
      (*J)(3 * i + 2, 3 * i + 2) += 1.0;
      (*J)(3 * i + 1, 3 * i) += mu * s.x();
      (*J)(3 * i + 2, 3 * i) += mu * s.y();
      J->middleRows<2>(3 * i + 1) *= scale;
    }
  };
  Eigen::MatrixXd J(3 * c, 3 * c);
  Eigen::VectorXd F(3 * c);
  residual(P_c, F, &J);
  // (An exactly zero pivot is tested apart: Eigen's estimate can miss it, giving 5e-3 for a 36 x 36 matrix
  // with a zero row and column, where the solve would divide by zero. Rows equal to round-off give
  // 1e-33.)
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;
  bool well_conditioned = false;
  if (c >= kPolishLuContacts) {
    lu.compute(J);
    well_conditioned = lu.matrixLU().diagonal().cwiseAbs().minCoeff() > 0 && lu.rcond() >= kPolishLuConditioning;
  }
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> rank_revealing;
  if (!well_conditioned) {
    rank_revealing.setThreshold(kPolishRank);
    rank_revealing.compute(J);
  }
  Eigen::VectorXd step(3 * c);
  for (int it = 0; it < kPolishIterations; ++it) {
    if (well_conditioned) step = lu.solve(-F);
    else step = rank_revealing.solve(-F);
    if (!step.allFinite()) break;
    P_c += step;
    if (step.cwiseAbs().maxCoeff() <= kPolishStepTolerance * P_c.cwiseAbs().maxCoeff()) break;
    residual(P_c, F, nullptr);
  }
  if (!P_c.allFinite()) return false;
  for (int i = 0; i < c; ++i) P.segment<3>(3 * cluster[i]) = P_c.segment<3>(3 * i);
  return true;
}

// Block Gauss-Seidel on the law from P = start (zero when null; P resized to 3m, m >= 1), with the Newton
// polish now and then: true when it converged (see kRelativeChange). A contact found cycling
// (kCyclingModeChanges) has its friction in `rows` set to 0. `sweeps` counts the sweeps; `recent_change`
// (per contact) is set to the largest change of its impulse (max norm, N s) over the last sweeps, at least
// kRecentSweeps of them, which tells the contacts still moving when it did not converge. `sticking` and
// `sliding` count the contacts that ended so.
bool gauss_seidel(const Eigen::MatrixXd& K, const Eigen::VectorXd& u, std::vector<ContactLawRow>& rows,
                  const Eigen::VectorXd* start, Eigen::VectorXd& P, int& sweeps, std::vector<double>& recent_change,
                  int& sticking, int& sliding) {
  const int m = static_cast<int>(rows.size());
  Eigen::VectorXd velocity = u;  // u + K P, kept current
  if (start) {
    P = *start;
    velocity.noalias() += K * P;
  } else {
    P.setZero(3 * m);
  }
  std::vector<Mode> mode(m, Mode::kNone);
  std::vector<Eigen::Vector2d> slide(m, Eigen::Vector2d::Zero());  // per contact: its slip's direction
  std::vector<double> change_of(m, 0.0);  // per contact: how much its impulse changed in the last sweep
  // Per contact, the largest change over the sweeps since the window was last restarted, and over the
  // window before (the two together cover kRecentSweeps to 2 kRecentSweeps sweeps).
  std::vector<double> window_change(m, 0.0), last_window_change(m, 0.0);
  int polishes = 0, settled_polishes = 0;
  int last_mode_change = 0, last_polish = 0;  // the sweeps they were made in
  std::vector<int> mode_changes(m, 0);         // per contact, after the second sweep
  std::vector<BlockSolver> blocks(m);  // formed as the contacts need them
  double velocity_scale = u.cwiseAbs().maxCoeff();
  for (const ContactLawRow& row : rows) velocity_scale = std::max(velocity_scale, std::abs(row.target_normal));
  Eigen::VectorXd sweep_start(3 * m), polished(3 * m);
  bool converged = false;
  ConvergenceForecast forecast;
  for (int sweep = 1; sweep <= kMaxSweeps; ++sweep) {
    sweeps = sweep;
    if (sweep % kRecentSweeps == 1 && sweep > 1) {
      std::swap(window_change, last_window_change);
      std::fill(window_change.begin(), window_change.end(), 0.0);
    }
    double largest_change = 0, largest_impulse = 0;
    sweep_start = velocity;
    for (int k = 0; k < m; ++k) {
      const Mat3d Kkk = K.block<3, 3>(3 * k, 3 * k);
      const Vec3d old = P.segment<3>(3 * k);
      const Vec3d u_free = velocity.segment<3>(3 * k) - Kkk * old;
      const Mode mode_before = mode[k];
      const Vec3d next = contact_impulse(Kkk, blocks[k], u_free, rows[k], mode[k], slide[k]);
      if (mode[k] != mode_before) {
        last_mode_change = sweep;
        if (sweep > 2 && ++mode_changes[k] >= kCyclingModeChanges) rows[k].friction = 0;
      }
      const Vec3d change = next - old;
      if (change.squaredNorm() > 0) {
        velocity.noalias() += K.middleCols<3>(3 * k) * change;
        P.segment<3>(3 * k) = next;
      }
      change_of[k] = change.cwiseAbs().maxCoeff();
      window_change[k] = std::max(window_change[k], change_of[k]);
      largest_change = std::max(largest_change, change_of[k]);
      largest_impulse = std::max(largest_impulse, next.cwiseAbs().maxCoeff());
    }
    const double velocity_change = (velocity - sweep_start).cwiseAbs().maxCoeff();
    if (m == 1 || largest_change <= kRelativeChange * largest_impulse ||
        velocity_change <= kRelativeChange * velocity_scale) {
      converged = true;
      break;
    }
    if (forecast.hopeless(sweep, std::min(largest_change / largest_impulse, velocity_change / velocity_scale))) break;
    const bool scheduled = polishes < kMaxPolishes && sweep == kPolishFirstSweep + polishes * kPolishEvery;
    const bool settled = polishes == kMaxPolishes && settled_polishes < kMaxSettledPolishes &&
                         sweep - last_mode_change >= kSettledSweeps && sweep - last_polish >= kSettledSweeps;
    if (scheduled || settled) {
      if (scheduled) ++polishes;
      else ++settled_polishes;
      last_polish = sweep;
      polished = P;
      if (polish_law(K, velocity, rows, mode, change_of, polished) &&
          polished.cwiseAbs().maxCoeff() <= kPolishGrowth * largest_impulse) {
        P = polished;
        velocity.noalias() = u + K * P;
      }
    }
  }
  recent_change.resize(m);
  for (int k = 0; k < m; ++k) recent_change[k] = std::max(window_change[k], last_window_change[k]);
  sticking = sliding = 0;
  for (int k = 0; k < m; ++k) {
    if (!(P[3 * k] > 0)) continue;
    if (mode[k] == Mode::kSliding) ++sliding;
    else ++sticking;
  }
  return converged;
}

}  // namespace

ContactLawResult solve_contact_law(const Eigen::MatrixXd& K, const Eigen::VectorXd& u,
                                   const std::vector<ContactLawRow>& rows, Eigen::VectorXd& P,
                                   const Eigen::VectorXd* start) {
  const int m = static_cast<int>(rows.size());
  ContactLawResult result;
  P.setZero(3 * m);
  if (m == 0) return result;
  std::vector<double> recent_change;
  std::vector<ContactLawRow> law = rows;  // with the friction of the contacts found cycling taken away
  const auto without_friction = [&](const std::vector<ContactLawRow>& solved) {
    int count = 0;
    for (int k = 0; k < m; ++k) count += rows[k].friction > 0 && !(solved[k].friction > 0);
    return count;
  };
  bool converged =
      gauss_seidel(K, u, law, start, P, result.iterations, recent_change, result.sticking, result.sliding);
  if (converged) result.frictionless_contacts = without_friction(law);
  if (!converged) {
    // The contacts that kept changing (a cluster trading sticking for sliding, see kUnsettledFraction)
    // lose their friction for this solve, and the law is solved again: the others keep theirs.
    const double largest = *std::max_element(recent_change.begin(), recent_change.end());
    std::vector<ContactLawRow> calmer = law;
    int with_friction = 0;
    for (int k = 0; k < m; ++k) {
      with_friction += rows[k].friction > 0;
      if (recent_change[k] >= kUnsettledFraction * largest) calmer[k].friction = 0;
    }
    const int unsettled = without_friction(calmer);  // the cycling contacts too
    if (unsettled > 0 && unsettled < with_friction) {
      int sweeps = 0;
      // From the same start, less the friction of the contacts that lose it (on the same inputs, 1023
      // swinging: as many solves ended without any friction as from no start, 20 against 21; restarted
      // from zero instead, 122 against 84).
      Eigen::VectorXd calmer_start;
      if (start) {
        calmer_start = *start;
        for (int k = 0; k < m; ++k)
          if (calmer[k].friction == 0) calmer_start.segment<2>(3 * k + 1).setZero();
      }
      converged = gauss_seidel(K, u, calmer, start ? &calmer_start : nullptr, P, sweeps, recent_change,
                               result.sticking, result.sliding);
      result.iterations += sweeps;
      if (converged) result.frictionless_contacts = without_friction(calmer);
    }
  }
  if (!converged) {
    // Block Gauss-Seidel with friction need not converge: contacts coupled through one body can keep
    // trading sticking for sliding (ContactLaw.DependentContactsMeetTheLaw: a body landing on four corners,
    // a few of 50 landings for friction coefficients 0.3 to 5). What it stops at can leave a contact
    // approaching (up to 0.08 m/s of 1-3 m/s there). The normal law alone is a convex problem that
    // converges; its impulses are used instead, without friction for this solve.
    Eigen::VectorXd target(m);
    for (int k = 0; k < m; ++k) target[k] = rows[k].target_normal;
    solve_frictionless_law(K, u(Eigen::seqN(0, m, 3)), target, P);
    result.friction_dropped = true;
    result.sticking = result.sliding = 0;
    result.frictionless_contacts = m;
    result.energy_change = contact_energy_change(K, u, P);
    return result;
  }
  result.energy_change = contact_energy_change(K, u, P);
  return result;
}

ContactLawResult solve_contact_law(const ContactLawRecord& record, Eigen::VectorXd& P) {
  std::vector<ContactLawRow> rows;
  for (int k = 0; k < record.contacts(); ++k) rows.push_back({record.target_normal[k], record.friction[k]});
  return solve_contact_law(record.K, record.u, rows, P, record.start.size() > 0 ? &record.start : nullptr);
}

namespace {

// Projected Gauss-Seidel sweeps of the normal law from P_n, whose contact velocities are `velocity`
// (u_n + K_nn P_n, kept current); at most `sweeps`, `done` counting them. True when converged: no
// impulse changed by more than kRelativeChange of the largest, or no velocity by more than that of
// `velocity_scale`, in the last sweep.
bool normal_sweeps(const Eigen::MatrixXd& K_nn, const Eigen::VectorXd& target, double velocity_scale, int sweeps,
                   int& done, Eigen::VectorXd& P_n, Eigen::VectorXd& velocity) {
  const int m = static_cast<int>(P_n.size());
  Eigen::VectorXd sweep_start(m);
  for (int sweep = 1; sweep <= sweeps; ++sweep) {
    ++done;
    double largest_change = 0, largest_impulse = 0;
    sweep_start = velocity;
    for (int k = 0; k < m; ++k) {
      const double kkk = K_nn(k, k);
      if (!(kkk > 0)) continue;
      const double next = std::max(0.0, P_n[k] + (target[k] - velocity[k]) / kkk);
      const double change = next - P_n[k];
      if (change != 0) {
        velocity.noalias() += K_nn.col(k) * change;
        P_n[k] = next;
      }
      largest_change = std::max(largest_change, std::abs(change));
      largest_impulse = std::max(largest_impulse, next);
    }
    if (m == 1 || largest_change <= kRelativeChange * largest_impulse ||
        (velocity - sweep_start).cwiseAbs().maxCoeff() <= kRelativeChange * velocity_scale)
      return true;
  }
  return false;
}

// How far contact velocities `velocity` are from meeting the normal law with impulses P_n (m/s): the
// most a contact approaches beyond its target, or separates beyond it while pushed.
double law_violation(const Eigen::VectorXd& P_n, const Eigen::VectorXd& velocity, const Eigen::VectorXd& target) {
  double worst = 0;
  for (int k = 0; k < P_n.size(); ++k) {
    const double beyond = velocity[k] - target[k];
    worst = std::max(worst, P_n[k] > 0 ? std::abs(beyond) : -beyond);
  }
  return worst;
}

// The normal law solved exactly on the contacts that push in `from` (the active set A = {k : from[k] >
// 0}): K_AA x = target_A - u_A (an LDL^T factorization with pivoting; pivots below kSingularPivot of the
// largest taken as zero, so that dependent rows give one of the solutions if the targets admit any), the
// other contacts without impulse, and x clamped at 0. Gives that candidate in P_n and its contact
// velocities in `velocity`; false where the factorization fails or the candidate is not finite.
bool exact_on_active_set(const Eigen::MatrixXd& K_nn, const Eigen::VectorXd& u_n, const Eigen::VectorXd& target,
                         const Eigen::VectorXd& from, Eigen::VectorXd& P_n, Eigen::VectorXd& velocity) {
  const int m = static_cast<int>(from.size());
  std::vector<int> active;
  for (int k = 0; k < m; ++k)
    if (from[k] > 0) active.push_back(k);
  const int a = static_cast<int>(active.size());
  P_n.setZero(m);
  if (a > 0) {
    Eigen::MatrixXd K_aa(a, a);
    Eigen::VectorXd x(a);
    for (int i = 0; i < a; ++i) {
      x[i] = target[active[i]] - u_n[active[i]];
      for (int j = 0; j < a; ++j) K_aa(i, j) = K_nn(active[i], active[j]);
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(K_aa);
    if (ldlt.info() != Eigen::Success) return false;
    // x = P^T L^-T D^+ L^-1 P (target - u), with D's small pivots inverted as 0.
    const Eigen::VectorXd pivots = ldlt.vectorD();
    const double cutoff = kSingularPivot * pivots.cwiseAbs().maxCoeff();
    x = ldlt.transpositionsP() * x;
    ldlt.matrixL().solveInPlace(x);
    for (int i = 0; i < a; ++i) x[i] = std::abs(pivots[i]) > cutoff ? x[i] / pivots[i] : 0.0;
    ldlt.matrixU().solveInPlace(x);
    x = ldlt.transpositionsP().transpose() * x;
    if (!x.allFinite()) return false;
    for (int i = 0; i < a; ++i) P_n[active[i]] = std::max(0.0, x[i]);
  }
  velocity = u_n + K_nn * P_n;
  return true;
}

}  // namespace

// Gauss-Seidel sweeps until they converge or kNormalSweepsBeforeExact have been made. Then, up to
// kMaxExactSolves times, an exact solve on the contacts that push (exact_on_active_set), which ends the
// solve where it meets the law within kExactResidual, and otherwise kNormalSweepsBetweenExact sweeps
// from it to settle which contacts push. Where none held (contacts so dependent that the solve on the
// active set gives impulses of both signs), the sweeps go on from where the first exact solve started,
// up to kMaxNormalSweeps in all, as they would have without the exact solves. Whenever the solve ends
// other than by an exact solve that held, the impulses closest to the law of all those tried are kept.
void solve_normal_law(const Eigen::MatrixXd& K_nn, const Eigen::VectorXd& u_n, const Eigen::VectorXd& target,
                      Eigen::VectorXd& P_n) {
  const int m = static_cast<int>(u_n.size());
  P_n.setZero(m);
  Eigen::VectorXd velocity = u_n;
  const double velocity_scale = std::max(u_n.cwiseAbs().maxCoeff(), target.cwiseAbs().maxCoeff());
  int sweeps = 0;
  if (normal_sweeps(K_nn, target, velocity_scale, kNormalSweepsBeforeExact, sweeps, P_n, velocity)) return;
  const double allowed = kExactResidual * velocity_scale;
  Eigen::VectorXd best = P_n;
  double best_violation = law_violation(P_n, velocity, target);
  Eigen::VectorXd tried = P_n, tried_velocity = velocity, candidate(m), candidate_velocity(m);
  const auto keep_if_better = [&](const Eigen::VectorXd& impulses, const Eigen::VectorXd& velocities) {
    const double violation = law_violation(impulses, velocities, target);
    if (violation < best_violation) {
      best_violation = violation;
      best = impulses;
    }
    return violation;
  };
  for (int solve = 0; solve < kMaxExactSolves; ++solve) {
    if (!exact_on_active_set(K_nn, u_n, target, tried, candidate, candidate_velocity)) break;
    if (keep_if_better(candidate, candidate_velocity) <= allowed) {
      P_n = candidate;
      return;
    }
    tried = candidate;
    tried_velocity = candidate_velocity;
    int between = 0;
    const bool settled =
        normal_sweeps(K_nn, target, velocity_scale, kNormalSweepsBetweenExact, between, tried, tried_velocity);
    keep_if_better(tried, tried_velocity);
    if (settled) {  // the sweeps converged from the candidate: the closest to the law seen is the result
      P_n = best;
      return;
    }
  }
  normal_sweeps(K_nn, target, velocity_scale, kMaxNormalSweeps - sweeps, sweeps, P_n, velocity);
  if (law_violation(P_n, velocity, target) > best_violation) P_n = best;
}

void solve_frictionless_law(const Eigen::MatrixXd& K, const Eigen::VectorXd& u_n, const Eigen::VectorXd& target,
                            Eigen::VectorXd& P) {
  const int m = static_cast<int>(u_n.size());
  const auto normal = Eigen::seqN(0, m, 3);  // the normal row of each contact
  Eigen::VectorXd P_n;
  solve_normal_law(K(normal, normal), u_n, target, P_n);
  P = Eigen::VectorXd::Zero(3 * m);
  P(normal) = P_n;
}

double contact_energy_change(const Eigen::MatrixXd& K, const Eigen::VectorXd& u, const Eigen::VectorXd& P) {
  return u.dot(P) + 0.5 * P.dot(K * P);
}

}  // namespace aloft
