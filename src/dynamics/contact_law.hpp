#pragma once
// The contact law at velocity level: given the collision matrix K of m contacts and their relative
// velocities u before the impulse, find impulses P such that, with u' = u + K P,
//   normal:   u'_n >= target_n,  P_n >= 0,  P_n (u'_n - target_n) = 0   (no pull, no overlap)
//   friction: sticking  u'_t = 0 with |P_t| <= mu P_n,
//             or sliding P_t = -mu P_n s on the edge of the Coulomb cone against the slip s = u'_t / |u'_t|
//             the impulse leaves (so sliding starts, continuously, where sticking ends).
// Each contact is expressed in its own orthonormal basis (n, t1, t2): 3 rows per contact, normal first.
// K = G H^-1 G^T is the inverse effective mass seen at the contacts through the whole articulated tree
// (symmetric positive semi-definite, 3m x 3m); u and P are in the same contact bases.
//
// The solve is block Gauss-Seidel over the contacts. For one contact it is exact in one pass: Mirtich's
// prediction decides sticking or sliding from the 3x3 block K_kk before committing (the impulse that
// would stick is computed; if it lies outside the cone the contact slides, and the sliding impulse is
// solved for, one equation in the angle of its friction), so the system is solved once, not once per
// guess. Several simultaneous contacts are iterated until their impulses stop changing, with Newton's
// method on the slowest of them now and then, and again once every contact's mode has settled
// (contact_law.cpp, polish_law); a contact that keeps trading sticking for sliding loses its friction for
// the solve.

#include <Eigen/Dense>

#include <vector>

namespace aloft {

struct ContactLawRecord;  // aloft/contact_law_record.hpp

struct ContactLawRow {
  double target_normal = 0;  // m/s: the least normal relative velocity allowed after the impulse
  double friction = 0;       // Coulomb mu >= 0
};

struct ContactLawResult {
  int iterations = 0;     // block Gauss-Seidel sweeps used
  int sticking = 0;       // contacts that ended sticking (P_n > 0, inside the cone)
  int sliding = 0;        // contacts that ended on the cone's edge
  double energy_change = 0;  // J: u^T P + P^T K P / 2, the change of kinetic energy the impulses make
  // Gauss-Seidel with friction did not converge in its sweeps, not even with the contacts that kept
  // changing solved without friction: P is the frictionless normal law's solution instead (sticking and
  // sliding are then 0).
  bool friction_dropped = false;
  // The contacts solved without friction: those found cycling between sticking and sliding in the sweeps
  // (contact_law.cpp, kCyclingModeChanges), and those that kept changing when Gauss-Seidel with friction
  // did not converge (solved again without theirs, the others with theirs); or all m when friction_dropped.
  int frictionless_contacts = 0;
};

// Solves for P (resized to 3m). K must be 3m x 3m, u 3m. `start` (3m, or null for zero; not P itself)
// is where Gauss-Seidel starts: a guess of P, such as the impulses the same contacts took in the last
// step, each inside its cone. The law P meets does not depend on it, only the sweeps it takes and, where
// the law has more than one solution (contacts whose rows depend on each other), which one it ends at.
ContactLawResult solve_contact_law(const Eigen::MatrixXd& K, const Eigen::VectorXd& u,
                                   const std::vector<ContactLawRow>& rows, Eigen::VectorXd& P,
                                   const Eigen::VectorXd* start = nullptr);

// The same for a solve recorded from a simulation (Simulation::record_contact_laws), from its start if it
// has one: the same law on the same machine gives its impulses again, bit for bit.
ContactLawResult solve_contact_law(const ContactLawRecord& record, Eigen::VectorXd& P);

// Normal-only variant (frictionless), used for the position correction: K_nn is m x m.
void solve_normal_law(const Eigen::MatrixXd& K_nn, const Eigen::VectorXd& u_n, const Eigen::VectorXd& target,
                      Eigen::VectorXd& P_n);

// The same on the whole 3m x 3m K (normal rows first in each contact's basis): P (resized to 3m) has the
// normal law's impulses in the normal rows and no friction. u_n and target are per contact (m).
void solve_frictionless_law(const Eigen::MatrixXd& K, const Eigen::VectorXd& u_n, const Eigen::VectorXd& target,
                            Eigen::VectorXd& P);

// The change of kinetic energy (J) impulses P make on a system whose contact velocities are u and
// collision matrix K: u^T P + P^T K P / 2 (exact for any mechanical system whose velocities satisfy its
// joints before the impulse).
double contact_energy_change(const Eigen::MatrixXd& K, const Eigen::VectorXd& u, const Eigen::VectorXd& P);

}  // namespace aloft
