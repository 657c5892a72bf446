// rattle()'s step 2, the drift (x' = x + h v, q' = exp(h w_m) q for every body, parents first) and the
// Newton corrections that close the joints at the new pose (SHAKE), full or sparse; the contact passes'
// drift; and step 2b, the push that moves overlapping pieces apart (simulation.cpp, rattle, says when
// each runs).

#include <algorithm>
#include <cmath>

#include "common/cpu_dispatch.hpp"
#include "dynamics/rotation.hpp"
#include "dynamics/step_workspace.hpp"

namespace aloft {

namespace {

// Joint i's gap at body i's position and lever arm `child_arm` (world) and its parent's pose in work.next
// (p < i: done first): the parent's lever arm into work.parent_arm[i], the gap divided by h into
// work.rows[i], ready for the next solve. Returns the gap's largest coordinate (m; NaN stays NaN).
[[gnu::always_inline]] inline double measure_joint(const Model& model, StepWorkspace& work, int i, double h,
                                                   const Vec3& position, const Vec3& child_arm) {
  const int p = model.parent[i];
  const Vec3 parent_arm = work.rotation[p] * model.joint_in_parent[i];
  const Vec3 gap = (work.next.position[p] + parent_arm) - (position + child_arm);
  work.parent_arm[i] = parent_arm;
  work.rows[i] = gap * (1.0 / h);
  return gap.cwiseAbs().maxCoeff();
}

// The drift of body i from `now` into work.next (its parent's must be done): x' = x + h v,
// q' = exp(h w_m) q with w_m = drift_map w (plus h times the pseudo-velocity if with_pseudo), the rotation
// matrix and lever arms at the new pose (kept for the factorization), and the joint gap divided by h into
// work.rows[i], ready for the next solve. Returns the gap's largest coordinate (m; NaN stays NaN).
[[gnu::always_inline]] inline double drift_body(const Model& model, StepWorkspace& work, const State& now, int i,
                                                double h, bool with_pseudo) {
  State& next = work.next;
  Vec3 position = now.position[i] + h * next.velocity[i];
  Quat orientation = turned(h * (work.drift_map[i] * next.angular[i]), now.orientation[i]);
  if (with_pseudo) {
    position += h * work.pseudo[i].head<3>();
    orientation = turned(h * work.pseudo[i].tail<3>(), orientation);
  }
  // The arms come from the local matrix, not from the array it is stored to (reading a just-written
  // matrix back stalls on store forwarding).
  const Mat3 turn = orientation.toRotationMatrix();
  const Vec3 child_arm = turn * model.joint_in_child[i];
  next.position[i] = position;
  next.orientation[i] = orientation;
  work.rotation[i] = turn;
  work.child_arm[i] = child_arm;
  return measure_joint(model, work, i, h, position, child_arm);
}

// Joint i's gap (m, per coordinate) as just measured, for the next correction: listed in work.open if
// wider than work.open_threshold (while there is room), else counted in work.unlisted_worst. (A NaN gap
// goes to the latter, and to the pass's worst, which gives the Newton iteration up.)
[[gnu::always_inline]] inline void note_gap(StepWorkspace& work, int i, double gap) {
  if (gap > work.open_threshold) {
    if (work.open.size() < work.most_open) {
      work.open.push_back(i);
    } else {
      work.open_overflow = true;
    }
  } else {
    work.unlisted_worst = widest(work.unlisted_worst, gap);
  }
}

// Before a full pass over the joints: nothing noted yet.
inline void start_noting(StepWorkspace& work) {
  work.open.clear();
  work.open_overflow = work.most_open == 0;
  work.unlisted_worst = 0;
}

// Before a sparse pass (a Newton correction's or a contact pass's, after a pass that left few joints
// open): those joints become work.listed, and nothing is noted yet. The joints not listed keep their gaps
// unless the solve reaches them (then they are measured again): what is known of the largest of them,
// returned, stays an upper bound.
inline double start_sparse_noting(StepWorkspace& work) {
  std::swap(work.listed, work.open);
  const double unlisted = work.unlisted_worst;
  start_noting(work);
  work.unlisted_worst = unlisted;
  return unlisted;
}

// A sparse pass's test for a subtree to pass over: the velocity its joint point is given (m/s, per
// coordinate) moves it by at most kSparseSkipFraction of the tolerance in the step of h.
inline auto negligible_motion(const StepWorkspace& work, double h) {
  const double negligible = kSparseSkipFraction * work.tolerance / h;
  return [negligible](int, const Vec3& parent_point) __attribute__((always_inline)) {
    return parent_point.cwiseAbs().maxCoeff() <= negligible;
  };
}

}  // namespace

// A pass of rattle()'s drift over all bodies (drift_body, parents first). The first of a step also forms
// each body's drift_map (see rattle's step 2) from the kicked velocities, just before drifting it.
// Returns the largest joint gap (m, per coordinate; NaN stays NaN).
ALOFT_CPU_DISPATCH double Simulation::drift_pass(double h, bool first_of_step, bool with_pseudo) {
  const int n = model_.count;
  StepWorkspace& work = *work_;
  const State& now = state_;
  const std::vector<Mat3>& inertia = work.solver.world_inertia();
  double worst = 0;
  start_noting(work);
  for (int i = 1; i < n; ++i) {
    if (first_of_step) {
      // drift_map = I(q_m)^-1 I(q) at the half-way orientation q_m = exp(h w / 2) q.
      const Quat half = turned(0.5 * h * work.next.angular[i], now.orientation[i]);
      const Mat3 midpoint_inverse_inertia = rotate_diagonal(half.toRotationMatrix(), work.inverse_moments[i]);
      work.drift_map[i].noalias() = midpoint_inverse_inertia * inertia[i];
    }
    const double gap = drift_body(model_, work, now, i, h, with_pseudo);
    worst = widest(worst, gap);
    note_gap(work, i, gap);
  }
  return worst;
}

// One Newton correction of rattle()'s drift: the tree solve of the joint gaps in work.rows, whose result
// each body adds, inside the solve's base-to-tip sweep, to its half-step velocity (kVelocity, with the
// joint impulses added to the step's) or to its pseudo-velocity (kPseudo) before drifting again
// (drift_body). Returns the largest joint gap after it (m, per coordinate; NaN stays NaN). Its callers
// count it, by the phase of the step, in StepStatistics.
// Sparse (see kSparseRowsPer) when the pass before left few joints open: the solve of those joints' gaps
// alone, visiting only the bodies whose joint point it moves by more than kSparseSkipFraction of the
// tolerance; joint i of a body it passes over, under a parent it moves, has its gap measured again with
// the parent's new pose (the body and what hangs from it keep their pose, velocities and impulses).
double Simulation::correct_and_drift(double h, DriftCorrection correction, bool with_pseudo) {
  StepWorkspace& work = *work_;
  const State& now = state_;
  State& next = work.next;
  double worst = 0;
  const auto correct_and_drift_body = [&](int i, const Vec6& du, const Vec3& impulse) __attribute__((always_inline)) {
    if (correction == DriftCorrection::kVelocity) {
      next.velocity[i] += du.head<3>();
      next.angular[i] += du.tail<3>();
      work.step_impulse[i] += impulse;
    } else {
      work.pseudo[i] += du;
    }
    const double gap = drift_body(model_, work, now, i, h, with_pseudo);
    worst = widest(worst, gap);
    note_gap(work, i, gap);
  };
  if (work.open_overflow) {
    start_noting(work);
    work.solver.solve_rows_visiting(work.rows, correct_and_drift_body);
    return worst;
  }
  ++work.statistics.sparse_corrections;
  const double unlisted = start_sparse_noting(work);
  // h |v| is how far the correction moves a point of velocity change v in the drift (both corrections).
  const auto skip = negligible_motion(work, h);
  const auto boundary = [&](int i) __attribute__((always_inline)) {
    const double gap = measure_joint(model_, work, i, h, next.position[i], work.child_arm[i]);
    worst = widest(worst, gap);
    note_gap(work, i, gap);
  };
  const auto visit = [&](int i, const Vec6& du, const Vec3& impulse) __attribute__((always_inline)) {
    ++work.statistics.sparse_bodies;
    correct_and_drift_body(i, du, impulse);
  };
  work.solver.solve_listed_rows_visiting(work.rows, work.listed, skip, visit, boundary);
  return widest(worst, unlisted);
}

// A contact pass of rattle(): the impulses work.response.solve_correction() found, added to the half-step
// velocities, and the drift again. Returns the largest joint gap after it (m, per coordinate; NaN stays
// NaN). Sparse, like correct_and_drift(), when the pass before left few joints open: the impulses act on
// the contacts' bodies, and only the bodies whose joint point they move by more than kSparseSkipFraction
// of the tolerance in the step are given their velocity change and drifted again (as the sparse
// corrections do; the joints at the edge of what it moves are measured again). A subtree it passes over
// keeps its velocities, where the full solve would have moved its joint point by at most that much (per
// coordinate) in the step; the Newton corrections close what that leaves of its joint's gap, and the
// step's velocity projection makes its velocities tangent to the joints, as after any drift. The joints
// the pass before left open are visited (their gaps measured again) whether or not it moves them, so
// every gap is known after it as after a full pass. The contacts' own bodies are on the impulses' paths,
// so their velocities are exactly the full solve's. (Measured against full passes:
// SparseCorrections.ContactPassesDriftOnlyWhatTheirImpulsesMoveAndEndWhereFullPassesDo.)
double Simulation::contact_pass_drift(double h) {
  StepWorkspace& work = *work_;
  State& next = work.next;
  if (work.open_overflow) {
    work.response.apply_correction(next.velocity, next.angular);
    return drift_pass(h, false, false);
  }
  ++work.statistics.sparse_contact_passes;
  const double unlisted = start_sparse_noting(work);
  const State& now = state_;
  double worst = 0;
  const auto skip = negligible_motion(work, h);
  const auto boundary = [&](int i) __attribute__((always_inline)) {
    const double gap = measure_joint(model_, work, i, h, next.position[i], work.child_arm[i]);
    worst = widest(worst, gap);
    note_gap(work, i, gap);
  };
  const auto visit = [&](int i, const Vec6& du, const Vec3&) __attribute__((always_inline)) {
    ++work.statistics.sparse_contact_pass_bodies;
    next.velocity[i] += du.head<3>();
    next.angular[i] += du.tail<3>();
    const double gap = drift_body(model_, work, now, i, h, false);
    worst = widest(worst, gap);
    note_gap(work, i, gap);
  };
  work.response.respond_visiting(work.listed, skip, visit, boundary);
  return widest(worst, unlisted);
}

// rattle()'s step 2b: drift with the pseudo-velocity added and correct the pseudo-velocity (not the real
// one) until the joints close. False if the Newton iteration gives up; the pose is then left open.
bool Simulation::push_apart(double h) {
  const double tolerance = joint_tolerance(h);
  double previous_worst = INFINITY;
  double worst = drift_pass(h, false, true);
  for (int iteration = 0;; ++iteration) {
    if (worst <= tolerance) return true;
    if (newton_gives_up(iteration, worst, previous_worst)) return false;
    previous_worst = worst;
    ++work_->statistics.push_corrections;
    worst = correct_and_drift(h, DriftCorrection::kPseudo, true);
  }
}

}  // namespace aloft
