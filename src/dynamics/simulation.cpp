#include "aloft/simulation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "common/cpu_dispatch.hpp"
#include "dynamics/step_workspace.hpp"

namespace aloft {

void ExternalLoads::resize(int count) {
  force.assign(count, Vec3::Zero());
  torque.assign(count, Vec3::Zero());
}

void ExternalLoads::clear() {
  std::fill(force.begin(), force.end(), Vec3::Zero());
  std::fill(torque.begin(), torque.end(), Vec3::Zero());
}

void set_breeze(const Model& model, ExternalLoads& loads) {
  if (static_cast<int>(loads.force.size()) != model.count) loads.resize(model.count);
  for (int i = 1; i < model.count; ++i) {
    const double a = 2.399963 * i;  // rad, the golden angle: directions spread round the circle
    loads.force[i] = 0.2 * 9.81 * model.mass[i] * Vec3(std::cos(a), 0, std::sin(a));
  }
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
// A step whose joint impulses do not converge is split in two, recursively, at most this deep.
constexpr int kMaxSubdivision = 8;
// A step starts at the subdivision depth the last step needed (see advance_by); after this many steps
// in a row that needed no more, the next one tries once more at half that depth.
constexpr int kStepsBeforeCoarser = 4;
// Contacts re-checked after the joints' impulses: at most this many corrections per step, each when a
// contact approaches faster than this (m/s; 1e-6 m/s closes 1 nm per step).
constexpr int kMaxContactPasses = 2;
constexpr double kContactVelocityTolerance = 1e-6;
// A half kick that changes a body's turn per step by more than this (rad) is suspected of a wrong guess of
// the joint impulses (see rattle): the forces of a mobile, gravity and the joints' reactions to it, change
// it by (h^2 / 2) times the angular acceleration, 1e-5 to 1e-3 rad at h = 1 ms. (A knock may exceed it;
// then the retry without the guess costs one more kick and detection.)
constexpr double kSuspiciousKick = 0.01;


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

void Simulation::record_contact_laws(ContactLawRecorder recorder) { work_->response.record_laws(std::move(recorder)); }

void Simulation::set_sparse_corrections(bool on) { work_->most_open = on ? work_->sparse_open : 0; }

const std::vector<Contact>& Simulation::contacts() const { return work_->contacts; }

const std::vector<std::pair<int, int>>& Simulation::pushed_pairs() const { return work_->pushed_pairs; }

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
  if (collisions_) work.response.step_taken();  // what its contacts pressed, and their impulses, for the next steps
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
    stats.energy_removed -= contact_report.energy_change;
    stats.deepest = std::max(stats.deepest, contact_report.deepest);
    stats.deepest_relative = std::max(stats.deepest_relative, contact_report.deepest_relative);
    if (contact_report.active > 0)
      for (const ContactResponse::PressedPair& pushed : work.response.pressed_last_step())
        work.pushed_pairs.emplace_back(pushed.a, pushed.b);
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
  work_->pushed_pairs.clear();
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
