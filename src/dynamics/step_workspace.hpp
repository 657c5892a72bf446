#pragma once
// What the stages of Simulation::step() share: the workspace (sized once per model) and the limits used
// by more than one of the files the step is written in:
//   simulation.cpp       the pipeline (step, advance_by, rattle: steps 1-4 top to bottom);
//   kick_and_collide.cpp rattle's step 1, the first half kick and the contacts' impulses;
//   drift_passes.cpp     its step 2, the drift and the Newton corrections that close the joints, and 2b,
//                        the push apart of overlaps;
//   contact_checks.cpp   whether the contacts allow a step of h (their turn and their motion in it).
// Internal to the library.

#include <array>
#include <cmath>
#include <cstddef>
#include <memory>
#include <vector>

#include "aloft/collision.hpp"
#include "aloft/simulation.hpp"
#include "dynamics/contact_response.hpp"
#include "dynamics/step_size_rule.hpp"
#include "dynamics/tree_solver.hpp"

namespace aloft {

// At most this many Newton corrections close the joints of one (sub)step (newton_gives_up).
inline constexpr int kMaxJointIterations = 8;

// Sparse Newton corrections (correct_and_drift): once a drift or correction leaves at most one joint in
// kSparseRowsPer open wider than kSparseRowFraction times the tolerance (and the mobile has at least
// kSparseMinBodies bodies), the next correction solves for those joints' gaps alone, and leaves whole
// every subtree whose joint point it would move by at most kSparseSkipFraction times the tolerance in
// the step (TreeSolver::solve_listed_rows_visiting). The joints it leaves keep their gaps, which were
// within kSparseRowFraction of the tolerance; the joints at the edge of what it moves are measured
// again. So every gap is known exactly after it, as after a full correction, and the iteration ends by
// the same test. The fractions are for speed only: over 6000 sparse corrections of generated-1023 in its
// tangle (`aloft_step_profile 1023 5000 1 swinging`), each solved both ways from the same state, a full
// correction closed the joints where the sparse one did not 22 times with a skip fraction of 0.1 and 13
// times (of 4000) with 0.5, which visits 45 bodies of 1022 per correction instead of 240 and costs 7 %
// of a full correction instead of 21 % (docs/performance.md, "Sparse Newton corrections"). Listing
// joints down to a tenth of the tolerance instead of a half made fewer passes sparse (0.57 per step
// instead of 1.17) for no fewer corrections.
inline constexpr int kSparseRowsPer = 16;
inline constexpr int kSparseMinBodies = 64;
inline constexpr double kSparseRowFraction = 0.5;
inline constexpr double kSparseSkipFraction = 0.5;

// Everything step() needs, sized once per model.
struct StepWorkspace {
  explicit StepWorkspace(const Model& model)
      : solver(model),
        next(rest_state(model)),
        backup(rest_state(model)),
        kick_sum(model.count, Vec6::Zero()),
        rows(model.count, Vec3::Zero()),
        impulse(model.count, Vec3::Zero()),
        step_impulse(model.count, Vec3::Zero()),
        drift_map(model.count, Mat3::Identity()),
        projection(model.count, Vec3::Zero()),
        older_projection(model.count, Vec3::Zero()),
        rotation(model.count, Mat3::Identity()),
        child_arm(model.count, Vec3::Zero()),
        parent_arm(model.count, Vec3::Zero()),
        inverse_moments(model.count, Vec3::Zero()),
        response(model),
        pseudo(model.count, Vec6::Zero()),
        probe(rest_state(model)),
        wider(model.count, 0),
        looked_margin(model.count, 0.0),
        step_rule(model) {
    for (int i = 0; i < model.count; ++i) rotation[i] = model.rest_orientation[i].toRotationMatrix();
    for (int i = 1; i < model.count; ++i) inverse_moments[i] = model.principal_moments[i].cwiseInverse();
    if (model.count >= kSparseMinBodies && solver.sparse_rows_possible()) sparse_open = model.count / kSparseRowsPer;
    most_open = sparse_open;
    open.reserve(most_open);
    listed.reserve(most_open);
  }
  TreeSolver solver;
  bool factored = false;         // solver holds the factorization at the current state's pose
  State next;                    // the state being computed; swapped in when the step succeeds
  State backup;                  // the state before a subdivided step, to return to if it fails (sized
                                 // here, so that the first halving does not allocate either)
  std::vector<Vec6> kick_sum;    // the half kick's impulses from the child joints' guesses, summed into each
                                 // parent (N s, N m s, world); zero between kicks (each entry reset once read)
  std::vector<Vec3> rows;        // scratch per joint
  std::vector<Vec3> impulse;     // joint impulses of the last step (N s), for the warm start
  std::vector<Vec3> step_impulse;  // joint impulses being accumulated in this step
  std::vector<Mat3> drift_map;   // per body: kicked angular velocity -> drift angular velocity
  std::vector<Vec3> projection;  // joint impulses of the last step's second half kick (N s), at its end
  std::vector<Vec3> older_projection;  // and of the step before
  double impulse_step = 0;       // the step length (s) impulse and projection belong to
  bool impulse_after_contacts = false;  // the step `impulse` comes from applied contact impulses (the next
                                        // guess leaves out its difference term; see kick_and_collide)
  double older_step = 0;         // and the one of older_projection
  std::vector<Mat3> rotation;    // rotation matrices of next.orientation (index 0: the fixed pose)
  std::vector<Vec3> child_arm;   // at next's pose: R_i joint_in_child[i] (handed to the solver's factor)
  std::vector<Vec3> parent_arm;  // at next's pose: R_p joint_in_parent[i]
  std::vector<Vec3> inverse_moments;  // 1 / principal moments (kg^-1 m^-2)
  // Sparse corrections (see kSparseRowsPer): the joints the last drift or correction left open wider than
  // open_threshold (m), at most most_open of them (open_overflow: there were more); the largest gap (m)
  // of the others, as far as it is known (an upper bound after a sparse correction); the step's joint
  // tolerance (m). `listed` is scratch: the joints a sparse correction solves for.
  std::vector<int> open, listed;
  std::size_t most_open = 0, sparse_open = 0;  // (sparse_open: most_open with sparse corrections on)
  bool open_overflow = true;
  double open_threshold = 0, unlisted_worst = 0, tolerance = 0;
  double state_sum = 0;          // sum of the last accepted (sub)step's state entries (NaN check)
  long long subdivisions = 0;    // how many times a step was halved
  int start_depth = 0;           // the subdivision depth a step starts at (advance_by)
  int deepest = 0;               // the deepest subdivision a substep of this step was taken at
  int settled_steps = 0;         // steps in a row that needed no subdivision deeper than start_depth
  StepStatistics statistics;       // see Simulation::step_statistics (also rejected_substeps, joint_iterations)
  // Why rattle() last returned false (counted in `statistics` by advance_by).
  enum class Outcome { kSpin, kContactTurn, kJoints, kContactMotion } outcome = Outcome::kSpin;
  std::array<bool, 3> spin_over{};  // for kSpin: which of the rule's measures (turn, anchor, drift) were over
  // Collisions.
  std::unique_ptr<CollisionDetector> detector;  // null while collisions are off
  std::vector<Contact> contacts;  // found at the start of the last (sub)step
  std::vector<std::pair<int, int>> pushed_pairs;  // of the accepted (sub)steps of the step so far
  ContactResponse response;
  std::vector<Vec6> pseudo;       // per body: penetration-removing pseudo-velocity (drift only)
  State probe;                    // the current pose with the half-step velocities, for detection
  std::vector<Contact> nearby;    // found within the margins plus kRecheckSlack (see kick_and_collide)
  bool last_look_found = false;   // the last detection found contacts
  std::vector<Contact> recheck;   // contacts found again after the impulses changed the velocities
  std::vector<char> wider;        // per component: its margin after the impulses is wider than the look's
  std::vector<double> looked_margin;  // per component: the margin (m) its pairs in `nearby` were looked for
                                      // with (kick_and_collide)
  StepSizeRule step_rule;         // whether h is short enough for the drift and the joints (else halve)
  // Why the last (sub)step of the shortest length the subdivision allows was rejected: what a failure
  // reports. kStepRule: `rejected_body` spins too fast (`rejected_value` its turn per step, rad);
  // kJoints: its joint stayed open (`rejected_value` the gap, m).
  enum class Rejection { kNone, kStepRule, kJoints } rejection = Rejection::kNone;
  int rejected_body = 0;
  double rejected_value = 0;
};

// Whether the Newton iteration on the joints should stop trying this h: too many iterations, a
// non-finite gap, or (from the third pass on) a gap that did not at least halve.
inline bool newton_gives_up(int iteration, double worst, double previous_worst) {
  return iteration == kMaxJointIterations || !std::isfinite(worst) ||
         (iteration >= 2 && !(worst < 0.5 * previous_worst));
}

// The larger of two gaps, NaN if either is (a NaN gap must not be lost).
inline double widest(double worst, double gap) { return gap > worst || !std::isfinite(gap) ? gap : worst; }

// Applied wrenches at `state` (world): gravity, external loads, air damping. There is no gyroscopic
// term: the kicks change the world angular momentum L, whose rate is the torque alone; the rotation
// of the inertia tensor is in the drift (step 2). `momentum` is body i's I w at `state`, read only for
// the damping (damped()).
inline Vec6 Simulation::applied_wrench(const State& state, int i, const Vec3& momentum) const {
  const double m = model_.mass[i];
  Vec6 f;
  f.head<3>() = m * model_.gravity;
  f.tail<3>().setZero();
  if (loads_in_use_) {
    f.head<3>() += loads_.force[i];
    f.tail<3>() = loads_.torque[i];
  }
  if (damped()) {
    f.head<3>() -= damping_.linear * m * state.velocity[i];
    f.tail<3>() -= damping_.angular * momentum;
  }
  return f;
}

}  // namespace aloft
