#include "dynamics/tree_solver.hpp"

#include <Eigen/Dense>
#include <algorithm>

namespace aloft {

TreeSolver::TreeSolver(const Model& model)
    : model_(model),
      n_(model.count),
      leaf_(n_, 1),
      inverse_moments_(n_, Vec3::Zero()),
      rotation_scratch_(n_, Mat3::Identity()),
      child_arm_(n_, Vec3::Zero()),
      parent_arm_(n_, Vec3::Zero()),
      inertia_(n_, Mat3::Zero()),
      inverse_inertia_(n_, Mat3::Zero()),
      sum_a_(n_, Mat3::Zero()),
      sum_b_(n_, Mat3::Zero()),
      sum_c_(n_, Mat3::Zero()),
      c_inv_(n_, Mat3::Zero()),
      p_(n_, Mat3::Zero()),
      k_inv_(n_, Mat3::Zero()),
      g_(n_, Vec6::Zero()),
      y_(n_, Vec6::Zero()),
      a_(n_, Vec3::Zero()),
      u_(n_, Vec6::Zero()),
      on_path_(n_, 0) {
  for (int i = 1; i < n_; ++i) {
    if (model.parent[i] > 0) leaf_[model.parent[i]] = 0;
    inverse_moments_[i] = model.principal_moments[i].cwiseInverse();
  }
  path_.reserve(n_);  // solve_sparse: at most every body (nothing allocates after construction)
  // Subtree ranges, if the bodies are in depth-first preorder: every body lies within its parent's range
  // and its own range within it (then each range holds exactly its subtree).
  std::vector<int> size(n_, 1);
  for (int i = n_ - 1; i >= 1; --i)
    if (model.parent[i] > 0) size[model.parent[i]] += size[i];
  bool preorder = true;
  for (int i = 1; i < n_ && preorder; ++i) {
    const int p = model.parent[i];
    preorder = p == 0 || (p < i && i + size[i] <= p + size[p]);
  }
  if (preorder) {
    subtree_end_.resize(n_);
    for (int i = 0; i < n_; ++i) subtree_end_[i] = i + size[i];
  }
  set_stack_folding(n_ >= kStackFoldingBodies);
}

// Replays the sweep's stack discipline: going tip to base, a body's children must all have been folded
// into the stack's top entry when the sweep reaches it, and a body's parent is either the top entry or
// not on the stack at all. Returns the deepest the stack gets, or -1 if the order does not allow it.
int TreeSolver::folding_stack_depth(const std::vector<int>& parent) {
  const int n = static_cast<int>(parent.size());
  std::vector<int> stack;
  std::vector<char> on_stack(n, 0);
  int deepest = 0;
  for (int i = n - 1; i >= 1; --i) {
    if (on_stack[i]) {
      if (stack.back() != i) return -1;
      stack.pop_back();
      on_stack[i] = 0;
    }
    const int p = parent[i];
    if (p == 0 || (!stack.empty() && stack.back() == p)) continue;
    if (on_stack[p]) return -1;
    stack.push_back(p);
    on_stack[p] = 1;
    deepest = std::max(deepest, static_cast<int>(stack.size()));
  }
  return stack.empty() ? deepest : -1;
}

bool TreeSolver::stack_folding_possible(const std::vector<int>& parent) { return folding_stack_depth(parent) >= 0; }

void TreeSolver::set_stack_folding(bool on) {
  const int depth = on ? folding_stack_depth(model_.parent) : -1;
  stack_folding_ = depth >= 0;
  // Entries 1..depth (the sweep's top starts at 0); sized once, never shrunk.
  if (stack_folding_ && static_cast<int>(folded_.size()) < depth + 1) folded_.resize(depth + 1);
}

void TreeSolver::factor(const State& state) {
  const std::vector<int>& parent = model_.parent;
  rotation_scratch_[0] = state.orientation[0].toRotationMatrix();
  for (int i = 1; i < n_; ++i) rotation_scratch_[i] = state.orientation[i].toRotationMatrix();
  for (int i = 1; i < n_; ++i) {
    child_arm_[i] = rotation_scratch_[i] * model_.joint_in_child[i];
    parent_arm_[i] = rotation_scratch_[parent[i]] * model_.joint_in_parent[i];
  }
  // The arrays: a plain factorization is rare (the first step, a jump; see set_stack_folding()).
  NoWrench none;
  factor_blocks<false, false>(rotation_scratch_, none);
}

inline void TreeSolver::fold_into_parent(int i, const Vec3& a) {
  const int p = model_.parent[i];
  if (p == 0) return;
  g_[p].head<3>() -= a;
  g_[p].tail<3>() -= parent_arm_[i].cross(a);
}

inline void TreeSolver::eliminate_body(int i, const Vec6& g, const Vec3& c) {
  const Vec3 h = g.tail<3>() - child_arm_[i].cross(g.head<3>());
  y_[i].head<3>() = c;
  y_[i].tail<3>() = c_inv_[i] * h;
  Vec3 a = k_inv_[i] * c;
  a += p_[i] * h - g.head<3>();
  a_[i] = a;
  fold_into_parent(i, a);
}

// Tip to base: g_i = f_i + what the child joints added, h_i = g_i's torque about the joint point,
// y_i = (c_i, C'^-1 h_i), a_i = K_i^-1 c_i + P_i h_i - g_i's force, and g_p += J_ip^T a_i. (g_ is zero
// between solves: each entry is reset once read.)
template <bool kWithForces>
void TreeSolver::eliminate(const std::vector<Vec6>* f, const std::vector<Vec3>& c) {
  for (int i = n_ - 1; i >= 1; --i) {
    if (leaf_[i] && !kWithForces) {  // a leaf with no applied wrench: g = 0
      y_[i].head<3>() = c[i];
      y_[i].tail<3>().setZero();
      a_[i] = k_inv_[i] * c[i];
      fold_into_parent(i, a_[i]);
    } else {
      Vec6 g = g_[i];
      g_[i].setZero();
      if constexpr (kWithForces) g += (*f)[i];
      eliminate_body(i, g, c[i]);
    }
  }
}

template void TreeSolver::eliminate<true>(const std::vector<Vec6>*, const std::vector<Vec3>&);
template void TreeSolver::eliminate<false>(const std::vector<Vec6>*, const std::vector<Vec3>&);

void TreeSolver::solve(const std::vector<Vec6>& f, const std::vector<Vec3>& c, std::vector<Vec6>& u,
                       std::vector<Vec3>* lambda) {
  u[0].setZero();
  if (lambda) {
    solve_visiting(f, c, [&](int i, const Vec6& ui, const Vec3& lam) { u[i] = ui, (*lambda)[i] = lam; });
  } else {
    solve_visiting(f, c, [&](int i, const Vec6& ui, const Vec3&) { u[i] = ui; });
  }
}

void TreeSolver::mark_paths(const std::vector<int>& bodies) {
  const std::vector<int>& parent = model_.parent;
  for (int b : bodies)
    for (int i = b; i > 0 && !on_path_[i]; i = parent[i]) {
      on_path_[i] = 1;
      path_.push_back(i);
    }
  std::sort(path_.begin(), path_.end(), [](int x, int y) { return x > y; });  // tip to base
}

void TreeSolver::mark_paths(const std::vector<int>& bodies, const std::vector<int>& also) {
  const std::vector<int>& parent = model_.parent;
  for (int b : also)
    for (int i = b; i > 0 && !on_path_[i]; i = parent[i]) {
      on_path_[i] = 1;
      path_.push_back(i);
    }
  mark_paths(bodies);  // and sorts them all
}

void TreeSolver::solve_sparse(const std::vector<Vec6>& f, const std::vector<int>& bodies, std::vector<Vec6>& u) {
  mark_paths(bodies);
  for (const int i : path_) {  // eliminate<true> with c = 0
    const Vec6 g = g_[i] + f[i];
    g_[i].setZero();
    eliminate_body(i, g, Vec3::Zero());
  }
  u[0].setZero();
  const auto store = [&](int i, const Vec6& ui, const Vec3&) { u[i] = ui; };
  substitute<true>(store);
  for (const int i : path_) on_path_[i] = 0;
  path_.clear();
}

void TreeSolver::eliminate_on_paths(int body_a, const Mat63& wrench_a, int body_b, const Mat63& wrench_b,
                                    PathColumns& out) const {
  const std::vector<int>& parent = model_.parent;
  out.clear();
  // Walk both paths to the base together, always taking the larger index (children have larger indices
  // than their parents, so every node is reached after all of its path-children). `pending_*` is the wrench
  // carried to the next node of each path.
  int x = body_a, z = body_b;
  Mat63 pending_x = wrench_a, pending_z = wrench_b;
  while (x > 0 || z > 0) {
    const int i = std::max(x, z);
    Mat63 g = Mat63::Zero();
    if (x == i) g += pending_x;
    if (z == i) g += pending_z;
    // The torque about the joint point, h = g_torque - [r]x g_force, its turn e = C'^-1 h, and the joint
    // node's entry a = P h - g_force (c = 0), as in eliminate().
    const Mat3 h = g.bottomRows<3>() - skew_times(child_arm_[i], g.topRows<3>());
    const Mat3 a = p_[i] * h - g.topRows<3>();
    out.node.push_back(i);
    out.h.push_back(h);
    out.e.push_back(c_inv_[i] * h);
    // Eliminating joint i adds J_ip^T a = [-a; -[s_i]x a] to the parent's entry.
    const int p = parent[i];
    Mat63 carried;
    carried.topRows<3>() = -a;
    carried.bottomRows<3>() = -skew_times(parent_arm_[i], a);
    const bool merged = x == i && z == i;  // both paths passed through i: carry the sum once, on x
    if (x == i) {
      x = p;
      pending_x = carried;
    }
    if (z == i) {
      z = p;
      pending_z = merged ? Mat63::Zero() : carried;
    }
  }
}

Mat3 TreeSolver::coupling(const PathColumns& x, const PathColumns& y, const std::vector<int>& position_in_y) {
  Mat3 out = Mat3::Zero();
  for (std::size_t p = 0; p < x.node.size(); ++p) {
    const int q = position_in_y[static_cast<std::size_t>(x.node[p])];
    if (q >= 0) out.noalias() += x.h[p].transpose() * y.e[static_cast<std::size_t>(q)];
  }
  return out;
}

Eigen::MatrixXd dense_kkt_matrix(const Model& model, const State& state) {
  const int m = model.count - 1;  // moving bodies 1..n-1 -> blocks 0..m-1
  const int size = 9 * m;
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(size, size);
  for (int i = 1; i < model.count; ++i) {
    const int b = 6 * (i - 1);
    h.block<3, 3>(b, b) = model.mass[i] * Mat3::Identity();
    h.block<3, 3>(b + 3, b + 3) = rotate_diagonal(state.orientation[i].toRotationMatrix(), model.principal_moments[i]);
  }
  for (int k = 1; k < model.count; ++k) {
    const int row = 6 * m + 3 * (k - 1);
    const Vec3 r = state.orientation[k] * model.joint_in_child[k];
    Eigen::Matrix<double, 3, 6> jc;
    jc << Mat3::Identity(), -skew(r);
    h.block<3, 6>(row, 6 * (k - 1)) = jc;
    h.block<6, 3>(6 * (k - 1), row) = jc.transpose();
    const int p = model.parent[k];
    if (p != 0) {
      const Vec3 s = state.orientation[p] * model.joint_in_parent[k];
      Eigen::Matrix<double, 3, 6> jp;
      jp << -Mat3::Identity(), skew(s);
      h.block<3, 6>(row, 6 * (p - 1)) = jp;
      h.block<6, 3>(6 * (p - 1), row) = jp.transpose();
    }
  }
  return h;
}

}  // namespace aloft
