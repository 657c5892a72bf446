// The linear-time tree solve against a dense solve of the same KKT system.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <random>
#include <vector>

#include "aloft/generate.hpp"
#include "dynamics/tree_solver.hpp"
#include "support/model_builder.hpp"

namespace aloft {
namespace {

// Solve H [u; mu] = [f; c] densely (partial-pivoting LU), lambda = -mu; compare with TreeSolver.
void check_against_dense(int count, unsigned seed) {
  std::srand(seed);  // Quat::UnitRandom draws from std::rand
  const Model model = test::random_tree(count, seed);
  State state = rest_state(model);
  std::mt19937 rng(seed + 1);
  std::normal_distribution<double> normal;
  const int m = count - 1;
  std::vector<Vec6> f(count, Vec6::Zero()), u(count, Vec6::Zero());
  std::vector<Vec3> c(count, Vec3::Zero()), lambda(count, Vec3::Zero());
  Eigen::VectorXd rhs(9 * m);
  for (int i = 1; i < count; ++i) {
    for (int k = 0; k < 6; ++k) f[i](k) = normal(rng);
    for (int k = 0; k < 3; ++k) c[i](k) = normal(rng);
    rhs.segment<6>(6 * (i - 1)) = f[i];
    rhs.segment<3>(6 * m + 3 * (i - 1)) = c[i];
  }
  TreeSolver solver(model);
  solver.factor(state);
  solver.solve(f, c, u, &lambda);

  const Eigen::MatrixXd h = dense_kkt_matrix(model, state);
  const Eigen::VectorXd dense = h.partialPivLu().solve(rhs);
  Eigen::VectorXd tree(9 * m);
  for (int i = 1; i < count; ++i) {
    tree.segment<6>(6 * (i - 1)) = u[i];
    tree.segment<3>(6 * m + 3 * (i - 1)) = -lambda[i];
  }
  // 1e-9 relative: both solves are backward stable; with masses 0.05..5 kg, inertias ~1e-3..5e-2
  // kg m^2 and arms ~0.1..0.5 m the KKT matrix has a condition number of order 1e4..1e6, so the
  // forward error of either is ~1e-16 * cond <= 1e-10.
  const double scale = dense.norm();
  EXPECT_LT((tree - dense).norm(), 1e-9 * scale) << "tree of " << count << " components, seed " << seed;
  // And the solution really solves the system (the dense solve is not trusted blindly).
  EXPECT_LT((h * tree - rhs).norm(), 1e-9 * rhs.norm());
}

TEST(TreeSolver, MatchesDenseSolveOnRandomTrees) {
  for (int count : {2, 3, 5, 9, 17, 40, 100, 200})
    for (unsigned seed : {1u, 2u, 3u}) check_against_dense(count, seed * 1000 + count);
}

TEST(TreeSolver, ChainIsLinearTreeToo) {
  // A chain (every parent the previous body) is the deepest tree: same check.
  std::srand(7);
  Model model = test::random_tree(60, 7);
  for (int i = 1; i < model.count; ++i) model.parent[i] = i - 1;
  for (int i = 1; i < model.count; ++i) model.joint_world[i] = model.rest_position[i - 1] + Vec3(0.05, -0.1, 0.02);
  test::finish_model(model);
  State state = rest_state(model);
  TreeSolver solver(model);
  solver.factor(state);
  std::vector<Vec6> f(model.count, Vec6::Zero()), u(model.count, Vec6::Zero());
  std::vector<Vec3> c(model.count, Vec3::Zero()), lambda(model.count);
  for (int i = 1; i < model.count; ++i) f[i] << 0, -9.81 * model.mass[i], 0, 0.1, 0, 0;
  solver.solve(f, c, u, &lambda);
  // The solution satisfies every joint row J u = c = 0 (to rounding: 1e-12 m/s^2 for accelerations of
  // order 10 m/s^2).
  for (int i = 1; i < model.count; ++i) {
    const Vec3 child = u[i].head<3>() + u[i].tail<3>().cross(solver.child_arm()[i]);
    const Vec3 parent = u[i - 1].head<3>() + u[i - 1].tail<3>().cross(solver.parent_arm()[i]);
    EXPECT_LT((child - parent).norm(), 1e-10) << "joint " << i;
  }
}

// A pose as factor_and_solve() takes it: every body's rotation matrix and the world lever arms.
struct PoseArrays {
  std::vector<Mat3> rotation;
  std::vector<Vec3> child_arm, parent_arm;
};

PoseArrays pose_arrays(const Model& model, const State& state) {
  PoseArrays out{std::vector<Mat3>(model.count), std::vector<Vec3>(model.count, Vec3::Zero()),
                 std::vector<Vec3>(model.count, Vec3::Zero())};
  for (int i = 0; i < model.count; ++i) out.rotation[i] = state.orientation[i].toRotationMatrix();
  for (int i = 1; i < model.count; ++i) {
    out.child_arm[i] = out.rotation[i] * model.joint_in_child[i];
    out.parent_arm[i] = out.rotation[model.parent[i]] * model.joint_in_parent[i];
  }
  return out;
}

TEST(TreeSolver, FactorAndSolveMatchesFactorThenSolve) {
  // The step's fused factorization and solve (c = 0) against the two done apart, on random trees at a
  // random pose (rotation matrices and arms handed in, as the step does). 1e-12 relative: the same
  // operations in a different order, so only round-off differs.
  for (const int count : {2, 9, 40, 200}) {
    std::srand(count);
    const Model model = test::random_tree(count, count);
    State state = rest_state(model);
    for (int i = 1; i < count; ++i) state.orientation[i] = Quat::UnitRandom();
    PoseArrays pose = pose_arrays(model, state);
    std::mt19937 rng(count);
    std::normal_distribution<double> normal;
    std::vector<Vec6> f(count, Vec6::Zero()), u(count, Vec6::Zero()), fused_u(count, Vec6::Zero());
    std::vector<Vec3> c(count, Vec3::Zero()), lambda(count, Vec3::Zero()), fused_lambda(count, Vec3::Zero());
    for (int i = 1; i < count; ++i)
      for (int k = 0; k < 6; ++k) f[i](k) = normal(rng);

    TreeSolver apart(model);
    apart.factor(state);  // the same rotation matrices and arms, from the orientations
    apart.solve(f, c, u, &lambda);

    TreeSolver fused(model);
    fused.factor(state);  // a first factorization, as the step has one from the step before
    // The wrench of each body is asked for once, with the inertia of the pose factored before (here the
    // same pose, so exactly apart's).
    std::vector<int> asked(count, 0);
    const auto wrench = [&](int i, const Mat3& previous_inertia) {
      ++asked[i];
      EXPECT_EQ(previous_inertia, apart.world_inertia()[i]) << "body " << i;
      return f[i];
    };
    fused.factor_and_solve(pose.rotation, pose.child_arm, pose.parent_arm, wrench,
                           [&](int i, const Vec6& ui, const Vec3& lam) {
                             fused_u[i] = ui;
                             fused_lambda[i] = lam;
                           });
    for (int i = 1; i < count; ++i) EXPECT_EQ(asked[i], 1) << "body " << i;
    double scale_u = 0, scale_l = 0, error_u = 0, error_l = 0;
    for (int i = 1; i < count; ++i) {
      scale_u = std::max(scale_u, u[i].norm());
      scale_l = std::max(scale_l, lambda[i].norm());
      error_u = std::max(error_u, (fused_u[i] - u[i]).norm());
      error_l = std::max(error_l, (fused_lambda[i] - lambda[i]).norm());
    }
    EXPECT_LT(error_u, 1e-12 * scale_u) << count << " components";
    EXPECT_LT(error_l, 1e-12 * scale_l) << count << " components";
    // And the factorization left behind is the same: a later solve of joint rows agrees too.
    for (int i = 1; i < count; ++i) c[i] = Vec3(normal(rng), normal(rng), normal(rng));
    std::vector<Vec6> zero(count, Vec6::Zero());
    apart.solve(zero, c, u, &lambda);
    fused.solve(zero, c, fused_u, &fused_lambda);
    double scale_rows = 0, error_rows = 0;
    for (int i = 1; i < count; ++i) {
      scale_rows = std::max(scale_rows, u[i].norm());
      error_rows = std::max(error_rows, (fused_u[i] - u[i]).norm());
    }
    EXPECT_LT(error_rows, 1e-12 * scale_rows) << count << " components";
  }
}

TEST(TreeSolver, FoldingOnAStackGivesTheSameBitsAsTheArrays) {
  // A generated mobile (compiled: depth-first preorder) of 127 components at a random pose: the fused
  // factorization and solve, and a later solve of joint rows, with the children's folds carried on the
  // stack and in the per-body arrays. The same sums in the same order: equal bit for bit.
  GenerateOptions options;
  options.components = 127;
  options.seed = 3;
  const Model model = compile(parse_mobile_text(generate_mobile(options), "generated-127.json"));
  ASSERT_TRUE(TreeSolver::stack_folding_possible(model.parent));
  std::srand(5);
  State state = rest_state(model);
  for (int i = 1; i < model.count; ++i) state.orientation[i] = Quat::UnitRandom();
  const PoseArrays pose = pose_arrays(model, state);
  std::mt19937 rng(9);
  std::normal_distribution<double> normal;
  std::vector<Vec6> f(model.count, Vec6::Zero()), zero(model.count, Vec6::Zero());
  std::vector<Vec3> c(model.count, Vec3::Zero());
  for (int i = 1; i < model.count; ++i) {
    for (int k = 0; k < 6; ++k) f[i](k) = normal(rng);
    c[i] = Vec3(normal(rng), normal(rng), normal(rng));
  }
  std::vector<Vec6> fused[2], rows[2];
  for (const bool stack : {false, true}) {
    TreeSolver solver(model);
    solver.set_stack_folding(stack);
    ASSERT_EQ(solver.stack_folding(), stack);
    solver.factor(state);
    PoseArrays arms = pose;  // factor_and_solve takes the arm arrays over
    std::vector<Vec6>& u = fused[stack];
    u.assign(model.count, Vec6::Zero());
    solver.factor_and_solve(
        arms.rotation, arms.child_arm, arms.parent_arm, [&](int i, const Mat3&) { return f[i]; },
        [&](int i, const Vec6& ui, const Vec3&) { u[i] = ui; });
    rows[stack].assign(model.count, Vec6::Zero());
    solver.solve(zero, c, rows[stack]);
  }
  for (int i = 1; i < model.count; ++i) {
    EXPECT_EQ(fused[0][i], fused[1][i]) << "body " << i;
    EXPECT_EQ(rows[0][i], rows[1][i]) << "body " << i;
  }
}

TEST(TreeSolver, FoldingOnAStackNeedsDepthFirstOrder) {
  // parent[i] < i is not enough: here body 3 (a child of 1) comes between body 2 and its child 4, so the
  // sweep leaves 2's subtree before finishing it.
  EXPECT_FALSE(TreeSolver::stack_folding_possible({-1, 0, 1, 1, 2}));
  EXPECT_TRUE(TreeSolver::stack_folding_possible({-1, 0, 1, 2, 1}));    // 1 -> 2 -> 3, 1 -> 4: preorder
  EXPECT_TRUE(TreeSolver::stack_folding_possible({-1, 0, 0, 2, 2, 0}));  // nails and a fork
  // A solver for an order that does not allow it keeps the arrays, whatever it is asked.
  std::srand(11);
  Model model = test::random_tree(6, 11);
  model.parent = {-1, 0, 1, 1, 2, 0};
  test::finish_model(model);
  TreeSolver solver(model);
  solver.set_stack_folding(true);
  EXPECT_FALSE(solver.stack_folding());
}

// F1^T H^-1 F2 by full solves: the velocity response u = H^-1 [F2; 0] read against F1's wrenches.
Mat3 coupling_by_full_solves(const Model& model, TreeSolver& solver, int a1, const Mat63& w1a, int b1,
                             const Mat63& w1b, int a2, const Mat63& w2a, int b2, const Mat63& w2b) {
  Mat3 out;
  std::vector<Vec6> f(model.count, Vec6::Zero()), u(model.count, Vec6::Zero());
  const std::vector<Vec3> c(model.count, Vec3::Zero());
  for (int col = 0; col < 3; ++col) {
    for (Vec6& x : f) x.setZero();
    f[a2] += w2a.col(col);
    f[b2] += w2b.col(col);
    solver.solve(f, c, u);
    u[0].setZero();  // the fixed component does not move
    for (int row = 0; row < 3; ++row) out(row, col) = w1a.col(row).dot(u[a1]) + w1b.col(row).dot(u[b1]);
  }
  return out;
}

TEST(TreeSolver, PathColumnsCouplingEqualsFullSolves) {
  // Random trees and chains (the deepest case), random pose-independent wrenches on random pairs of
  // bodies, including the fixed component and a body paired with itself.
  for (bool chain : {false, true}) {
    for (unsigned seed : {3u, 4u, 5u}) {
      std::srand(seed);
      Model model = test::random_tree(40, seed);
      if (chain) {
        for (int i = 1; i < model.count; ++i) model.parent[i] = i - 1;
        for (int i = 1; i < model.count; ++i)
          model.joint_world[i] = model.rest_position[i - 1] + Vec3(0.05, -0.1, 0.02);
        test::finish_model(model);
      }
      const State state = rest_state(model);
      TreeSolver solver(model);
      solver.factor(state);
      std::mt19937 rng(seed);
      std::uniform_int_distribution<int> body(0, model.count - 1);
      std::normal_distribution<double> normal;
      auto random_wrench = [&] {
        Mat63 w;
        for (int r = 0; r < 6; ++r)
          for (int k = 0; k < 3; ++k) w(r, k) = normal(rng);
        return w;
      };
      PathColumns x, y;
      for (int trial = 0; trial < 20; ++trial) {
        const int a1 = body(rng), b1 = trial % 5 == 0 ? a1 : body(rng);
        const int a2 = trial % 7 == 0 ? 0 : body(rng), b2 = body(rng);
        const Mat63 w1a = random_wrench(), w1b = random_wrench(), w2a = random_wrench(), w2b = random_wrench();
        solver.eliminate_on_paths(a1, w1a, b1, w1b, x);
        solver.eliminate_on_paths(a2, w2a, b2, w2b, y);
        // A wrench on the fixed component moves nothing: compare with it removed.
        const Mat63 zero = Mat63::Zero();
        const Mat3 dense = coupling_by_full_solves(model, solver, a1, a1 ? w1a : zero, b1, b1 ? w1b : zero, a2,
                                                   a2 ? w2a : zero, b2, b2 ? w2b : zero);
        // Each path marked by body, as ContactResponse marks the other contact's.
        const auto positions = [&](const PathColumns& path) {
          std::vector<int> position(static_cast<std::size_t>(model.count), -1);
          for (std::size_t q = 0; q < path.node.size(); ++q) position[static_cast<std::size_t>(path.node[q])] = static_cast<int>(q);
          return position;
        };
        const Mat3 sparse = TreeSolver::coupling(x, y, positions(y));
        // 1e-10 relative: both are the same elimination, summed in a different order; the KKT system's
        // condition number (1e4..1e6, see above) bounds the difference at ~1e-16 * cond.
        EXPECT_LE((sparse - dense).norm(), 1e-10 * dense.norm())
            << (chain ? "chain" : "tree") << " seed " << seed << " trial " << trial;
        EXPECT_LE((TreeSolver::coupling(y, x, positions(x)) - sparse.transpose()).norm(), 1e-12 * sparse.norm());
      }
    }
  }
}

TEST(TreeSolver, SparseSolveOfAFewWrenchesEqualsTheFullSolve) {
  // Wrenches on a few bodies (a contact's two, the fixed component among them, a body listed twice) on a
  // random tree and a generated mobile at a random pose: the sweep along their paths alone gives what the
  // full solve gives (c = 0), number for number (the same operations on the path; zeros elsewhere), and
  // leaves the solver ready for the next solve of either kind.
  GenerateOptions options;
  options.components = 127;
  options.seed = 4;
  std::srand(13);
  const Model models[] = {test::random_tree(60, 13),
                          compile(parse_mobile_text(generate_mobile(options), "generated-127.json"))};
  for (const Model& model : models) {
    State state = rest_state(model);
    for (int i = 1; i < model.count; ++i) state.orientation[i] = Quat::UnitRandom();
    TreeSolver solver(model);
    solver.factor(state);
    std::mt19937 rng(17);
    std::normal_distribution<double> normal;
    std::uniform_int_distribution<int> body(1, model.count - 1);
    const std::vector<Vec3> zero_rows(model.count, Vec3::Zero());
    for (int trial = 0; trial < 10; ++trial) {
      std::vector<int> bodies = {body(rng), body(rng), trial % 3 == 0 ? 0 : body(rng)};
      bodies.push_back(bodies[0]);
      std::vector<Vec6> f(model.count, Vec6::Zero()), full(model.count, Vec6::Zero()),
          sparse(model.count, Vec6::Constant(NAN));
      for (const int b : bodies)
        if (b != 0)
          for (int k = 0; k < 6; ++k) f[b](k) += normal(rng);
      solver.solve(f, zero_rows, full);
      solver.solve_sparse(f, bodies, sparse);
      for (int i = 0; i < model.count; ++i) EXPECT_EQ(sparse[i], full[i]) << "trial " << trial << ", body " << i;
    }
  }
}

// generated-127 (seed 4; bodies in depth-first preorder, as compile() orders them) at a random pose drawn
// after std::srand(seed), for the sparse solves' tests.
struct RandomPoseMobile {
  Model model;
  State state;
};
RandomPoseMobile generated_127_at_random_pose(unsigned seed) {
  GenerateOptions options;
  options.components = 127;
  options.seed = 4;
  std::srand(seed);
  RandomPoseMobile out{compile(parse_mobile_text(generate_mobile(options), "generated-127.json")), {}};
  out.state = rest_state(out.model);
  for (int i = 1; i < out.model.count; ++i) out.state.orientation[i] = Quat::UnitRandom();
  return out;
}

// Which bodies lie on the paths to the base from the bodies (or joints: joint i is body i's) listed.
std::vector<char> on_paths(const Model& model, std::initializer_list<const std::vector<int>*> lists) {
  std::vector<char> on(model.count, 0);
  for (const std::vector<int>* list : lists)
    for (int b : *list)
      for (int i = b; i > 0; i = model.parent[i]) on[i] = 1;
  return on;
}

TEST(TreeSolver, ListedRowsSolveVisitsWhatTheFullSolveMovesAndSkipsOnlyWhatItSaysIsStill) {
  // Joint rows on a few joints of a generated mobile at a random pose (preorder, as compile() orders
  // bodies). solve_listed_rows_visiting() must give every body it visits what the full solve of the same
  // rows gives (number for number: the same operations along the paths, exact zeros elsewhere); pass over
  // exactly the subtrees below the bodies it asked skip() about and was told to skip, calling boundary()
  // for each such body once; and ask skip() only off the listed joints' paths.
  const RandomPoseMobile mobile = generated_127_at_random_pose(29);
  const Model& model = mobile.model;
  TreeSolver solver(model);
  ASSERT_TRUE(solver.sparse_rows_possible());
  solver.factor(mobile.state);
  std::mt19937 rng(31);
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<int> joint(1, model.count - 1);
  int skipped_somewhere = 0, visited_off_paths = 0;  // (that the cases above were met at all)
  for (int trial = 0; trial < 12; ++trial) {
    std::vector<int> listed;
    for (int k = 0; k < 1 + trial % 4; ++k) {
      const int j = joint(rng);
      if (std::find(listed.begin(), listed.end(), j) == listed.end()) listed.push_back(j);
    }
    std::vector<Vec3> rows(model.count, Vec3::Zero());
    for (int j : listed)
      for (int k = 0; k < 3; ++k) rows[j](k) = normal(rng);
    std::vector<Vec6> full(model.count, Vec6::Zero());
    std::vector<Vec3> full_lambda(model.count, Vec3::Zero());
    solver.solve(std::vector<Vec6>(model.count, Vec6::Zero()), rows, full, &full_lambda);
    // Rows that are not listed are ignored: garbage there must not change anything.
    std::vector<Vec3> given = rows;
    for (int i = 1; i < model.count; ++i)
      if (std::find(listed.begin(), listed.end(), i) == listed.end()) given[i] = Vec3::Constant(1e6);
    // Skip below a threshold that leaves some subtrees out (trial 0: skip nothing that moves at all).
    const double threshold = trial == 0 ? 0.0 : 1e-3 * trial;
    const std::vector<char> on = on_paths(model, {&listed});
    std::vector<int> visited(model.count, 0), bounded(model.count, 0), asked(model.count, 0);
    std::vector<Vec6> sparse(model.count, Vec6::Constant(NAN));
    std::vector<Vec3> sparse_lambda(model.count, Vec3::Constant(NAN));
    solver.solve_listed_rows_visiting(
        given, listed,
        [&](int i, const Vec3& parent_point) {
          ++asked[i];
          EXPECT_FALSE(on[i]) << "asked about body " << i << " on a listed joint's path";
          // The parent's velocity at the joint point, as the full solve has it.
          const int p = model.parent[i];
          const Vec3 expected = p == 0 ? Vec3::Zero()
                                       : Vec3(full[p].head<3>() + full[p].tail<3>().cross(solver.parent_arm()[i]));
          EXPECT_EQ(parent_point, expected) << "body " << i;
          return parent_point.cwiseAbs().maxCoeff() <= threshold;
        },
        [&](int i, const Vec6& u, const Vec3& lambda) {
          ++visited[i];
          sparse[i] = u;
          sparse_lambda[i] = lambda;
        },
        [&](int i) { ++bounded[i]; });
    for (int i = 1; i < model.count; ++i) {
      const int p = model.parent[i];
      // A body is passed over when an ancestor (or itself) was skipped; it is visited otherwise.
      const bool parent_passed = p > 0 && !visited[p];
      if (parent_passed) {
        EXPECT_EQ(visited[i] + bounded[i] + asked[i], 0) << "body " << i << " below a skipped body";
        continue;
      }
      EXPECT_EQ(visited[i] + bounded[i], 1) << "body " << i;
      if (visited[i]) {
        EXPECT_EQ(sparse[i], full[i]) << "trial " << trial << ", body " << i;
        EXPECT_EQ(sparse_lambda[i], full_lambda[i]) << "trial " << trial << ", body " << i;
      } else {
        // Skipped: the full solve moves it by no more than the threshold allowed at its joint point.
        const Vec3 parent_point =
            p == 0 ? Vec3::Zero() : Vec3(full[p].head<3>() + full[p].tail<3>().cross(solver.parent_arm()[i]));
        EXPECT_LE(parent_point.cwiseAbs().maxCoeff(), threshold) << "body " << i;
      }
    }
    for (int j : listed) EXPECT_EQ(visited[j], 1) << "listed joint " << j;
    for (int i = 1; i < model.count; ++i) {
      skipped_somewhere += bounded[i] && !(full[i] == Vec6::Zero());
      visited_off_paths += visited[i] && !on[i];
    }
    if (trial == 0) {  // nothing moving was skipped: only bodies whose joint point stays exactly still
      for (int i = 1; i < model.count; ++i) {
        if (bounded[i]) {
          EXPECT_EQ(full[i], Vec6::Zero()) << "body " << i;
        }
      }
    }
  }
  EXPECT_GT(skipped_somewhere, 0);
  EXPECT_GT(visited_off_paths, 0);
  std::printf("listed rows: %d bodies that move skipped, %d visited off the paths, over the trials\n",
              skipped_somewhere, visited_off_paths);
  // The solver is left ready for a plain solve.
  std::vector<Vec3> rows(model.count, Vec3::Zero());
  rows[5] = Vec3(1, 2, 3);
  std::vector<Vec6> once(model.count, Vec6::Zero()), again(model.count, Vec6::Zero());
  const std::vector<Vec6> no_wrench(model.count, Vec6::Zero());
  solver.solve(no_wrench, rows, once);
  solver.solve_listed_rows_visiting(rows, {5}, [](int, const Vec3&) { return false; },
                                    [](int, const Vec6&, const Vec3&) {}, [](int) {});
  solver.solve(no_wrench, rows, again);
  for (int i = 0; i < model.count; ++i) EXPECT_EQ(once[i], again[i]) << "body " << i;
}

TEST(TreeSolver, SparseWrenchSolveVisitsWhatTheFullSolveMovesAndTheJointsAskedFor) {
  // Wrenches on a few bodies (a contact pass's impulses) of a generated mobile at a random pose, and a few
  // other joints to visit whatever the solve does to them (the joints the pass before left open).
  // solve_sparse_visiting() must give every body it visits what solve_sparse() gives (number for number:
  // the same operations along the paths, the same substitution below them); visit every body on the
  // wrenches' and the asked-for joints' paths; ask skip() only off those paths; pass over exactly the
  // subtrees it was told to skip, calling boundary() once for each; and leave the solver ready.
  const RandomPoseMobile mobile = generated_127_at_random_pose(37);
  const Model& model = mobile.model;
  TreeSolver solver(model);
  ASSERT_TRUE(solver.sparse_rows_possible());
  solver.factor(mobile.state);
  std::mt19937 rng(41);
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<int> body(1, model.count - 1);
  int skipped_somewhere = 0, visited_off_paths = 0;
  for (int trial = 0; trial < 12; ++trial) {
    // A contact's two bodies (the fixed component among them now and then), one listed twice.
    std::vector<int> bodies = {body(rng), trial % 3 == 0 ? 0 : body(rng)};
    bodies.push_back(bodies[0]);
    std::vector<int> also;
    for (int k = 0; k < trial % 3; ++k) also.push_back(body(rng));
    std::vector<Vec6> f(model.count, Vec6::Zero()), full(model.count, Vec6::Zero());
    for (const int b : bodies)
      if (b != 0)
        for (int k = 0; k < 6; ++k) f[b](k) += normal(rng);
    solver.solve_sparse(f, bodies, full);
    // Skip below a threshold that leaves some subtrees out (trial 0: skip nothing that moves at all): a
    // share of the fastest joint point's velocity.
    double fastest = 0;
    for (int i = 1; i < model.count; ++i) {
      const int p = model.parent[i];
      if (p > 0)
        fastest = std::max(fastest, (full[p].head<3>() + full[p].tail<3>().cross(solver.parent_arm()[i])).cwiseAbs().maxCoeff());
    }
    const double threshold = trial == 0 ? 0.0 : 0.01 * trial * fastest;
    const std::vector<char> on = on_paths(model, {&bodies, &also});
    std::vector<int> visited(model.count, 0), bounded(model.count, 0), asked(model.count, 0);
    std::vector<Vec6> sparse(model.count, Vec6::Constant(NAN));
    solver.solve_sparse_visiting(
        f, bodies, also,
        [&](int i, const Vec3& parent_point) {
          ++asked[i];
          EXPECT_FALSE(on[i]) << "asked about body " << i << " on a path";
          const int p = model.parent[i];
          const Vec3 expected = p == 0 ? Vec3::Zero()
                                       : Vec3(full[p].head<3>() + full[p].tail<3>().cross(solver.parent_arm()[i]));
          EXPECT_EQ(parent_point, expected) << "body " << i;
          return parent_point.cwiseAbs().maxCoeff() <= threshold;
        },
        [&](int i, const Vec6& u, const Vec3&) {
          ++visited[i];
          sparse[i] = u;
        },
        [&](int i) { ++bounded[i]; });
    for (int i = 1; i < model.count; ++i) {
      const int p = model.parent[i];
      if (p > 0 && !visited[p]) {
        EXPECT_EQ(visited[i] + bounded[i] + asked[i], 0) << "body " << i << " below a skipped body";
        continue;
      }
      EXPECT_EQ(visited[i] + bounded[i], 1) << "body " << i;
      if (on[i]) {
        EXPECT_EQ(visited[i], 1) << "body " << i << " on a path";
      }
      if (visited[i]) {
        EXPECT_EQ(sparse[i], full[i]) << "trial " << trial << ", body " << i;
      } else {
        const Vec3 parent_point =
            p == 0 ? Vec3::Zero() : Vec3(full[p].head<3>() + full[p].tail<3>().cross(solver.parent_arm()[i]));
        EXPECT_LE(parent_point.cwiseAbs().maxCoeff(), threshold) << "body " << i;
      }
      skipped_somewhere += bounded[i] && !(full[i] == Vec6::Zero());
      visited_off_paths += visited[i] && !on[i];
    }
    for (int j : also) EXPECT_EQ(visited[j], 1) << "joint " << j << " asked for";
  }
  EXPECT_GT(skipped_somewhere, 0);
  EXPECT_GT(visited_off_paths, 0);
  std::printf("sparse wrenches: %d bodies that move skipped, %d visited off the paths, over the trials\n",
              skipped_somewhere, visited_off_paths);
  // The solver is left ready for a plain solve.
  std::vector<Vec6> f(model.count, Vec6::Zero()), once(model.count, Vec6::Zero()), again(model.count, Vec6::Zero());
  f[7] = Vec6::Constant(1.0);
  const std::vector<Vec3> zero_rows(model.count, Vec3::Zero());
  solver.solve(f, zero_rows, once);
  solver.solve_sparse_visiting(f, {7}, {3}, [](int, const Vec3&) { return true; },
                               [](int, const Vec6&, const Vec3&) {}, [](int) {});
  solver.solve(f, zero_rows, again);
  for (int i = 0; i < model.count; ++i) EXPECT_EQ(once[i], again[i]) << "body " << i;
}

TEST(TreeSolver, ListedRowsNeedDepthFirstOrder) {
  // Numbered breadth first (1 -> 2, 3; 2 -> 4; 3 -> 5), body 2's subtree {2, 4} is not a range of
  // indices, so the sparse sweep, which passes over subtrees as ranges, is not offered; numbered depth
  // first (1 -> 2 -> 3, 1 -> 4 -> 5) it is.
  std::srand(11);
  Model model = test::random_tree(6, 11);
  model.parent = {-1, 0, 1, 1, 2, 3};
  test::finish_model(model);
  EXPECT_FALSE(TreeSolver(model).sparse_rows_possible());
  model.parent = {-1, 0, 1, 2, 1, 4};
  test::finish_model(model);
  EXPECT_TRUE(TreeSolver(model).sparse_rows_possible());
}

}  // namespace
}  // namespace aloft
