// Contact impulses solved together with the joints: against a dense solve of Moore & Wilhelms' system
// (momentum, joint velocity constraints and the contact law as one linear system), and energy/cone
// bounds on random trees.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdlib>
#include <random>

#include "dynamics/contact_response.hpp"
#include "dynamics/tree_solver.hpp"
#include "support/model_builder.hpp"

namespace aloft {
namespace {

// A chain of `count - 1` random bodies hanging from a nail on component 0.
Model random_chain(int count, unsigned seed) {
  std::srand(seed);
  Model m = test::random_tree(count, seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int i = 1; i < count; ++i) {
    m.parent[i] = i - 1;
    m.joint_world[i] = m.rest_position[i - 1] + Vec3(u(rng), u(rng), u(rng));
    m.rest_position[i] = m.joint_world[i] + Vec3(u(rng), -0.3, u(rng));
  }
  test::finish_model(m);
  return m;
}

// Random velocities that satisfy every joint: a random momentum projected through the tree solve.
void random_consistent_velocities(const Model& model, TreeSolver& solver, unsigned seed, State& state) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::vector<Vec6> f(model.count, Vec6::Zero()), u(model.count, Vec6::Zero());
  std::vector<Vec3> c(model.count, Vec3::Zero());
  for (int i = 1; i < model.count; ++i)
    for (int k = 0; k < 6; ++k) f[i](k) = g(rng);
  solver.solve(f, c, u);
  for (int i = 1; i < model.count; ++i) {
    state.velocity[i] = u[i].head<3>();
    state.angular[i] = u[i].tail<3>();
  }
}

// How fast joint i's two sides move apart (m/s): the velocity of its point on the child minus that on
// the parent, with `pose`'s orientations and `moving`'s velocities (a solve's result).
double joint_opening_speed(const Model& model, const State& pose, const State& moving, int i) {
  const int p = model.parent[i];
  const Vec3 r = pose.orientation[i] * model.joint_in_child[i];
  const Vec3 s = pose.orientation[p] * model.joint_in_parent[i];
  const Vec3 vp = p == 0 ? Vec3::Zero() : Vec3(moving.velocity[p] + moving.angular[p].cross(s));
  return (moving.velocity[i] + moving.angular[i].cross(r) - vp).norm();
}

// A contact on body b (against a, possibly the fixed component 0) at a point near b, with a normal chosen
// so that the two approach.
Contact approaching_contact(const State& state, int a, int b, const Vec3& offset, const Vec3& direction) {
  Contact c;
  c.a = a;
  c.b = b;
  c.point = state.position[b] + offset;
  c.normal = direction.normalized();
  c.distance = 0;
  auto point_velocity = [&](int i) {
    return i == 0 ? Vec3::Zero() : Vec3(state.velocity[i] + state.angular[i].cross(c.point - state.position[i]));
  };
  if (c.normal.dot(point_velocity(a) - point_velocity(b)) > 0) c.normal = -c.normal;
  return c;
}

// Moore's system, densely: unknowns [u'; -lambda; -P] with
//   M u' + J^T(-lambda) + G^T(-P) = M u,    J u' = 0,    G u' = target,
// G the rows of the contact law: sticking (normal and both tangents, rows = 3) or frictionless (the
// normal only, rows = 1).
void dense_moore(const Model& model, const State& state, const Contact& c, const Mat3& basis, int rows,
                 const Eigen::Vector3d& target, Eigen::VectorXd& u_after, Eigen::Vector3d& P) {
  const int m = model.count - 1;
  const Eigen::MatrixXd H = dense_kkt_matrix(model, state);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(9 * m + rows, 9 * m + rows);
  A.topLeftCorner(9 * m, 9 * m) = H;
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(rows, 9 * m);
  auto add_body = [&](int body, double sign) {
    if (body == 0) return;
    Eigen::Matrix<double, 3, 6> row;
    row << Mat3::Identity(), -skew(c.point - state.position[body]);
    G.block(0, 6 * (body - 1), rows, 6) += sign * (basis.transpose() * row).topRows(rows);
  };
  add_body(c.a, +1);
  add_body(c.b, -1);
  A.block(9 * m, 0, rows, 9 * m) = G;
  A.block(0, 9 * m, 9 * m, rows) = G.transpose();
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(9 * m + rows);
  for (int i = 1; i < model.count; ++i) {
    rhs.segment<3>(6 * (i - 1)) = H.block<3, 3>(6 * (i - 1), 6 * (i - 1)) * state.velocity[i];
    rhs.segment<3>(6 * (i - 1) + 3) = H.block<3, 3>(6 * (i - 1) + 3, 6 * (i - 1) + 3) * state.angular[i];
  }
  rhs.tail(rows) = target.head(rows);
  const Eigen::VectorXd x = A.fullPivLu().solve(rhs);
  u_after = x.head(6 * m);
  P.setZero();
  P.head(rows) = -x.tail(rows);
}

// Returns false (nothing compared) when the law's answer is not the sticking one Moore's linear system
// describes: in an articulated chain, stopping the slip can need a pull (P_n < 0), and then the contact
// slides. friction = 0 compares the frictionless law.
bool check_chain_against_moore(int count, unsigned seed, int a, double restitution, double friction) {
  Model model = random_chain(count, seed);
  model.restitution.assign(count, restitution);
  model.friction.assign(count, friction);
  State state = rest_state(model);
  TreeSolver solver(model);
  solver.factor(state);
  random_consistent_velocities(model, solver, seed + 7, state);
  const int b = count - 1;
  const Contact contact = approaching_contact(state, a, b, Vec3(0.05, -0.1, 0.02), Vec3(0.3, 1, -0.2));

  ContactResponse response(model);
  response.tuning.bounce_threshold = 0;  // bounce at any speed: the test compares the law itself
  std::vector<Vec3> v = state.velocity, w = state.angular;
  std::vector<Vec6> pseudo(count, Vec6::Zero());
  bool has_pseudo = false;
  const double h = 1e-3;
  const ContactStepReport report = response.resolve(state, solver, {contact}, h, v, w, pseudo, has_pseudo);
  EXPECT_EQ(report.active, 1);
  if (friction > 0 && report.sticking != 1) return false;
  const double un = response.contact_velocity()[0];
  Eigen::VectorXd u_after;
  Eigen::Vector3d P;
  // Sticking with Newton's restitution can add energy in an articulated system (Kane's kind of paradox);
  // the response then solves with e = 0, and so must the reference.
  const double e = report.restitution_dropped ? 0.0 : restitution;
  dense_moore(model, state, contact, response.basis(0), friction > 0 ? 3 : 1, Eigen::Vector3d(-e * un, 0, 0),
              u_after, P);

  // Both solve the same linear system (one by tree elimination with the collision matrix, one densely
  // with full pivoting): agreement to 1e-9 relative, as for the joint solve alone.
  const Eigen::Vector3d ours = response.impulses().head<3>();
  EXPECT_LT((ours - P).norm(), 1e-9 * P.norm()) << "seed " << seed << " friction " << friction << ": ours " << ours.transpose() << ", dense "
      << P.transpose() << (report.restitution_dropped ? " (restitution dropped)" : "");
  double scale = 0, error = 0;
  for (int i = 1; i < count; ++i) {
    scale = std::max(scale, u_after.segment<6>(6 * (i - 1)).cwiseAbs().maxCoeff());
    error = std::max(error, (v[i] - u_after.segment<3>(6 * (i - 1))).cwiseAbs().maxCoeff());
    error = std::max(error, (w[i] - u_after.segment<3>(6 * (i - 1) + 3)).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(error, 1e-9 * scale);
  return true;
}

TEST(ContactResponse, ChainAgainstTheHookMatchesMooresDenseSystem) {
  int compared = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    compared += check_chain_against_moore(6, seed, 0, 0.5, 50.0);
    check_chain_against_moore(6, seed, 0, 0.5, 0.0);
  }
  EXPECT_GE(compared, 5);  // sticking happened often enough to be compared
}

TEST(ContactResponse, TwoLinksOfOneChainMatchMooresDenseSystem) {
  int compared = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    compared += check_chain_against_moore(8, seed, 2, 0.8, 50.0);
    check_chain_against_moore(8, seed, 2, 0.8, 0.0);
  }
  EXPECT_GE(compared, 3);
}

// A random 12-body tree at rest pose with random joint-consistent velocities, factored, and `count`
// simultaneous approaching contacts between random bodies (or against the hook). Restitution random in
// [0, 1) per tree if random_restitution, else 0; friction random in [0, friction_scale).
struct RandomContactCase {
  RandomContactCase(unsigned seed, bool random_restitution, double friction_scale, int count)
      : model(make_model(seed, random_restitution, friction_scale)), state(rest_state(model)), solver(model) {
    solver.factor(state);
    random_consistent_velocities(model, solver, seed + 3, state);
    for (int k = 0; k < count; ++k) {
      int a = static_cast<int>(unit(rng) * model.count), b = static_cast<int>(unit(rng) * model.count);
      if (a == b) b = (b + 1) % model.count;
      if (a > b) std::swap(a, b);
      contacts.push_back(approaching_contact(state, a, b, 0.1 * Vec3::Random(), Vec3::Random()));
    }
  }
  Model make_model(unsigned seed, bool random_restitution, double friction_scale) {
    std::srand(seed);
    Model m = test::random_tree(12, seed);
    rng.seed(seed);
    m.restitution.assign(m.count, random_restitution ? unit(rng) : 0.0);
    m.friction.assign(m.count, friction_scale * unit(rng));
    return m;
  }
  std::mt19937 rng;
  std::uniform_real_distribution<double> unit{0.0, 1.0};
  Model model;
  State state;
  TreeSolver solver;
  std::vector<Contact> contacts;
};

TEST(ContactResponse, NeverAddsEnergyStaysInTheConeAndKeepsJoints) {
  int sliding = 0;
  for (unsigned seed = 1; seed <= 60; ++seed) {
    RandomContactCase test_case(seed, true, 1.2, 3);
    const Model& model = test_case.model;
    const State& state = test_case.state;
    TreeSolver& solver = test_case.solver;
    const std::vector<Contact>& contacts = test_case.contacts;
    const double before = kinetic_energy(model, state);
    ContactResponse response(model);
    response.tuning.bounce_threshold = 0;
    State after = state;
    std::vector<Vec6> pseudo(model.count, Vec6::Zero());
    bool has_pseudo = false;
    const ContactStepReport report =
        response.resolve(state, solver, contacts, 1e-3, after.velocity, after.angular, pseudo, has_pseudo);
    sliding += report.sliding;
    // Energy only leaves (round-off of O(1) energies allowed).
    EXPECT_LE(kinetic_energy(model, after), before * (1 + 1e-10)) << "seed " << seed;
    const Eigen::VectorXd& P = response.impulses();
    for (int k = 0; k < 3; ++k) {
      const double mu = model.friction[contacts[k].a];
      EXPECT_GE(P[3 * k], 0.0);
      EXPECT_LE(P.segment<2>(3 * k + 1).norm(), mu * P[3 * k] * (1 + 1e-12) + 1e-15);
    }
    // The joints still move together: the impulse went through the joint rows too.
    for (int i = 1; i < model.count; ++i)  // relative 1e-9 of O(1) velocities, the tree solve's accuracy
      EXPECT_LT(joint_opening_speed(model, state, after, i), 1e-9) << "seed " << seed << " joint " << i;
  }
  EXPECT_GT(sliding, 5);  // the sliding branch was exercised
}

// More closing contacts than one solve takes (ContactResponse::kMaxContacts): the soonest to close are
// solved, the rest left for the next step and counted (ContactStepReport::dropped, which the simulation's
// CollisionStatistics::contacts_left sums), with the solve's size in `solved`. Velocities are scaled to
// mm/s so that a contact's gap after two steps is its distance to within 2 h |u_n| ~ 2e-6 m: the
// overlapping ones (-0.1 mm) close before the shallow ones (+0.04 mm, inside the slop, so kept as
// candidates).
TEST(ContactResponse, MoreClosingContactsThanASolveTakesLeaveTheLatestAndAreCounted) {
  constexpr int kShallow = 5;
  for (const int deep : {10, ContactResponse::kMaxContacts}) {
    RandomContactCase test_case(7, false, 0.5, 0);
    const Model& model = test_case.model;
    State state = test_case.state;
    for (int i = 1; i < model.count; ++i) state.velocity[i] *= 1e-3, state.angular[i] *= 1e-3;
    std::vector<Contact> contacts;
    for (int k = 0; k < deep + kShallow; ++k) {
      const int a = k % (model.count - 1), b = a + 1;  // each body against the next (a may be the hook)
      Contact c = approaching_contact(state, a, b, 0.01 * Vec3::Random(), Vec3::Random());
      c.distance = k < deep ? -1e-4 : 4e-5;
      contacts.push_back(c);
    }
    ContactResponse response(model);
    std::vector<Vec6> pseudo(model.count, Vec6::Zero());
    bool has_pseudo = false;
    const ContactStepReport report = response.resolve(state, test_case.solver, contacts, 1e-3, state.velocity,
                                                      state.angular, pseudo, has_pseudo);
    const int solvable = std::min(deep + kShallow, ContactResponse::kMaxContacts);
    EXPECT_EQ(report.contacts, deep + kShallow);
    EXPECT_EQ(report.solves, 1);
    EXPECT_EQ(report.solved, solvable);
    EXPECT_EQ(report.dropped, deep + kShallow - solvable);
    EXPECT_GE(report.iterations, 1);
    ASSERT_EQ(static_cast<int>(response.kept().size()), solvable);
    int shallow_kept = 0;
    for (const Contact& c : response.kept()) shallow_kept += c.distance > 0;
    EXPECT_EQ(shallow_kept, solvable - deep) << "the overlapping contacts close first and are solved first";
  }
}

// The look after a step's impulses finds most of the step's contacts again, at the same pose: resolve()
// then takes their columns of the collision matrix, and the blocks between them, from the resolve before
// instead of computing them again. The result must be the same, bit for bit, as a fresh response's (which
// computes everything) for a second list that drops one contact, keeps the others in order and adds new
// ones; and nothing may be taken from another solver, or once the solver has factored again.
TEST(ContactResponse, ContactsFoundAgainAtTheSameFactorizationGiveTheSameResultBitForBit) {
  int reused = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    RandomContactCase test_case(seed, true, 0.8, 6);
    const Model& model = test_case.model;
    TreeSolver& solver = test_case.solver;
    std::vector<Contact> first = test_case.contacts;
    const auto by_pair = [](const Contact& x, const Contact& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; };
    std::stable_sort(first.begin(), first.end(), by_pair);
    std::vector<Contact> second(first.begin() + 1, first.end());
    second.push_back(approaching_contact(test_case.state, 0, model.count - 1, 0.1 * Vec3::Random(), Vec3::Random()));
    second.push_back(approaching_contact(test_case.state, 1, 2, 0.1 * Vec3::Random(), Vec3::Random()));
    std::stable_sort(second.begin(), second.end(), by_pair);
    const double h = 1e-3;
    const auto resolve = [&](ContactResponse& response, TreeSolver& with, const std::vector<Contact>& contacts,
                             State& out, std::vector<Vec6>& pseudo) {
      out = test_case.state;
      bool has_pseudo = false;
      pseudo.assign(model.count, Vec6::Zero());
      return response.resolve(test_case.state, with, contacts, h, out.velocity, out.angular, pseudo, has_pseudo);
    };
    ContactResponse cached(model), fresh(model);
    State a, b;
    std::vector<Vec6> pseudo_a, pseudo_b;
    resolve(cached, solver, first, a, pseudo_a);
    const ContactStepReport report = resolve(cached, solver, second, a, pseudo_a);
    const ContactStepReport fresh_report = resolve(fresh, solver, second, b, pseudo_b);
    // Every contact is kept (each approaches at distance 0), so the first list's, less the one dropped,
    // are all found again.
    ASSERT_EQ(fresh_report.solved, static_cast<int>(second.size())) << "seed " << seed;
    EXPECT_EQ(fresh_report.reused, 0);
    EXPECT_EQ(report.reused, static_cast<int>(first.size()) - 1) << "seed " << seed;
    reused += report.reused;
    for (int i = 1; i < model.count; ++i) {
      EXPECT_TRUE(a.velocity[i] == b.velocity[i] && a.angular[i] == b.angular[i] && pseudo_a[i] == pseudo_b[i])
          << "seed " << seed << " body " << i;
    }
    // A new factorization (here of the same pose) makes the last resolve's columns stale: none taken.
    solver.factor(test_case.state);
    EXPECT_EQ(resolve(cached, solver, second, a, pseudo_a).reused, 0) << "seed " << seed;
    // Another solver, even one with as many factorizations, is not the one the columns came from.
    TreeSolver other(model);
    while (other.factorizations() < solver.factorizations()) other.factor(test_case.state);
    ASSERT_EQ(other.factorizations(), solver.factorizations());
    EXPECT_EQ(resolve(cached, other, second, a, pseudo_a).reused, 0) << "seed " << seed;
  }
  EXPECT_GT(reused, 40);
}

// The contact pass (Simulation's step, after the joints' Newton corrections): when the joints' impulses
// made the kept contacts approach again, correct() applies extra impulses. After it no contact
// approaches, the joints still move together and no energy is added.
TEST(ContactResponse, CorrectionStopsTheApproachKeepsTheJointsAndAddsNoEnergy) {
  int corrected = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    RandomContactCase test_case(seed, false, 0.8, 2);
    const Model& model = test_case.model;
    State& state = test_case.state;
    TreeSolver& solver = test_case.solver;
    const std::vector<Contact>& contacts = test_case.contacts;
    ContactResponse response(model);
    response.tuning.bounce_threshold = 0;
    std::vector<Vec6> pseudo(model.count, Vec6::Zero());
    bool has_pseudo = false;
    response.resolve(state, solver, contacts, 1e-3, state.velocity, state.angular, pseudo, has_pseudo);
    // What the joints' impulses do in the drift, for the test: another joint-consistent velocity on top.
    State pushed = state;
    random_consistent_velocities(model, solver, seed + 100, pushed);
    for (int i = 1; i < model.count; ++i) {
      pushed.velocity[i] = state.velocity[i] + 0.5 * pushed.velocity[i];
      pushed.angular[i] = state.angular[i] + 0.5 * pushed.angular[i];
    }
    const double tolerance = 1e-6;  // m/s, the step's (kContactVelocityTolerance)
    const double before = kinetic_energy(model, pushed);
    if (!response.correct(1e-3, pushed.velocity, pushed.angular, tolerance)) continue;
    ++corrected;
    // Inelastic (e = 0) impulses only take energy out (round-off of O(1) energies allowed).
    EXPECT_LE(kinetic_energy(model, pushed), before * (1 + 1e-10)) << "seed " << seed;
    for (const Contact& c : response.kept()) {
      const auto point_velocity = [&](int i) {
        return i == 0 ? Vec3::Zero() : Vec3(pushed.velocity[i] + pushed.angular[i].cross(c.point - pushed.position[i]));
      };
      // n . (v_a - v_b) < 0 approaches; the contact law holds it to within its own accuracy (1e-9 of
      // O(1) velocities) of no approach.
      EXPECT_GE(c.normal.dot(point_velocity(c.a) - point_velocity(c.b)), -1e-9) << "seed " << seed;
    }
    for (int i = 1; i < model.count; ++i)
      EXPECT_LT(joint_opening_speed(model, state, pushed, i), 1e-9) << "seed " << seed << " joint " << i;
    // A second look finds nothing more to do.
    EXPECT_FALSE(response.correct(1e-3, pushed.velocity, pushed.angular, tolerance)) << "seed " << seed;
  }
  EXPECT_GT(corrected, 10);
}

TEST(ContactResponse, OverlapIsPushedOutByAPseudoVelocityOnly) {
  const Model model = random_chain(4, 3);
  State state = rest_state(model);
  TreeSolver solver(model);
  solver.factor(state);
  Contact c = approaching_contact(state, 0, 3, Vec3(0, -0.1, 0), Vec3::UnitY());
  c.distance = -1e-3;  // 1 mm overlap, bodies at rest
  ContactResponse response(model);
  std::vector<Vec3> v = state.velocity, w = state.angular;
  std::vector<Vec6> pseudo(model.count, Vec6::Zero());
  bool has_pseudo = false;
  response.resolve(state, solver, {c}, 1e-3, v, w, pseudo, has_pseudo);
  ASSERT_TRUE(has_pseudo);
  // The real velocities stay zero: no energy is added to push the overlap out.
  for (int i = 1; i < model.count; ++i) EXPECT_EQ(v[i].norm() + w[i].norm(), 0.0);
  // The pseudo-velocity separates the contact at the requested rate: rate * (overlap - slop) / h.
  const Vec3 arm = c.point - state.position[3];
  const double separating = -c.normal.dot(pseudo[3].head<3>() + pseudo[3].tail<3>().cross(arm));
  const double expected = response.tuning.penetration_rate * (1e-3 - response.tuning.penetration_slop) / 1e-3;
  EXPECT_NEAR(separating, expected, 1e-9 * expected);
}

}  // namespace
}  // namespace aloft
