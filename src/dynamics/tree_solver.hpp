#pragma once
// Baraff's linear-time solve of the joint KKT system of a tree of rigid bodies.
//
// Unknowns: u_i = (v_i, w_i) per moving body (6), lambda_k per joint (3). Equations:
//     M_i u_i = f_i + sum_k J_ki^T lambda_k          (momentum: f = applied wrench, J^T lambda = joint forces)
//     sum_i J_ki u_i = c_k                             (joint rows)
// with M_i = diag(m_i E, I_i) (world axes). Joint k joins child body k to its parent p = parent[k]; with
// world lever arms r_k (child's centre of mass -> joint) and s_k (parent's centre of mass -> joint),
//     C_k = (x_k + r_k) - (x_p + s_k),   J_kk = [E, -[r_k]x],   J_kp = -[E, -[s_k]x].
// A joint to the fixed component (index 0) is a nail: it has no parent block.
//
// Baraff (SIGGRAPH 1996) orders the body and joint nodes of H = [M J^T; J 0] children first; the block
// LDL^T factorization then has no fill-in. Eliminating child body k and then its joint k gives, for every
// body, the articulated block
//     D_k = M_k + sum over child joints c of J_ck^T K_c^-1 J_ck,      K_k = J_kk D_k^-1 J_kk^T,
// which are exactly Baraff's D (body node) and -D (joint node) blocks; L_kp = D_k^-1 J_kp is applied
// implicitly. factor() computes them in one tip-to-base sweep; solve() does one tip-to-base and one
// base-to-tip sweep. Every block is 6x6, 6x3 or 3x3, so both cost O(n).
//
// D_k is not inverted as it stands but at the joint point (the articulated-body form of a ball joint):
// in the coordinates u' = (v_j, w) = X u, v_j = v + w x r the velocity of the joint point, J_kk = [E, 0]
// and D' = X^-T D X^-1 = [A, B'; B'^T, C'] with A = m E + A_folded, B' = A [r]x + B_folded, and C' the
// inertia about the joint point. Then K^-1 = A - P B'^T with P = B' C'^-1 (a Schur complement), so one 3x3
// inverse per body (C'^-1) gives K^-1 without inverting K, and what the solves need is C'^-1, P and K^-1
// (27 numbers per body). Where the joint point is far from the centre of mass against the body's own
// inertia, the Schur complement loses up to the factor m |r|^2 / I_min in relative precision: at most 180
// on the presets' bodies and 1.9e4 / 4.2e4 / 7.6e4 on generated mobiles of 127 / 1023 / 8191 components
// (seed 1; their light bars hanging off-centre), so K^-1 stays within ~1e-11 relative, far below what the
// Newton corrections and the joint tolerance need.
// The arrays are sized once; nothing allocates after construction.

#include <algorithm>
#include <cstdint>
#include <vector>


#include "aloft/state.hpp"
#include "common/cpu_dispatch.hpp"
#include "dynamics/small_matrix.hpp"

namespace aloft {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat63 = Eigen::Matrix<double, 6, 3>;

// The non-zero part of L^-1 [F; 0] for three wrench columns F applied at one or two bodies, where
// H = L D L^T is TreeSolver's factorization: only the body and joint nodes on the paths from those bodies
// to the base are non-zero (eliminating a node touches only its parent). Entries are stored per node,
// nodes in decreasing index order (tip to base). Because H^-1 = L^-T D^-1 L^-1 and, at the joint point,
//     g1^T D_i^-1 g2 - j1^T K_i^-1 j2 = h1^T C_i'^-1 h2      (j = -J_ii D_i^-1 g the joint-node entry),
// with h = g_torque - r x g_force the node's torque about its joint point, the pivots of the body and
// joint nodes together leave only the torques:
//     F1^T H^-1 F2 = sum over nodes on both paths of  h1^T C_i'^-1 h2,
// which TreeSolver::coupling() evaluates in O(common path length).
struct PathColumns {
  std::vector<int> node;        // body (and its parent joint) indices, decreasing
  std::vector<Mat3> h;          // the wrench gathered at the body, as torque about its joint point (N m s)
  std::vector<Mat3> e;          // C'^-1 h: the body's turn with its joint point held (rad/s)
  void clear() { node.clear(); h.clear(); e.clear(); }
};

class TreeSolver {
 public:
  explicit TreeSolver(const Model& model);

  // Form and factor H at the pose `state` (orientations give the world inertias and lever arms).
  void factor(const State& state);

  // The same at a pose given by every body's world rotation matrix (rotation[i] = R(q_i), body -> world;
  // index 0 unused) and the world lever arms r_k = R_k joint_in_child[k], s_k = R_p joint_in_parent[k],
  // as the caller already has them (the step computes them for its joint gaps; the arm arrays are taken
  // over by swapping: the caller gets the previous pose's arrays back, as scratch of the same size),
  // fused with a solve for the wrenches f and c = 0 (joint velocities held at zero), handing each body's
  // result to visit(i, u_i, lambda_i) as solve_visiting() does: the solve's tip-to-base sweep runs inside
  // the factorization's, on the blocks just formed, so the step's velocity projection costs one pass
  // over the bodies, not two. (With f_i = M_i u_i + impulse, u' is the velocity that is tangent to the
  // joints at the new pose: what RATTLE's projection needs.)
  // The wrenches are asked for as the sweep reaches each body, f_i = wrench(i, I_i), with I_i the body's
  // world inertia at the pose factored before (the step's start, where the caller's momenta I w are
  // taken), read just before the sweep overwrites it: no pass of the caller's own over the bodies to
  // form f, and no array of them (docs/performance.md, "Two passes fewer per step").
  template <class Wrench, class Visit>
  void factor_and_solve(const std::vector<Mat3>& rotation, std::vector<Vec3>& child_arm,
                        std::vector<Vec3>& parent_arm, Wrench&& wrench, Visit&& visit) {
    child_arm_.swap(child_arm);
    parent_arm_.swap(parent_arm);
    if (stack_folding_) {
      factor_blocks<true, true>(rotation, wrench);
    } else {
      factor_blocks<true, false>(rotation, wrench);
    }
    substitute(visit);
  }

  // How factor_and_solve() carries what a body's child joints fold into it (A', B, C' below, and the
  // solve's g) to the body: in per-body arrays, or on a stack as deep as the tree (nothing per body is
  // read or written for it). The stack needs the bodies in depth-first preorder (as compile() orders
  // them), so that the tip-to-base sweep finishes each subtree before it leaves it; it saves memory
  // traffic, which pays where the per-body arrays outgrow the caches, and costs a few per cent where they
  // do not (docs/performance.md, "Folding on a stack"). Default: the stack from kStackFoldingBodies
  // bodies on, when the order allows it. Results are the same bit for bit either way (same sums in the
  // same order). The plain factor() (the first step, or after a jump) always uses the arrays: a third
  // instantiation of the sweep made GCC stop inlining Eigen's 3x3 products in the others (+6%
  // instructions).
  static constexpr int kStackFoldingBodies = 4096;
  static bool stack_folding_possible(const std::vector<int>& parent);
  bool stack_folding() const { return stack_folding_; }
  // Choose explicitly (for tests and measurements); the stack only if stack_folding_possible().
  void set_stack_folding(bool on);

  // Solve with the last factorization. f: per body (force N, torque N m), world; c: per joint (3);
  // entries for index 0 are ignored. Writes u (per body; u[0] = 0) and, if given, lambda (per joint).
  // `lambda` may be the same array as `c`.
  void solve(const std::vector<Vec6>& f, const std::vector<Vec3>& c, std::vector<Vec6>& u,
             std::vector<Vec3>* lambda = nullptr);
  // solve() with c = 0 for wrenches f that are zero except at the bodies listed (repeats and 0 allowed):
  // the tip-to-base sweep visits only the bodies on their paths to the base (elsewhere g = 0, so y and the
  // joint term are 0); the base-to-tip sweep visits all, as it must (an impulse anywhere moves the whole
  // tree). The same result as solve(f, 0, u) (equal as numbers; a zero may differ in sign). For contact
  // impulses, which act on a few bodies.
  void solve_sparse(const std::vector<Vec6>& f, const std::vector<int>& bodies, std::vector<Vec6>& u);

  // solve() handing each body's result to visit(i, u_i, lambda_i) instead of storing it, for i = 1, 2,
  // ... (parents before children), so that a caller's own per-body pass can run inside the base-to-tip
  // sweep: one pass over the bodies instead of two, which matters when the arrays outgrow the caches.
  // `visit` may overwrite c[i] (c is read only by the tip-to-base sweep). solve_rows_visiting() is the
  // same with f = 0 (joint rows only), which saves the leaves' work.
  template <class Visit>
  void solve_visiting(const std::vector<Vec6>& f, const std::vector<Vec3>& c, Visit&& visit) {
    eliminate<true>(&f, c);
    substitute(visit);
  }
  template <class Visit>
  void solve_rows_visiting(const std::vector<Vec3>& c, Visit&& visit) {
    eliminate<false>(nullptr, c);
    substitute(visit);
  }

  // solve_rows_visiting() for joint rows that are zero except at the joints `listed` (each joint once;
  // joint i is body i's), visiting only the bodies the solve moves noticeably: the rest of the step's
  // Newton corrections, after the first has closed all but a few joints. The tip-to-base sweep runs
  // only along the listed joints' paths to the base (elsewhere g = 0, so y and the joint term are 0).
  // The base-to-tip sweep goes as solve_rows_visiting()'s, except at a body off those paths whose parent
  // moves its joint point by the velocity `parent_point` (the parent's u at the joint, world): if
  // skip(i, parent_point) says that is negligible, body i's whole subtree is left as it was (taken as
  // u = 0: its joints keep their gaps) and boundary(i) is called instead of visit (joint i is the one
  // the parent's motion changes). Needs the bodies in depth-first preorder, so that a subtree is a range
  // of indices (sparse_rows_possible()).
  bool sparse_rows_possible() const { return !subtree_end_.empty(); }
  template <class Skip, class Visit, class Boundary>
  void solve_listed_rows_visiting(const std::vector<Vec3>& c, const std::vector<int>& listed, Skip&& skip,
                                  Visit&& visit, Boundary&& boundary);
  // solve_sparse() (wrenches f at the `bodies` listed, c = 0) visiting only the bodies the solve moves
  // noticeably, as solve_listed_rows_visiting() does: a subtree off the wrenches' paths whose joint point
  // skip() finds negligible is left as it was (boundary(i) instead of visit). The joints `also` (each
  // joint i is body i's) are visited whatever skip() says: their bodies' paths are swept as the wrenches'
  // are (with no wrench of their own), so a caller that must look at them again gets them. The visited
  // bodies' u are those of solve_sparse() exactly. For the contact passes' impulses, which move the bodies
  // near the contacts and hardly any other. Needs sparse_rows_possible().
  template <class Skip, class Visit, class Boundary>
  void solve_sparse_visiting(const std::vector<Vec6>& f, const std::vector<int>& bodies, const std::vector<int>& also,
                             Skip&& skip, Visit&& visit, Boundary&& boundary);

  // Eliminate three wrench columns (world; rows force then torque) applied at `body_a` (wrench_a) and
  // `body_b` (wrench_b) along the paths to the base, with the last factorization. Either body may be 0
  // (the fixed component: its wrench is ignored) and they may be equal. O(path lengths), no allocation once
  // `out` has grown to the tree's depth.
  void eliminate_on_paths(int body_a, const Mat63& wrench_a, int body_b, const Mat63& wrench_b,
                          PathColumns& out) const;
  // F1^T H^-1 F2 (the 3x3 block of velocity responses) for two eliminated column sets: column j of x's
  // wrenches against column i of y's gives entry (j, i). Symmetric: coupling(y, x) = coupling(x, y)^T.
  // Summed over x's nodes (decreasing), y's looked up in `position_in_y` (indexed by body: the index of
  // that body in y.node, or -1 where y's path does not pass): O(x's path), for one y marked once against
  // many x, as the collision matrix's blocks are formed.
  static Mat3 coupling(const PathColumns& x, const PathColumns& y, const std::vector<int>& position_in_y);

  // World lever arms at the factored pose: centre of mass of body i -> joint i, and of parent -> joint i.
  const std::vector<Vec3>& child_arm() const { return child_arm_; }
  const std::vector<Vec3>& parent_arm() const { return parent_arm_; }
  // World inertia tensors and their inverses at the factored pose.
  const std::vector<Mat3>& world_inertia() const { return inertia_; }
  const std::vector<Mat3>& world_inverse_inertia() const { return inverse_inertia_; }
  // How many factorizations this solver has made: two results computed from it with the same count are
  // from the same factorization (what may be kept between the uses of one pose's, ContactResponse).
  std::uint64_t factorizations() const { return factorizations_; }

 private:
  // The factorization's tip-to-base sweep (defined below the class); with kEliminate also eliminate()
  // for the wrenches wrench(i, previous world inertia) and c = 0.
  template <bool kEliminate, bool kStack, class Wrench>
  void factor_blocks(const std::vector<Mat3>& rotation, Wrench& wrench);
  // factor()'s: no wrenches.
  struct NoWrench {
    Vec6 operator()(int, const Mat3&) const { return Vec6::Zero(); }
  };
  // The deepest the folding stack gets for this order of the bodies, or -1 if the order does not allow
  // it (see stack_folding_possible()).
  static int folding_stack_depth(const std::vector<int>& parent);
  // Tip to base: y_i and the joint terms a_i (with f = 0 if !kWithForces).
  template <bool kWithForces>
  void eliminate(const std::vector<Vec6>* f, const std::vector<Vec3>& c);
  // Body i's step of a tip-to-base sweep, for the wrench g gathered at it and its joint row c: y_[i] and
  // a_[i] (see eliminate()), and J_ip^T a_i added to the parent's g_.
  void eliminate_body(int i, const Vec6& g, const Vec3& c);
  // J_ip^T a = -(a, s_i x a) added to the parent's g_ (nothing for a joint to the fixed component).
  void fold_into_parent(int i, const Vec3& a);
  // Base to tip: the joint point's velocity v_j = c_i + (v_p + w_p x s_i) (the joint row), then
  // lambda_i = a_i + K_i^-1 (v_p + w_p x s_i), w_i = e_i - P_i^T v_j and v_i = v_j - w_i x r_i, handed to
  // visit. (y_[i] holds (c_i, e_i) from the tip-to-base sweep.) kSparse: y_ and a_ hold values only where
  // on_path_ is set (solve_sparse), and are taken as zero elsewhere.
  template <bool kSparse = false, class Visit>
  ALOFT_CPU_DISPATCH void substitute(Visit& visit) {
    const std::vector<int>& parent = model_.parent;
    for (int i = 1; i < n_; ++i) {
      const int p = parent[i];
      const bool given = !kSparse || on_path_[i];
      Vec3 joint_velocity = given ? Vec3(y_[i].head<3>()) : Vec3::Zero();
      Vec3 lam = given ? a_[i] : Vec3::Zero();
      const Vec3 turn = given ? Vec3(y_[i].tail<3>()) : Vec3::Zero();
      if (p != 0) {
        const Vec3 parent_point_velocity = u_[p].head<3>() + u_[p].tail<3>().cross(parent_arm_[i]);
        joint_velocity += parent_point_velocity;
        lam += k_inv_[i] * parent_point_velocity;
      }
      const Vec6 u = body_velocity(i, joint_velocity, turn);
      u_[i] = u;
      visit(i, u, lam);
    }
  }
  // Marks the bodies on the paths from `bodies` to the base (on_path_ = 1) and lists them in path_, tip to
  // base (the sparse solves' tip-to-base sweep).
  void mark_paths(const std::vector<int>& bodies);
  void mark_paths(const std::vector<int>& bodies, const std::vector<int>& also);  // both lists' paths
  // The base-to-tip sweep of the skipping solves, after a tip-to-base sweep along path_ (y_ and a_ hold
  // values only where on_path_ is set): a body off the paths whose joint point skip() finds negligible
  // has its subtree passed over (boundary(i)); every other body is visited. Clears on_path_ and path_.
  template <class Skip, class Visit, class Boundary>
  void substitute_skipping(Skip& skip, Visit& visit, Boundary& boundary);
  // Body i's u = (v_i, w_i) from its joint point's velocity v_j and its turn e_i with the joint point
  // held: w_i = e_i - P_i^T v_j, v_i = v_j - w_i x r_i (substitute's last step).
  [[gnu::always_inline]] Vec6 body_velocity(int i, const Vec3& joint_velocity, const Vec3& turn) const {
    Vec6 u;
    u.tail<3>() = turn - p_[i].transpose() * joint_velocity;
    u.head<3>() = joint_velocity - u.tail<3>().cross(child_arm_[i]);
    return u;
  }

  const Model& model_;
  int n_;
  std::vector<char> leaf_;          // body i has no child joint (fixed by the topology)
  std::vector<Vec3> inverse_moments_;     // 1 / principal moments
  std::uint64_t factorizations_ = 0;      // factor_blocks() calls so far
  std::vector<Mat3> rotation_scratch_;    // factor(State): rotation matrices of the orientations
  std::vector<Vec3> child_arm_;     // r_k, world
  std::vector<Vec3> parent_arm_;    // s_k, world
  std::vector<Mat3> inertia_;       // I_i, world
  std::vector<Mat3> inverse_inertia_;  // I_i^-1, world
  // D_i = [m E + A_f; B_f; B_f^T I_i + C_f] is accumulated from the children's joints in 3x3 blocks during
  // the tip-to-base sweep (A_f, B_f, C_f below, reset to zero once used), then factored at the joint point
  // (see the top of this file).
  std::vector<Mat3> sum_a_;         // sum K_c^-1                          (symmetric)
  std::vector<Mat3> sum_b_;         // - sum K_c^-1 [s_c]x
  std::vector<Mat3> sum_c_;         // sum -[s_c]x K_c^-1 [s_c]x           (symmetric)
  std::vector<Mat3> c_inv_;         // C'^-1: inverse inertia about the joint point, joints held (symmetric)
  std::vector<Mat3> p_;             // P = B' C'^-1
  std::vector<Mat3> k_inv_;         // K_i^-1 = A - P B'^T (symmetric)
  // The stack of stack_folding(): one entry per body whose children have begun to fold into it and that
  // is not done yet (bodies on the path from the sweep's position to the base), at most the tree's depth.
  struct Folded {
    int body;
    Mat3 a, b, c;  // as sum_a_, sum_b_, sum_c_
    Vec6 g;        // as g_ (the fused solve's)
  };
  bool stack_folding_ = false;
  std::vector<Folded> folded_;      // [1, top] in use during a sweep; sized to the deepest it gets
  std::vector<Vec6> g_;             // solve scratch: what the children's joints add to f (zero between solves)
  std::vector<Vec6> y_;             // solve scratch: (c_i, e_i = C'^-1 h_i), h_i = g's torque about the joint point
  std::vector<Vec3> a_;             // solve scratch: joint terms, a_i = K^-1 c_i + P h_i - g_i's force
  std::vector<Vec6> u_;             // solve scratch: the solution (u_[0] = 0: the fixed component)
  std::vector<char> on_path_;       // solve_sparse scratch: body i is on a listed body's path (0 between
                                    // solves; solve_listed_rows_visiting: 2 for the listed joints themselves)
  std::vector<int> path_;           // solve_sparse scratch: those bodies
  std::vector<int> subtree_end_;    // one past the last index of body i's subtree (bodies in depth-first
                                    // preorder); empty when the order is not that
};

template <class Skip, class Visit, class Boundary>
void TreeSolver::solve_listed_rows_visiting(const std::vector<Vec3>& c, const std::vector<int>& listed, Skip&& skip,
                                            Visit&& visit, Boundary&& boundary) {
  mark_paths(listed);
  for (const int b : listed) on_path_[b] = 2;
  for (const int i : path_) {  // eliminate<false> along the paths, c = 0 at the joints not listed
    const Vec6 g = g_[i];
    g_[i].setZero();
    eliminate_body(i, g, on_path_[i] == 2 ? c[i] : Vec3::Zero());
  }
  substitute_skipping(skip, visit, boundary);
}

template <class Skip, class Visit, class Boundary>
void TreeSolver::solve_sparse_visiting(const std::vector<Vec6>& f, const std::vector<int>& bodies,
                                       const std::vector<int>& also, Skip&& skip, Visit&& visit, Boundary&& boundary) {
  mark_paths(bodies, also);
  for (const int i : path_) {  // eliminate<true> along the paths, c = 0 (f is zero off `bodies`)
    const Vec6 g = g_[i] + f[i];
    g_[i].setZero();
    eliminate_body(i, g, Vec3::Zero());
  }
  substitute_skipping(skip, visit, boundary);
}

template <class Skip, class Visit, class Boundary>
void TreeSolver::substitute_skipping(Skip& skip, Visit& visit, Boundary& boundary) {
  const std::vector<int>& parent = model_.parent;
  for (int i = 1; i < n_;) {
    const int p = parent[i];
    const bool given = on_path_[i] != 0;
    Vec3 joint_velocity = given ? Vec3(y_[i].head<3>()) : Vec3::Zero();
    Vec3 lam = given ? a_[i] : Vec3::Zero();
    const Vec3 turn = given ? Vec3(y_[i].tail<3>()) : Vec3::Zero();
    // (p was visited: a skipped body's subtree is passed over whole, and the fixed component does not move.)
    const Vec3 parent_point_velocity =
        p != 0 ? Vec3(u_[p].head<3>() + u_[p].tail<3>().cross(parent_arm_[i])) : Vec3::Zero();
    if (!given && skip(i, parent_point_velocity)) {
      boundary(i);
      i = subtree_end_[i];
      continue;
    }
    joint_velocity += parent_point_velocity;
    lam += k_inv_[i] * parent_point_velocity;
    const Vec6 u = body_velocity(i, joint_velocity, turn);
    u_[i] = u;
    visit(i, u, lam);
    ++i;
  }
  for (const int i : path_) on_path_[i] = 0;
  path_.clear();
}

// The symmetric KKT matrix H = [M J^T; J 0] written out densely (moving bodies 1..n-1 as 6-blocks, then
// joints as 3-blocks), for tests: H [u; -lambda] = [f; c] is the system TreeSolver solves.
Eigen::MatrixXd dense_kkt_matrix(const Model& model, const State& state);

// One tip-to-base sweep: body i's own inertia, then D_i from what its children's joints folded in
// (children have larger indices, so they are done), factored at the joint point (see the top of this
// file), then joint i eliminated into the parent: A^T K_i^-1 A with A = [E, -[s_i]x] is
// [K^-1, -K^-1 [s]x; [s]x K^-1, -[s]x K^-1 [s]x] (K^-1 symmetric).
// With kEliminate, body i's step of eliminate() (c_i = 0) follows at once, on the blocks still at hand.
// With kStack, the children's folds are carried on folded_ instead of sum_a_, sum_b_, sum_c_ and g_.
template <bool kEliminate, bool kStack, class Wrench>
ALOFT_CPU_DISPATCH void TreeSolver::factor_blocks(const std::vector<Mat3>& rotation, Wrench& wrench) {
  ++factorizations_;
  const std::vector<int>& parent = model_.parent;
  int top = 0;  // kStack: folded_[1..top] in use
  for (int i = n_ - 1; i >= 1; --i) {
    // kStack: what i's children folded into it, on top of the stack (an interior body's always is).
    const Folded* mine = kStack && top > 0 && folded_[top].body == i ? &folded_[top] : nullptr;
    const Mat3 inertia = rotate_diagonal(rotation[i], model_.principal_moments[i]);
    Vec6 g;  // with kEliminate: the wrench gathered at body i (its own and its child joints')
    if constexpr (kEliminate) {
      g = wrench(i, inertia_[i]);  // still the previous pose's inertia
      if constexpr (kStack) {
        if (mine) g += mine->g;
      } else {
        g += g_[i];
        g_[i].setZero();
      }
    }
    inertia_[i] = inertia;
    inverse_inertia_[i] = rotate_diagonal(rotation[i], inverse_moments_[i]);
    const Vec3& r = child_arm_[i];
    const double m = model_.mass[i];
    // D' at the joint point: A = m E + A_f, B' = A [r]x + B_f, C' = I + C_f + B_f^T [r]x - [r]x B'.
    Mat3 c_inv, p, k_inv;
    if (leaf_[i]) {
      // A = m E, B' = m [r]x, C' = I + m [r]x^T [r]x = I + m (|r|^2 E - r r^T) (the parallel-axis theorem),
      // P = m [r]x C'^-1, K^-1 = m E - P B'^T = m E + m P [r]x.
      Mat3 c_joint = inertia;
      c_joint.noalias() -= m * (r * r.transpose());
      c_joint.diagonal().array() += m * r.squaredNorm();
      c_inv = symmetric_inverse(c_joint);
      p = m * skew_times(r, c_inv);
      k_inv = m * times_skew_symmetric(p, r);
      k_inv.diagonal().array() += m;
    } else {
      const Mat3* folded_a = &sum_a_[i];
      const Mat3* folded_b = &sum_b_[i];
      const Mat3* folded_c = &sum_c_[i];
      if constexpr (kStack) folded_a = &mine->a, folded_b = &mine->b, folded_c = &mine->c;
      Mat3 a = *folded_a;
      a.diagonal().array() += m;
      const Mat3& b = *folded_b;
      const Mat3 b_joint = times_skew(a, r) + b;
      const Mat3 c_joint = (inertia + *folded_c) + times_skew(b.transpose(), r) - skew_times(r, b_joint);
      c_inv = symmetric_inverse(c_joint);
      p.noalias() = b_joint * c_inv;
      k_inv = minus_symmetric_product(a, p, b_joint);
      if constexpr (kStack) {
        --top;  // mine is done with (its entry may be reused below)
      } else {
        sum_a_[i].setZero();
        sum_b_[i].setZero();
        sum_c_[i].setZero();
      }
    }
    c_inv_[i] = c_inv;
    p_[i] = p;
    k_inv_[i] = k_inv;
    const int pa = parent[i];
    Vec3 a;
    if constexpr (kEliminate) {
      // c_i = 0: h = g's torque about the joint point, e = C'^-1 h, a = P h - g's force.
      const Vec3 h = g.tail<3>() - r.cross(g.head<3>());
      y_[i].head<3>().setZero();
      y_[i].tail<3>() = c_inv * h;
      a = p * h - g.head<3>();
      a_[i] = a;
    }
    if (pa != 0) {
      const Mat3 k_sx = times_skew(k_inv, parent_arm_[i]);
      if constexpr (kStack) {
        if (top > 0 && folded_[top].body == pa) {  // a sibling began pa's entry
          Folded& into = folded_[top];
          into.a += k_inv;
          into.b -= k_sx;
          into.c -= skew_times_symmetric(parent_arm_[i], k_sx);
          if constexpr (kEliminate) {
            into.g.head<3>() -= a;
            into.g.tail<3>() -= parent_arm_[i].cross(a);
          }
        } else {  // the first of pa's children the sweep reaches: 0 - x, as the arrays' sums start at 0
          Folded& into = folded_[++top];
          into.body = pa;
          into.a = k_inv;
          into.b = -k_sx;
          into.c = -skew_times_symmetric(parent_arm_[i], k_sx);
          if constexpr (kEliminate) {
            into.g.head<3>() = -a;
            into.g.tail<3>() = -parent_arm_[i].cross(a);
          } else {
            into.g.setZero();
          }
        }
      } else {
        sum_a_[pa] += k_inv;
        sum_b_[pa] -= k_sx;
        sum_c_[pa] -= skew_times_symmetric(parent_arm_[i], k_sx);
        if constexpr (kEliminate) {
          g_[pa].head<3>() -= a;
          g_[pa].tail<3>() -= parent_arm_[i].cross(a);
        }
      }
    }
  }
}

}  // namespace aloft
