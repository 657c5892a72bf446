#include "aloft/simulation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "dynamics/contact_response.hpp"
#include "dynamics/contact_sweep.hpp"
#include "dynamics/contact_travel.hpp"
#include "dynamics/rotation.hpp"
#include "dynamics/step_size_rule.hpp"
#include "dynamics/tree_solver.hpp"

namespace aloft {

void ExternalLoads::resize(int count) {
  force.assign(count, Vec3::Zero());
  torque.assign(count, Vec3::Zero());
}

void ExternalLoads::clear() {
  std::fill(force.begin(), force.end(), Vec3::Zero());
  std::fill(torque.begin(), torque.end(), Vec3::Zero());
}

namespace {

// Joint positions must agree to kJointToleranceRate h^2 (m, per coordinate), and never need to agree
// closer than kJointToleranceFloor, before a (sub)step of h is accepted (Simulation::joint_tolerance).
// A gap left open is a position error that the next step closes, not one that accumulates. Measured
// against a converged run (h = 0.01 ms, gaps below 1e-13 m), from the benchmarks' swinging state, the
// largest distance between centres of mass at t = 1 s:
//   Steel Fish, h = 1 ms:     5.6e-7 m with gaps up to 1e-9 m, 4.8e-7 with 1e-7, 1.7e-6 with 1e-6;
//   Steel Fish, h = 0.1 ms:   5.5e-9 m with 1e-9, 5.4e-8 with 3e-8, 1.6e-7 with 1e-7;
//   generated-127, h = 1 ms:  7.8e-5 m with 1e-9 and with 1e-7 (9.5e-6 against 8.7e-6 at 0.5 s);
// and for the gentler swing of the unbalanced Steel Fish released from rest, 1.3e-7 m with gaps up to
// 1e-12 m, 1.8e-7 m with this rule at 1 ms; 1.25e-9 and 1.57e-9 m at 0.1 ms (JointTolerance tests).
// So what the gap adds stays below the gap allowed, which costs little while it stays below the
// method's own error; that error falls as h^2, so the tolerance does: 1e-7 m at 1 ms. (Gaps up to 1e-9 m
// at every h, as before, took one more Newton correction on most steps of the generated mobiles:
// docs/performance.md, "The joint tolerance".) The floor is that old tolerance: it keeps the short
// substeps of a knock from needing more corrections than they did. Either way a joint stays 5 times
// closer than it may ever open (1e-6 m; 1.7e-7 m is the diagonal of a 1e-7 m gap per coordinate).
constexpr double kJointToleranceRate = 0.1;    // m/s^2
constexpr double kJointToleranceFloor = 1e-9;  // m
constexpr int kMaxJointIterations = 8;
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
constexpr int kSparseRowsPer = 16;
constexpr int kSparseMinBodies = 64;
constexpr double kSparseRowFraction = 0.5;
constexpr double kSparseSkipFraction = 0.5;
// A step whose joint impulses do not converge is split in two, recursively, at most this deep.
constexpr int kMaxSubdivision = 8;
// A step starts at the subdivision depth the last step needed (see advance_by); after this many steps
// in a row that needed no more, the next one tries once more at half that depth.
constexpr int kStepsBeforeCoarser = 4;
// A step with collisions on is accepted (contacts_move_slowly_enough) when, for every contact, either
// the pieces can get at most kDeepeningPerHalfWidth times the thinnest one's half-width (and at most
// kMaxContactTravel) deeper into each other (contact_deepening_bound), or no point of them travels more
// than kMaxContactTravel, or, where neither holds, the pair's motion through the step, sampled
// (sweep_contact), takes it no deeper than the first allows.
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
// Contacts are looked for within this distance (m) plus what the pair can close in one step. Half a
// millimetre keeps a resting contact (which settles to within the penetration slop, 0.05 mm) in the
// list from one step to the next without testing pieces that are far apart.
constexpr double kContactMargin = 5e-4;
// The detection at the start of a step looks this much (m) further from each component than its margin,
// so that when the impulses change the velocities, the contacts within the new margins can be picked
// from what it found instead of detecting again, as long as no component's margin grew by more (see
// kick_and_collide).
constexpr double kRecheckSlack = 1e-4;
// Contacts re-checked after the joints' impulses: at most this many corrections per step, each when a
// contact approaches faster than this (m/s; 1e-6 m/s closes 1 nm per step).
constexpr int kMaxContactPasses = 2;
constexpr double kContactVelocityTolerance = 1e-6;
// A half kick that changes a body's turn per step by more than this (rad) is suspected of a wrong guess of
// the joint impulses (see rattle): the forces of a mobile, gravity and the joints' reactions to it, change
// it by (h^2 / 2) times the angular acceleration, 1e-5 to 1e-3 rad at h = 1 ms. (A knock may exceed it;
// then the retry without the guess costs one more kick and detection.)
constexpr double kSuspiciousKick = 0.01;

}  // namespace

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
  ContactResponse response;
  std::vector<Vec6> pseudo;       // per body: penetration-removing pseudo-velocity (drift only)
  State probe;                    // the current pose with the half-step velocities, for detection
  std::vector<Contact> nearby;    // found within the margins plus kRecheckSlack (see kick_and_collide)
  bool last_look_found = false;   // the last detection found contacts
  std::vector<Contact> recheck;   // contacts found again after the impulses changed the velocities
  std::vector<char> wider;        // per component: its margin after the impulses is wider than the look's
  StepSizeRule step_rule;         // whether h is short enough for the drift and the joints (else halve)
  // Why the last (sub)step of the shortest length the subdivision allows was rejected: what a failure
  // reports. kStepRule: `rejected_body` spins too fast (`rejected_value` its turn per step, rad);
  // kJoints: its joint stayed open (`rejected_value` the gap, m).
  enum class Rejection { kNone, kStepRule, kJoints } rejection = Rejection::kNone;
  int rejected_body = 0;
  double rejected_value = 0;
};

namespace {

// Whether the Newton iteration on the joints should stop trying this h: too many iterations, a
// non-finite gap, or (from the third pass on) a gap that did not at least halve.
inline bool newton_gives_up(int iteration, double worst, double previous_worst) {
  return iteration == kMaxJointIterations || !std::isfinite(worst) ||
         (iteration >= 2 && !(worst < 0.5 * previous_worst));
}

bool finite(const Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

}  // namespace

Simulation::Simulation(const Model& model) : Simulation(model, rest_state(model)) {}

Simulation::Simulation(const Model& model, State initial)
    : model_(model),
      state_(std::move(initial)),
      timestep_(model.timestep),
      damping_(model.damping),
      work_(std::make_unique<StepWorkspace>(model)) {
  loads_.resize(model.count);
  work_->next = state_;
  work_->rotation[0] = state_.orientation[0].toRotationMatrix();
  set_collisions(model.contact.enabled);
}

void Simulation::set_collisions(bool enabled) {
  collisions_ = enabled;
  if (enabled && !work_->detector) work_->detector = std::make_unique<CollisionDetector>(model_);
  if (!enabled) work_->contacts.clear();
}

void Simulation::set_sparse_corrections(bool on) { work_->most_open = on ? work_->sparse_open : 0; }

const std::vector<Contact>& Simulation::contacts() const { return work_->contacts; }

const CollisionDetector* Simulation::collision_detector() const { return work_->detector.get(); }

Simulation::~Simulation() = default;

State& Simulation::mutable_state() {
  work_->factored = false;
  work_->impulse_step = work_->older_step = 0;  // no warm start across a jump
  work_->start_depth = work_->settled_steps = 0;  // nor a remembered subdivision
  return state_;
}

long long Simulation::subdivisions() const { return work_->subdivisions; }

long long Simulation::rejected_substeps() const {
  const StepStatistics& s = work_->statistics;
  return s.attempts - s.accepted;
}

long long Simulation::joint_iterations() const {
  const StepStatistics& s = work_->statistics;
  return s.joint_corrections + s.contact_pass_corrections + s.push_corrections;
}

const StepStatistics& Simulation::step_statistics() const { return work_->statistics; }

double Simulation::joint_tolerance(double h) const {
  if (fixed_joint_tolerance_ > 0) return fixed_joint_tolerance_;
  return std::max(kJointToleranceFloor, kJointToleranceRate * h * h);
}

void Simulation::set_timestep(double seconds) {
  timestep_ = seconds;
}

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

// Whether h is the shortest (sub)step the subdivision allows.
bool Simulation::at_finest_step(double h) const { return !(h > std::ldexp(timestep_, -kMaxSubdivision) * 1.5); }

// The step-size rule rejected the half-kicked velocities work.next.angular: count which of its measures
// were over their limits, note, for a failure at the shortest step, the body that spins fastest for its
// limits, and return false. (Measuring every body costs about a pass over them; rejections are a few per
// cent of the (sub)steps even where the motion is fastest.)
bool Simulation::reject_spin(double h) {
  StepWorkspace& work = *work_;
  const TreeSolver& solver = work.solver;
  const StepSizeMeasures m = work.step_rule.measure(h, work.next.angular, solver.world_inertia(),
                                                    solver.world_inverse_inertia(), solver.child_arm(),
                                                    solver.parent_arm());
  work.outcome = StepWorkspace::Outcome::kSpin;
  work.spin_over = {!(m.turn <= 1), !(m.anchor_turn <= 1), !(m.drift_error <= 1)};
  if (at_finest_step(h)) {
    int body = m.turn_body;
    double worst = m.turn;
    if (!(m.anchor_turn <= worst)) worst = m.anchor_turn, body = m.anchor_turn_body;
    if (!(m.drift_error <= worst)) body = m.drift_error_body;
    work.rejection = StepWorkspace::Rejection::kStepRule;
    work.rejected_body = body;
    work.rejected_value = h * work.next.angular[body].norm();
  }
  return false;
}

namespace {

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
//   - travel little: no point of the near parts of its pieces (Contact::near_low_a ...) moves more than
//     kMaxContactTravel, or
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
  // How far any point of the pieces in contact travels, from the speed of their fastest point: at most
  // |v| + |w| times the pieces' reach from the centre of mass, and at most the fastest corner of the box
  // around them, |v + w x corner| (sharper for a piece turning about an axis through or near it, as a
  // plate spinning on its thread; to first order in the turn). Any other piece of the pair that could come
  // near within the step is within the detection margin, which the component's whole reach sets, so it is
  // a contact of its own, checked here too.
  const auto travels_little = [&](const Contact& c) {
    for (int k = 0; k < 2; ++k) {
      const int i = k == 0 ? c.a : c.b;
      if (i == 0) continue;
      const Motion m = motion(i);
      const double reach = std::min(work.detector->reach(i), k == 0 ? c.reach_a : c.reach_b);
      const double turn = m.drift.norm() + m.push.norm();
      if (h * (m.velocity.norm() + turn * reach) <= kMaxContactTravel) continue;
      const Vec3& low = k == 0 ? c.near_low_a : c.near_low_b;
      const Vec3& high = k == 0 ? c.near_high_a : c.near_high_b;
      if (!(low.x() <= high.x()) ||
          h * (fastest_corner_speed(state_.orientation[i], m.velocity, m.drift, low, high) +
               m.push.norm() * farthest_corner(low, high)) > kMaxContactTravel)
        return false;
    }
    return true;
  };
  // The bound on how much deeper the pieces get, where it covers them all: every nearby piece pair of
  // the two components is a contact (c.complete), each within a known box.
  const auto deepens_little = [&](const Contact& c) {
    if (!c.complete || !(c.near_low_a.x() <= c.near_high_a.x()) || !(c.near_low_b.x() <= c.near_high_b.x()))
      return false;
    const double allowed = std::min(kMaxContactTravel, kDeepeningPerHalfWidth * c.thinnest);
    return contact_deepening_bound(c, side(c.a, c.reach_a, c.near_low_a, c.near_high_a),
                                   side(c.b, c.reach_b, c.near_low_b, c.near_high_b), h, true) <= allowed;
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
    const double allowed = std::min(kMaxContactTravel, kDeepeningPerHalfWidth * c.thinnest);
    const SweepResult sweep =
        sweep_contact(*work.detector, c.a, swept(c.a, c.reach_a, c.near_low_a, c.near_high_a), c.b,
                      swept(c.b, c.reach_b, c.near_low_b, c.near_high_b), h, start_overlap, allowed, c.thinnest);
    if (!sweep.shallow) return false;
  }
  return true;
}

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

// The larger of two gaps, NaN if either is (a NaN gap must not be lost).
inline double widest(double worst, double gap) { return gap > worst || !std::isfinite(gap) ? gap : worst; }

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
    // When no component's margin grew by more than kRecheckSlack, every contact within the new margins
    // is in `nearby`: `aloft_step_profile` after the breeze, collisions on, needed the detector again
    // for 38 of 979 looks on generated-127 (1000 steps) and 23 of 354 on generated-1023 (100 steps);
    // with a slack of 0.05 mm for 57 and 29, with 0.25 mm for 10 and 9 (a wider first look costs more);
    // with the slack only after a look whose contacts had impulses, for 405 and 26. Where some margins did
    // grow more, only the pairs of those components are looked at again (find_contacts_again).
    work.last_look_found = !work.contacts.empty();
    if (contact_report.active > 0) {
      bool covered = true;  // no component's margin is wider now than in the look `nearby` came from
      for (int i = 1; i < n; ++i) {
        const double looked =
            work.detector->margin(i, probe.velocity[i], probe.angular[i], h, kContactMargin + 2 * slack);
        probe.velocity[i] = next.velocity[i];
        probe.angular[i] = next.angular[i];
        work.wider[i] = work.detector->margin(i, probe.velocity[i], probe.angular[i], h, kContactMargin) > looked;
        covered = covered && !work.wider[i];
      }
      if (covered)
        work.detector->keep_within_margin(work.nearby, probe, h, kContactMargin, work.recheck);
      else
        work.detector->find_contacts_again(work.nearby, probe, h, kContactMargin, work.wider, work.recheck);
      const auto same_pair = [](const Contact& x, const Contact& y) { return x.a == y.a && x.b == y.b; };
      const bool other = work.recheck.size() != work.contacts.size() ||
                         !std::equal(work.recheck.begin(), work.recheck.end(), work.contacts.begin(), same_pair);
      if (other) {
        std::swap(work.contacts, work.recheck);
        const ContactStepReport again =
            work.response.resolve(now, solver, work.contacts, h, next.velocity, next.angular, work.pseudo, has_pseudo);
        contact_report.contacts = again.contacts;
        contact_report.dropped = again.dropped;  // what the step leaves unsolved is the last list's
        contact_report.solves += again.solves;
        contact_report.solved += again.solved;
        contact_report.reused += again.reused;
        contact_report.iterations += again.iterations;
        contact_report.active += again.active;
        contact_report.sticking += again.sticking;
        contact_report.sliding += again.sliding;
        contact_report.restitution_dropped = contact_report.restitution_dropped || again.restitution_dropped;
        contact_report.friction_dropped = contact_report.friction_dropped || again.friction_dropped;
        contact_report.frictionless = std::max(contact_report.frictionless, again.frictionless);
        contact_report.energy_change += again.energy_change;
        contact_report.deepest = std::max(contact_report.deepest, again.deepest);
      }
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

// One RATTLE step of `h` seconds from state_ into work.next. Returns false, leaving state_ and the
// factorization untouched, when the joint impulses do not converge (the motion is too fast for h).
ALOFT_CPU_DISPATCH bool Simulation::rattle(double h) {
  const int n = model_.count;
  StepWorkspace& work = *work_;
  const State& now = state_;
  State& next = work.next;
  TreeSolver& solver = work.solver;
  std::vector<Vec3>& c = work.rows;
  std::vector<Mat3>& rotation = work.rotation;

  if (!work.factored) {
    solver.factor(now);
    rotation[0] = now.orientation[0].toRotationMatrix();
  }

  // 1. The half kick and the contacts. A rejection after a kick that changed some body's turn per step by
  //    more than kSuspiciousKick is tried once more without the guessed joint impulses: the guess is only
  //    a starting point for SHAKE, and a wrong one (a force going round a loop that a contact closes,
  //    which the contact cancels every step while the warm start carries it on, and which the
  //    extrapolation used until then doubled) must not halve the step down to failure at the finest step,
  //    as it did for generated-1023 after a breeze (t = 0.6 s;
  //    Collisions.CrowdedGeneratedMobileInABreezeKeepsGoing) and, in a version without this retry, for
  //    the shaken Steel Fish (t = 48 s). Kicked without a guess, SHAKE finds the joint impulses afresh,
  //    and the loop force is gone.
  bool has_pseudo = false;
  ContactStepReport contact_report;
  if (!kick_and_collide(h, true, contact_report, has_pseudo)) {
    bool suspicious = false;
    for (int i = 1; i < n && !suspicious && work.impulse_step > 0; ++i)
      suspicious = h * (next.angular[i] - now.angular[i]).norm() > kSuspiciousKick;
    if (!suspicious) return false;
    ++work.statistics.kicks_retried;
    if (!kick_and_collide(h, false, contact_report, has_pseudo)) return false;
  }

  // 2. Drift with the half-step velocities, x' = x + h v, q' = exp(h w) q, choosing the joint impulses
  //    of the half kick so that every joint closes at the new pose (SHAKE). Newton's method with the
  //    current pose's factorization: solving J du = -C(x')/h moves the joints by -C to first order.
  //    The first pass drifts with the kicked velocities; each correction (correct_and_drift) is one tree
  //    solve whose base-to-tip sweep adds each body's correction and drifts it again at once. A pass
  //    leaves the rotation matrices and lever arms of the new pose (kept for the factorization) and the
  //    joint gaps. The drift turns each body at constant world angular momentum L = I w (a free rigid
  //    body): the implicit midpoint of that flow, q' = exp(h w_m) q with w_m = I(q_m)^-1 L at the half-way
  //    orientation q_m = exp(h w_m / 2) q, found by one fixed-point pass from the predicted velocity
  //    (symmetric to O(h^3) per step, so the energy does not drift). drift_map = I(q_m)^-1 I(q), formed by
  //    the first pass, turns the kicked angular velocity (at the current inertia) into w_m, also for the
  //    corrections.
  const double tolerance = joint_tolerance(h);
  work.tolerance = tolerance;
  work.open_threshold = kSparseRowFraction * tolerance;
  double previous_worst = INFINITY;
  int contact_passes = 0;
  double worst = drift_pass(h, true, false);
  for (int iteration = 0;; ++iteration) {  // iteration: the corrections since the last plain drift
    if (worst <= tolerance) {
      // The joint impulses changed the velocities after the contacts were solved: if a contact is
      // approaching again, correct it (no new bounce) and close the joints once more.
      if (contact_report.active == 0 || contact_passes == kMaxContactPasses ||
          !work.response.solve_correction(h, next.velocity, next.angular, kContactVelocityTolerance))
        break;
      ++contact_passes;
      ++work.statistics.contact_passes;
      previous_worst = INFINITY;
      iteration = -1;
      worst = contact_pass_drift(h);
      continue;
    }
    // Not converging (too many iterations, growing or non-finite gaps): give up on this h.
    if (newton_gives_up(iteration, worst, previous_worst)) {
      work.outcome = StepWorkspace::Outcome::kJoints;
      if (at_finest_step(h)) {
        work.rejection = StepWorkspace::Rejection::kJoints;
        work.rejected_value = -1;  // the widest gap, or NaN at the first joint whose gap is not finite
        for (int i = 1; i < n; ++i) {
          if (!c[i].allFinite()) {
            work.rejected_value = NAN;
            work.rejected_body = i;
            break;
          }
          const double gap = h * c[i].cwiseAbs().maxCoeff();
          if (gap > work.rejected_value) {
            work.rejected_value = gap;
            work.rejected_body = i;
          }
        }
      }
      return false;
    }
    previous_worst = worst;
    ++(contact_passes == 0 ? work.statistics.joint_corrections : work.statistics.contact_pass_corrections);
    worst = correct_and_drift(h, DriftCorrection::kVelocity, false);
  }
  // 2b. Overlaps: the split impulse's pseudo-velocity moves the bodies apart on top of the drift. It
  //     respects the joints only to first order; the rest is closed here by correcting the
  //     pseudo-velocity itself (the same Newton iteration), never the real velocities. Closed with real
  //     impulses (as SHAKE did before), the rest, up to a push's square over a lever arm, became a real
  //     velocity of rest / h: kinetic energy from nothing, more the more a step is halved. (On
  //     generated-1023 after a breeze, this alone moved the failure described above from t = 0.6 s to
  //     0.8 s.) If the pass does not close the joints, the overlap is left for the next step.
  work.statistics.pushes += has_pseudo;
  const bool pushed = has_pseudo && push_apart(h);
  if (has_pseudo && !pushed) drift_pass(h, false, false);
  // The step's motion is final: whether the pieces in contact moved slowly enough for h.
  if (collisions_ && !work.contacts.empty() && !contacts_move_slowly_enough(h, pushed)) {
    work.outcome = StepWorkspace::Outcome::kContactMotion;
    return false;
  }
  std::swap(work.impulse, work.step_impulse);
  work.older_step = work.impulse_step;
  work.impulse_step = h;
  work.impulse_after_contacts = contact_report.active > 0;

  // 3. Factor at the new pose (also used by the next step), from the rotation matrices and lever arms of
  //    the last drift pass, and in the same sweep:
  // 4. Second half kick with the new pose's forces, and joint impulses that make the velocities tangent
  //    to the joints at the new pose (RATTLE): M' v' = M' v + (h/2) f' + J'^T mu,  J' v' = 0, where the
  //    angular part of M' v is the angular momentum I w of the half-step velocity (unchanged by the
  //    drift's turn: the free body's). So the tree solve is of the momenta with zero joint rows, and its
  //    result is the new velocity itself.
  //    The solver asks for each body's f as its sweep reaches it, with the world inertia of the step's
  //    start (the pose it factored before), which turns the half-step angular velocity into I w.
  const auto momenta_and_forces = [&](int i, const Mat3& start_inertia) __attribute__((always_inline)) {
    const Vec3 momentum = start_inertia * next.angular[i];
    Vec6 f = (0.5 * h) * applied_wrench(next, i, momentum);
    f.head<3>() += model_.mass[i] * next.velocity[i];
    f.tail<3>() += momentum;
    return f;
  };
  std::swap(work.older_projection, work.projection);
  double sum = 0;
  solver.factor_and_solve(rotation, work.child_arm, work.parent_arm, momenta_and_forces,
                          [&](int i, const Vec6& u, const Vec3& impulse) __attribute__((always_inline)) {
                            next.velocity[i] = u.head<3>();
                            next.angular[i] = u.tail<3>();
                            work.projection[i] = impulse;
                            sum += next.position[i].sum() + next.velocity[i].sum() + next.angular[i].sum() +
                                   next.orientation[i].w();
                          });
  work.state_sum = sum;
  next.time = now.time + h;
  std::swap(state_, next);
  work.factored = true;
  // (A look after the impulses may find no contacts left, `contacts` then 0, after the first look's were
  // solved: `solves` still counts that step.)
  if (contact_report.contacts > 0 || contact_report.solves > 0) {
    CollisionStatistics& stats = collision_stats_;
    ++stats.steps_with_contacts;
    stats.impulses += contact_report.active;
    stats.sliding += contact_report.sliding;
    stats.restitution_dropped += contact_report.restitution_dropped;
    stats.friction_dropped += contact_report.friction_dropped;
    stats.friction_dropped_in_part += !contact_report.friction_dropped && contact_report.frictionless > 0;
    stats.law_solves += contact_report.solves;
    stats.law_contacts += contact_report.solved;
    stats.law_sweeps += contact_report.iterations;
    stats.contacts_left += contact_report.dropped;
    stats.energy_removed -= std::min(0.0, contact_report.energy_change);
    stats.deepest = std::max(stats.deepest, contact_report.deepest);
  }
  return true;
}

// Advance by h, halving the step where RATTLE does not converge or the step-size rule finds h too long
// for the spins (step_size_rule.hpp), down to h / 2^kMaxSubdivision. Lengths above the step's start
// depth are not tried: motion fast enough to need halving lasts many steps, and each failed attempt
// costs a kick and, with collisions on, a detection (on generated-1023 swinging with collisions, about
// 3 failed attempts per step before this).
bool Simulation::advance_by(double h, int depth) {
  StepWorkspace& work = *work_;
  if (depth >= work.start_depth) {
    StepStatistics& stats = work.statistics;
    ++stats.attempts;
    if (rattle(h)) {
      ++stats.accepted;
      work.deepest = std::max(work.deepest, depth);
      return true;
    }
    using Outcome = StepWorkspace::Outcome;
    switch (work.outcome) {
      case Outcome::kSpin:
        ++stats.rejected_spin;
        stats.spin_turn_over += work.spin_over[0];
        stats.spin_anchor_over += work.spin_over[1];
        stats.spin_drift_over += work.spin_over[2];
        break;
      case Outcome::kContactTurn: ++stats.rejected_contact_turn; break;
      case Outcome::kJoints: ++stats.rejected_joints; break;
      case Outcome::kContactMotion: ++stats.rejected_contact_motion; break;
    }
  }
  if (depth == kMaxSubdivision) return false;
  if (depth == 0) work_->backup = state_;  // sized once: copying does not allocate after the first time
  ++work_->subdivisions;
  return advance_by(0.5 * h, depth + 1) && advance_by(0.5 * h, depth + 1);
}

bool Simulation::step() {
  const double start = state_.time;
  const long long subdivisions_before = work_->subdivisions;
  work_->rejection = StepWorkspace::Rejection::kNone;
  work_->rejected_value = 0;
  work_->deepest = 0;
  const bool converged = advance_by(timestep_, 0);
  // The next step starts as deep as this one needed to go; after kStepsBeforeCoarser steps that needed
  // no deeper, one level less deep.
  StepWorkspace& w = *work_;
  if (w.deepest > w.start_depth) {
    w.start_depth = w.deepest;
    w.settled_steps = 0;
  } else if (w.start_depth > 0 && ++w.settled_steps >= kStepsBeforeCoarser) {
    --w.start_depth;
    w.settled_steps = 0;
  }

  // Check: a non-finite state (or one the solver cannot close) stops the simulation with a report.
  const int n = model_.count;
  double sum = work_->state_sum;  // of the state the last accepted (sub)step made
  if (!converged) {
    sum = 0;
    for (int i = 1; i < n; ++i)
      sum += state_.position[i].sum() + state_.velocity[i].sum() + state_.angular[i].sum() + state_.orientation[i].w();
  }
  if (!converged || !std::isfinite(sum)) {
    int bad = 1;
    for (int i = 1; i < n; ++i)
      if (!(finite(state_.position[i]) && finite(state_.velocity[i]) && finite(state_.angular[i]) &&
            std::isfinite(state_.orientation[i].w()))) {
        bad = i;
        break;
      }
    const StepWorkspace& work = *work_;
    using Rejection = StepWorkspace::Rejection;
    if (std::isfinite(sum) && work.rejection != Rejection::kNone) bad = work.rejected_body;
    const bool non_finite = !std::isfinite(sum) || !std::isfinite(work.rejected_value);
    SimulationFailure fail;
    fail.component = bad;
    fail.component_name = model_.names[bad];
    fail.time = start + timestep_;
    std::ostringstream msg;
    msg << "the simulation " << (non_finite ? "became non-finite" : "stopped") << " at t = " << fail.time
        << " s (step " << steps_ + 1 << "): ";
    if (non_finite) {
      msg << "component '" << model_.names[bad] << "' has a NaN or infinite position, velocity or angular velocity";
    } else if (work.rejection == Rejection::kStepRule) {
      msg << "component '" << model_.names[bad] << "' spins too fast even for the step divided "
          << (1 << kMaxSubdivision) << " times (it would turn " << work.rejected_value
          << " rad in that step, beyond the step-size rule's limits)";
    } else {
      msg << "the joints could not be closed even with the step divided " << (1 << kMaxSubdivision) << " times";
      if (work.rejection == Rejection::kJoints)
        msg << " (the widest gap, " << work.rejected_value << " m, at the joint of component '" << model_.names[bad]
            << "')";
    }
    msg << "; the last finite state is kept";
    fail.message = msg.str();
    failure_ = fail;
    if (work_->subdivisions == subdivisions_before) {
      if (converged) std::swap(state_, work_->next);  // one whole step was taken: its start is in next
    } else {
      state_ = work_->backup;  // undo the completed substeps
    }
    work_->factored = false;
    return false;
  }
  ++steps_;
  return true;
}

bool Simulation::advance(double duration) {
  const long long count = std::llround(duration / timestep_);
  for (long long k = 0; k < count; ++k)
    if (!step()) return false;
  return true;
}

}  // namespace aloft
