#pragma once
// Stepping a mobile in time: constraint dynamics with Baraff's linear-time tree factorization.
//
// One step (fixed h, default 1 ms), top to bottom in Simulation::step(); the pose's factorization is
// carried over from the previous step:
//   1. applied forces     gravity, external loads (wind), air damping, implicit-midpoint gyroscopic torque
//   2. predict            unconstrained velocities, warm-started with the last step's joint impulses
//   3. joint impulses     SHAKE: Newton iterations on the joint impulses until the *new* positions
//                         satisfy every joint (|C| < 1e-9 m), each iteration one O(n) tree solve
//   4. factor             children-first block LDL^T of the joint KKT matrix at the new pose, O(n)
//   5. velocity projection  RATTLE: velocities projected (mass-weighted) onto the joints' tangent space
//   6. check              stop with a report if any component's state is not finite
// Collisions enter between 2 and 3: the contacts found at the current pose (speculatively: pairs that
// could close their gap within the step) receive impulses solved together with the joints, with
// restitution and Coulomb friction, before the drift (dynamics/contact_response.hpp).
// Where the joint impulses do not converge (a thin wire spinning fast), the step is halved, recursively.
// Steps 2-5 are the constrained symplectic Euler method (Hairer, Lubich & Wanner, Geometric Numerical
// Integration, VII.1): first order, symplectic for the translational part, so energy does not drift.

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "aloft/collision.hpp"
#include "aloft/contact_law_record.hpp"
#include "aloft/state.hpp"

namespace aloft {

// Why a simulation stopped: the first component whose state became non-finite, and when.
struct SimulationFailure {
  int component = -1;
  std::string component_name;
  double time = 0;        // s
  std::string message;    // full, user-facing
};

// Forces applied from outside (wind, a user's pull) for the next steps, per component, world frame.
struct ExternalLoads {
  std::vector<Vec3> force;    // N, through the centre of mass
  std::vector<Vec3> torque;   // N m, about the centre of mass
  void resize(int count);
  void clear();
};

// The benchmarks' breeze, which sets a mobile knocking as a room's draught would (`aloft bench`'s
// default start, aloft_step_profile's "breeze", and the tests that need a generated mobile's pieces to
// touch): a horizontal push of 0.2 g (0.2 * 9.81 m/s^2 times each component's mass, N) on every moving
// component, its direction turning by the golden angle from one component to the next. Sets `loads`'s
// forces (sized to the model; torques untouched); they act until the caller clears them.
void set_breeze(const Model& model, ExternalLoads& loads);

// Running totals of the collision response since the simulation started.
struct CollisionStatistics {
  long long steps_with_contacts = 0;  // (sub)steps in which the detector reported contacts
  long long impulses = 0;             // contact impulses applied (one per active contact per step)
  long long sliding = 0;              // of those, sliding on the friction cone's edge
  long long restitution_dropped = 0;  // steps where bouncing would have added energy (solved with e = 0)
  long long friction_dropped_in_part = 0;  // steps where the law with friction did not converge, and was
                                          // solved again without the friction of the contacts that kept
                                          // changing only (the others kept theirs)
  long long friction_dropped = 0;     // steps where the law with friction did not converge or even that
                                      // gained (nearly dependent contacts): solved without friction, or
                                      // without impulse
  // The contact law's work: its solves (one per resolve with contacts to solve: a (sub)step resolves once,
  // and again, up to 4 solves in all, while the look after the impulses finds other contacts or they
  // close a contact left out), the contacts they were for (each solve's m: its sweeps cost O(m^2) and its
  // collision matrix O(m^2) path sums) and their Gauss-Seidel sweeps. And the closing
  // contacts beyond ContactResponse::kMaxContacts that a step left unsolved (the latest to close; the
  // next step looks at them again).
  long long law_solves = 0, law_contacts = 0, law_sweeps = 0;
  long long contacts_left = 0;
  // J: the energy the contact impulses took out of the mobile, summed over the steps, each step's
  // weighed at its start velocities (ContactStepReport::energy_change; a step that only holds pieces at
  // rest adds about 0, of either sign). Without air damping, the energy the mobile lost is this, less
  // what the overlap pushes lift and the integrator's own error (docs/collisions.md, "Energy").
  double energy_removed = 0;
  double deepest = 0;                 // m, largest overlap seen at the start of a step
  // The largest overlap seen at the start of a step as a fraction of the smallest half-width of its
  // pair's pieces near the contact (Contact::thinnest: a wire's radius, half a plate's thickness). At 1
  // a piece would be reached to its middle, where the narrow phase could read the overlap from the far
  // side and the push drive it through; the step's checks keep it well below (contact_checks.cpp).
  double deepest_relative = 0;
};

// Running totals of how the (sub)steps were taken since the simulation started: what they cost and why
// some were rejected, for profiling (aloft_step_profile prints them per step). A rejected (sub)step counts
// once, under the check that rejected it; the Newton corrections (one tree solve each) are counted by
// the phase of the step they closed the joints in. Simulation::rejected_substeps() is attempts - accepted,
// and Simulation::joint_iterations() the sum of the three corrections' counts.
struct StepStatistics {
  long long attempts = 0;  // (sub)steps tried
  long long accepted = 0;  // of those, taken
  long long kicks_retried = 0;  // half kicks rejected and tried again without the guessed joint impulses
  // Rejections: the step-size rule on the half-kicked velocities, before or after the contact impulses
  // (step_size_rule.hpp; the three below count which of its measures were over their limits, so they may
  // add up to more) ...
  long long rejected_spin = 0;
  long long spin_turn_over = 0, spin_anchor_over = 0, spin_drift_over = 0;
  long long rejected_contact_turn = 0;    // ... a pair in contact turning too fast, before the drift ...
  long long rejected_joints = 0;          // ... the joints' Newton iteration giving up ...
  long long rejected_contact_motion = 0;  // ... and the pieces in contact moving too far in the drift.
  // Newton corrections closing the joints after the step's first drift, after a contact pass, and under
  // the overlap push (of the pseudo-velocity).
  long long joint_corrections = 0, contact_pass_corrections = 0, push_corrections = 0;
  // Of all those corrections, the sparse ones (after a pass that left few joints open: only the bodies
  // they move are visited), and the bodies they visited in all.
  long long sparse_corrections = 0, sparse_bodies = 0;
  long long contact_passes = 0;  // contacts solved again after the joints' impulses made them approach
  // Of those, the sparse ones (only the bodies their impulses move are drifted again), and the bodies
  // they drifted in all.
  long long sparse_contact_passes = 0, sparse_contact_pass_bodies = 0;
  long long pushes = 0;          // (sub)steps that pushed overlapping pieces apart
};

struct StepWorkspace;  // solver factorization and scratch (dynamics/step_workspace.hpp)
struct ContactStepReport;  // what the contact stage did in one step (dynamics/contact_response.hpp)

class Simulation {
 public:
  explicit Simulation(const Model& model);          // starts from the designed pose at rest
  Simulation(const Model& model, State initial);
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // Advance by one step of timestep() seconds. Returns false (and failure() tells why) when the state
  // became non-finite; the state is then left as it was before the step.
  bool step();

  // Advance by whole steps covering `duration` seconds. Returns false on failure.
  bool advance(double duration);

  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  // Change the state from outside (reset, a user's drag): the next step re-factors at the new pose.
  State& mutable_state();
  // The loads applied from outside for the next steps. From the first call on, every step reads them;
  // a simulation whose loads() was never asked for has none, and its steps skip reading them (two
  // vectors per component, read twice per step).
  ExternalLoads& loads() {
    loads_in_use_ = true;
    return loads_;
  }

  double timestep() const { return timestep_; }
  void set_timestep(double seconds);

  // How closely (m, per coordinate) a (sub)step of h seconds closes every joint before it is accepted.
  // By default it falls with h^2, as the method's own error does: 1e-7 m at 1 ms, 1e-9 m (the floor) at
  // 0.1 ms and below; simulation.cpp (kJointToleranceRate) says why. set_joint_tolerance(metres) fixes
  // it for every h instead (for studies of its effect); 0 restores the default.
  double joint_tolerance(double h) const;
  void set_joint_tolerance(double metres) { fixed_joint_tolerance_ = metres; }
  // Whether a Newton correction that follows a pass leaving few joints open solves for those joints
  // alone and visits only the bodies it moves, and a contact pass after such a pass drifts again only
  // the bodies its impulses move (on by default; dynamics/step_workspace.hpp, kSparseRowsPer, and
  // dynamics/drift_passes.cpp). Off, every correction and contact pass is a full solve and drift: for
  // tests and measurements. Mobiles of fewer than 64 bodies, or whose bodies are not in depth-first
  // order, always take full ones.
  void set_sparse_corrections(bool on);

  // Air damping rates (1/s); default from the model.
  void set_damping(const DampingSpec& damping) { damping_ = damping; }

  // Collisions: on when the model's contact settings say so; contacts() are those of the last step.
  void set_collisions(bool enabled);
  bool collisions() const { return collisions_; }
  const std::vector<Contact>& contacts() const;
  // The pairs of components (a < b) that a contact impulse pushed apart in the last step (in any of its
  // accepted substeps; a pair may appear more than once). A knock is often stopped and turned back
  // before its pieces meet (the speculative contacts of docs/collisions.md), so it may show in no
  // contact's distance at a step's start: this is where to see it.
  const std::vector<std::pair<int, int>>& pushed_pairs() const;
  const CollisionStatistics& collision_statistics() const { return collision_stats_; }
  // Hands every solve of the contact law the steps make (the rejected tries' too) to `recorder`, or to
  // none when it is empty: for measuring the law on fixed inputs (aloft/contact_law_record.hpp).
  void record_contact_laws(ContactLawRecorder recorder);
  // The detector (for its pair pruning), or null when collisions are off.
  const CollisionDetector* collision_detector() const;

  const std::optional<SimulationFailure>& failure() const { return failure_; }
  long long step_count() const { return steps_; }
  // How many times a step had to be halved because the motion was too fast for it.
  long long subdivisions() const;
  // How many (sub)steps were tried and rejected as too long for the motion, each at the cost of a kick
  // (and, with collisions on, a detection). A step starts at the subdivision the last one needed, so
  // this stays well below subdivisions() while the motion stays fast.
  long long rejected_substeps() const;
  // How many Newton corrections (one tree solve each) the joint impulses needed, over all steps; a step
  // costs this plus one solve for the velocity projection.
  long long joint_iterations() const;
  // The same, and more, in detail: see StepStatistics.
  const StepStatistics& step_statistics() const;

 private:
  bool rattle(double h);
  bool contacts_turn_slowly_enough(double h, const std::vector<Vec3>& angular) const;
  bool contacts_move_slowly_enough(double h, bool pushed) const;
  bool advance_by(double h, int depth);
  // rattle()'s drift (dynamics/drift_passes.cpp): a plain pass, and a Newton correction of the half-step
  // velocities or of the pseudo-velocities followed by a pass.
  enum class DriftCorrection { kVelocity, kPseudo };
  double drift_pass(double h, bool first_of_step, bool with_pseudo);
  double correct_and_drift(double h, DriftCorrection correction, bool with_pseudo);
  double contact_pass_drift(double h);
  bool push_apart(double h);
  bool kick_and_collide(double h, bool guess, ContactStepReport& contact_report, bool& has_pseudo);
  bool at_finest_step(double h) const;
  bool reject_spin(double h);
  Eigen::Matrix<double, 6, 1> applied_wrench(const State& state, int i, const Vec3& momentum) const;
  bool damped() const { return damping_.linear != 0 || damping_.angular != 0; }

  const Model& model_;
  State state_;
  ExternalLoads loads_;
  bool loads_in_use_ = false;  // loads() was asked for: the loads may be non-zero
  double timestep_;
  double fixed_joint_tolerance_ = 0;  // m; 0: the default rule
  DampingSpec damping_;
  bool collisions_ = false;
  CollisionStatistics collision_stats_;
  std::optional<SimulationFailure> failure_;
  long long steps_ = 0;
  std::unique_ptr<StepWorkspace> work_;  // sized once; step() never allocates
};

}  // namespace aloft
