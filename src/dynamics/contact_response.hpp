#pragma once
// Collision response solved together with the joints (method notes section 5; Moore & Wilhelms 1988,
// Mirtich 1996), in time linear in the number of components.
//
// At a collision the velocities jump. The unknowns are the new velocities of every moving component,
// the contact impulses P and the joint impulses; the equations are momentum for every component, the
// joints' velocity constraints, and the contact law. That is the velocity-level tree system of section
// 3 with the contact rows as auxiliary rows. Its Schur complement on the contact rows is the collision
// matrix K = G H^-1 G^T (3 rows per contact). It is built from the tree factorization's path-sparse
// columns (TreeSolver::eliminate_on_paths): a unit impulse at a contact touches only the nodes on the
// paths from its two bodies to the base, so K costs O(m^2 depth) for m contacts, not m full solves. The contact law (dynamics/contact_law.hpp) then gives P, and
// one more tree solve with G^T P gives every component's velocity change and the joint impulses — so
// one knock moves the whole chain the way a real mobile does.
//
// Contacts are speculative (the detector reports pairs closer than the distance they can close in one
// step). Per contact, with d the signed gap and u_n the normal approach velocity:
//   * colliding within this step, faster than the bounce threshold (and, for a pair stopped in one of the
//     last two steps, faster than twice the speed it was stopped from: start_step): u_n' >= -e u_n;
//   * otherwise: u_n' >= -max(d, 0) / h, the contact may close its gap but not pass it.
// Penetration (d < 0, from round-off or a resting contact settling) is pushed out by a separate
// frictionless "pseudo-velocity" that moves positions in this step's drift only and is then forgotten
// (split impulse), so correcting it adds no kinetic energy.
// If the Newton restitution targets would add kinetic energy (possible with sticking friction and
// several contacts), the step's impulses are recomputed with e = 0, which only removes energy. If even
// that gains (the friction law's Gauss-Seidel need not converge on nearly dependent contacts), they are
// recomputed without friction, and dropped for this step if that gains too.

#include <cstdint>
#include <utility>
#include <vector>

#include "aloft/collision.hpp"
#include "aloft/contact_law_record.hpp"
#include "dynamics/contact_law.hpp"
#include "dynamics/tree_solver.hpp"

namespace aloft {

struct ContactTuning {
  // Normal approach speeds (m/s) below this are not bounced: a resting contact under gravity approaches
  // at about g h per step, and bouncing it would make it chatter. Raised to 2 g h at run time. (A pair
  // pressed harder than gravity presses it is held by ContactResponse::start_step's rule.)
  double bounce_threshold = 0.005;
  double penetration_slop = 5e-5;  // m: overlap tolerated without correction (round-off, settling)
  double penetration_rate = 0.8;   // fraction of the overlap beyond the slop removed per step
  // m: the most a step's overlap correction may move a contact apart. The pseudo-velocity respects
  // the joints only to first order; SHAKE closes the second-order rest with real impulses, which
  // could add energy if a deep overlap were pushed out in one step.
  double max_push = 1e-3;
};

// What the last resolve did (for statistics, the viewer and tests).
struct ContactStepReport {
  int contacts = 0;            // speculative contacts reported by the detector
  int dropped = 0;             // closing contacts beyond kMaxContacts, left to the next step
  int solves = 0;              // contact-law problems: one per resolve() with contacts to solve (solved
                               // again without bounce when that would add energy; `iterations` has both)
  int solved = 0;              // contacts those solves were for (the collision matrix is 3 solved square)
  int reused = 0;              // of those, contacts whose columns of the collision matrix came from the
                               // resolve before at the same factorization (the same contact found again)
  int active = 0;              // contacts that received an impulse
  int sticking = 0;
  int sliding = 0;
  int iterations = 0;          // Gauss-Seidel sweeps of the contact law (both solves' when the bounce
                               // was dropped and the law solved again)
  bool restitution_dropped = false;  // Newton restitution would have added energy: solved with e = 0
  int frictionless = 0;              // contacts solved without friction: those whose impulses kept changing
                                     // where the law with friction did not converge (the others kept
                                     // theirs: ContactLawResult::frictionless_contacts), or all of them
                                     // when friction_dropped
  bool friction_dropped = false;     // the law with friction did not converge, or added energy (nearly
                                     // dependent contacts): solved frictionless, or with no impulse if
                                     // that gained too
  // J: what the impulses change the mobile's energy by over the step, weighed at the step's start
  // velocities (plus this step's earlier contact impulses), not at the half-kicked ones they act on
  // (resolve() says why). Usually < 0; a step that only holds pieces at rest gives about 0, of either sign.
  double energy_change = 0;
  double deepest = 0;          // m, largest overlap among the contacts (>= 0)
  double deepest_relative = 0; // the largest overlap over its contact's Contact::thinnest (>= 0)
};

class ContactResponse {
 public:
  explicit ContactResponse(const Model& model);

  // Resolve `contacts` (detected at `pose`, the pose `solver` is factored at) against the velocities
  // `velocity`/`angular` (world, changed in place). The joint impulses the contact impulses cause are
  // not added to the step's joint impulses used for the next step's warm start (contacts are re-solved
  // every step), so they are not kept. `pseudo` (per body: linear m/s, angular rad/s) is
  // set to the penetration-removing pseudo-velocity; `has_pseudo` says whether it is non-zero.
  // `pose` also holds the velocities the step started from, before its first half kick; `again` says
  // that this is a later resolve of the step, after the earlier ones' impulses were added to `velocity`.
  // Both are for the report's energy_change: the energy the impulses change is weighed at the step's start
  // velocities (plus the earlier resolves' changes when `again`), not at `velocity`. The split kick makes the
  // difference: a piece resting on another gains (h/2) g of downward speed in the first half kick, the
  // impulse stops that and the second half kick starts the fall again, so the piece keeps its energy from
  // step to step, yet at the half-kicked velocity the impulse takes m (g h)^2 / 2 out of it. For constant
  // forces (two equal half kicks) and leaving the joints' own impulses aside, the energy over the step
  // changes by exactly dv^T M v_start + dv^T M dv / 2.
  ContactStepReport resolve(const State& pose, TreeSolver& solver, const std::vector<Contact>& contacts, double h,
                            std::vector<Vec3>& velocity, std::vector<Vec3>& angular, std::vector<Vec6>& pseudo,
                            bool& has_pseudo, bool again = false);

  // Whether, at the velocities `velocity`/`angular` (world), some contact of `found` (the list the last
  // resolve() was given, at the same `pose` and `h`) that resolve() left out as neither touching nor
  // closing now closes within two steps: the impulses of the others knocked one of its components
  // towards the other. Such a contact must be solved with the rest (Simulation::kick_and_collide resolves
  // again): left out, nothing would stop it within the step.
  bool closes_left_out(const State& pose, const std::vector<Contact>& found, double h,
                       const std::vector<Vec3>& velocity, const std::vector<Vec3>& angular) const;

  // After the joints' impulses changed the velocities (SHAKE), make the contacts kept by the last
  // resolve() hold again: the same collision matrix, targets without restitution (the bounce was
  // given), the extra impulses applied to `velocity`/`angular`. Returns whether any impulse was needed
  // beyond `tolerance` (m/s of normal velocity).
  bool correct(double h, std::vector<Vec3>& velocity, std::vector<Vec3>& angular, double tolerance);
  // correct() in two parts, for a caller that applies the impulses itself: solve_correction() solves the
  // law for them (returns correct()'s answer; the velocities are not changed), then either
  // apply_correction() adds them to every body, as correct() does, or respond_visiting() hands each body
  // the solver reaches its velocity change (TreeSolver::solve_sparse_visiting: the joints `also` are
  // visited whatever skip says; a body it passes over keeps its velocity, u = 0 taken for its subtree).
  bool solve_correction(double h, const std::vector<Vec3>& velocity, const std::vector<Vec3>& angular,
                        double tolerance);
  void apply_correction(std::vector<Vec3>& velocity, std::vector<Vec3>& angular);
  template <class Skip, class Visit, class Boundary>
  void respond_visiting(const std::vector<int>& also, Skip&& skip, Visit&& visit, Boundary&& boundary) {
    gather_wrenches(kept_, P_);
    solver_->solve_sparse_visiting(wrench_, touched_, also, skip, visit, boundary);
    clear_wrenches(kept_);
  }

  // The most contacts solved in one step (the collision matrix is 3m x 3m; the contact law's sweeps cost
  // O(m^2) each).
  static constexpr int kMaxContacts = 128;
  // The contacts the last resolve() solved, in the order of the matrices below.
  const std::vector<Contact>& kept() const { return kept_; }
  // A pair of components (a < b) given a normal impulse, and the fastest it approached (m/s, >= 0) where
  // it was stopped.
  struct PressedPair {
    int a = 0, b = 0;
    double approach = 0;
  };
  // The pairs given a normal impulse by the resolves of the last step taken (the first, and the later
  // ones, `again`; the contact passes' corrections are not included), one per pair, sorted by (a, b).
  // Set by step_taken().
  const std::vector<PressedPair>& pressed_last_step() const { return pressed_last_; }

  // A contact pressed by a steady force does not bounce. Between two steps that stop it, a pair pressed
  // together approaches by a h (a its relative acceleration without the contact); where a exceeds the 2 g
  // the bounce threshold allows for (the joints of a tangle pressing a light piece on another, a strong
  // wind pressing a plate on a wire), each stop bounced it, and the next step or the one after brought it
  // back: it chattered, pushed every other step (generated-1023 swinging, seed 7: 13,234 of 78,906
  // impulses were of a pair pushed two steps before and not in the step between). A bounce that the
  // pressing brings back within two steps cannot be followed at this step length anyway. So a pair
  // stopped in one of the last two steps taken bounces only when it approaches faster than twice the
  // speed it was last stopped from (faster than two steps of its pressing build: another piece knocked
  // it). start_step() begins a step's attempt (forgetting what an attempt that was not taken pressed);
  // step_taken() says that the attempt since is taken, so its pairs become the last step's.
  //
  // The law of a step's first resolve starts from the impulses its contacts took in the first resolve of
  // the last step taken (each contact of a pair from the one of the same pair nearest to it, within
  // kCarriedReach), scaled by the ratio of the step lengths: a pair pressed together is stopped by about
  // the same impulse every step. (Until pairs pressed together stopped chattering, the impulses did not
  // carry over: docs/performance.md, "2026-12-06, fifth session".)
  void start_step();
  void step_taken();

  ContactTuning tuning;

  // Hands every solve of the contact law (resolve's and solve_correction's) to `recorder` as it is made,
  // or to none when it is empty (aloft/contact_law_record.hpp). Recording copies the solve's matrices.
  void record_laws(ContactLawRecorder recorder) { recorder_ = std::move(recorder); }

  // The collision matrix and pre-impulse contact velocities of the last resolve (contact bases), for
  // tests.
  const Eigen::MatrixXd& collision_matrix() const { return K_; }
  const Eigen::VectorXd& contact_velocity() const { return u_; }
  const Eigen::VectorXd& impulses() const { return P_; }
  // Orthonormal basis (n, t1, t2) of contact k, as matrix columns.
  const Mat3& basis(int k) const { return basis_[k]; }

 private:
  // Contact c's gap after two steps of h at its normal approach speed (resolve's test of what to keep).
  static double gap_after_two_steps_of(const Contact& c, const State& pose, double h,
                                       const std::vector<Vec3>& velocity, const std::vector<Vec3>& angular);
  // Tree-solve the response to contact impulses `P` (contact bases, 3 per contact) into du_.
  void respond(const std::vector<Contact>& contacts, const Eigen::VectorXd& P);
  // The impulses `P` as wrenches on the contacts' bodies (wrench_, listed in touched_), and back to zero.
  void gather_wrenches(const std::vector<Contact>& contacts, const Eigen::VectorXd& P);
  void clear_wrenches(const std::vector<Contact>& contacts);
  // solve_contact_law on K_, u_ and rows_ into P_ from `start` (null: from zero), recorded when asked.
  ContactLawResult solve_law(const Eigen::VectorXd* start);

  const Model& model_;
  TreeSolver* solver_ = nullptr;  // the one passed to resolve(), factored at its pose
  std::vector<Contact> kept_;     // the contacts solved: touching, overlapping or closing
  std::vector<std::pair<double, int>> closing_;  // their gap after two steps (m) and index
  std::vector<char> left_out_;  // per contact of the last resolve's `found`: neither touching nor closing
  std::vector<Mat3> basis_;
  std::vector<Vec3> arm_a_, arm_b_;  // centre of mass of a (b) -> contact point, world, m
  std::vector<ContactLawRow> rows_;
  std::vector<PathColumns> columns_;  // per contact, reused (no allocation once grown)
  std::vector<int> path_position_;    // per body: its index in one contact's columns_.node, or -1
  Eigen::MatrixXd K_;
  // The last resolve's contacts, lever arms, path columns and K, and the solver and its factorization they
  // were computed with (TreeSolver::factorizations): a contact of the next resolve identical to one of them
  // (same components, point, normal and arms) at the same factorization of the same solver has the same
  // columns, and two such the same block of K. The look after a step's impulses finds most of the same
  // contacts again.
  std::vector<Contact> last_contacts_;
  std::vector<Vec3> last_arm_a_, last_arm_b_;
  std::vector<PathColumns> last_columns_;
  Eigen::MatrixXd last_K_;
  const TreeSolver* last_solver_ = nullptr;
  std::uint64_t last_factorization_ = 0;
  bool have_last_ = false;
  std::vector<int> same_as_last_;  // per contact of this resolve: its index in the last one's, or -1
  Eigen::VectorXd u_, P_;
  std::vector<Vec6> wrench_;   // per body, zero between uses
  std::vector<int> touched_;   // the bodies wrench_ is non-zero at (each contact's two)
  std::vector<Vec6> du_;
  // The velocity change (per body: linear m/s, angular rad/s) of this step's resolves so far, which
  // weighs a later one's energy change (resolve(), `again`); valid when has_earlier_change_.
  std::vector<Vec6> earlier_change_;
  bool has_earlier_change_ = false;
  // The fastest approach (m/s) the pair (a, b) was stopped from in the last two steps taken, or -1 when
  // it was not stopped in them.
  double pressed_recently(int a, int b) const;
  std::vector<PressedPair> pressing_;        // by this step's resolves so far (unsorted, repeats)
  std::vector<PressedPair> pressed_last_;    // by the last step taken: sorted by (a, b), one per pair
  std::vector<PressedPair> pressed_before_;  // by the step taken before it, the same way

  // m: the farthest a contact's point may be from the last step's contact of the same pair whose impulse
  // it starts from. A contact held from step to step moves by its pieces' relative motion in a step, under
  // a millimetre below 1 m/s at 1 ms steps (a faster one starts from zero, as every contact did before);
  // another contact of the same pair is usually farther.
  static constexpr double kCarriedReach = 1e-3;
  // A contact's impulse in a step's first resolve, for the next step's law to start from.
  struct CarriedImpulse {
    int a = 0, b = 0;
    Vec3 point = Vec3::Zero();    // world, m: the contact's point at the step's start pose
    Vec3 impulse = Vec3::Zero();  // world, N s: on a, from b
  };
  // Fills start_ for the contacts of the step's first resolve from carried_ (sorted by (a, b), as the
  // contacts are); false when none has a carried impulse.
  bool start_from_carried(const std::vector<Contact>& contacts, double h);
  std::vector<CarriedImpulse> carrying_;  // this step's first resolve's, sorted by (a, b)
  std::vector<CarriedImpulse> carried_;   // the last step taken's
  double carrying_step_ = 0, carried_step_ = 0;  // s: their step lengths (0 while there are none)
  Eigen::VectorXd start_;                         // where the step's first law solve starts
  ContactLawRecorder recorder_;  // empty: the solves are not recorded
  ContactLawRecord record_;      // the one handed to recorder_ (its storage reused)
};

}  // namespace aloft
