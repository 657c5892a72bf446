#include "dynamics/tree_solver.hpp"

#include <Eigen/Dense>

namespace aloft {

namespace {

// World inertia R diag(I) R^T of a body with principal moments I and orientation q, and its inverse
// R diag(1/I) R^T.
void world_inertia_pair(const Quat& q, const Vec3& moments, Mat3& inertia, Mat3& inverse) {
  const Mat3 r = q.toRotationMatrix();
  inertia = r * moments.asDiagonal() * r.transpose();
  inverse = r * moments.cwiseInverse().asDiagonal() * r.transpose();
}

}  // namespace

TreeSolver::TreeSolver(const Model& model)
    : model_(model),
      n_(model.count),
      child_arm_(n_, Vec3::Zero()),
      parent_arm_(n_, Vec3::Zero()),
      inertia_(n_, Mat3::Zero()),
      inverse_inertia_(n_, Mat3::Zero()),
      block_a_(n_, Mat3::Zero()),
      block_b_(n_, Mat3::Zero()),
      block_c_(n_, Mat3::Zero()),
      has_children_(n_, 0),
      a_inv_(n_, Mat3::Zero()),
      t_(n_, Mat3::Zero()),
      s_inv_(n_, Mat3::Zero()),
      w_(n_, Mat63::Zero()),
      k_inv_(n_, Mat3::Zero()),
      g_(n_, Vec6::Zero()),
      y_(n_, Vec6::Zero()),
      a_(n_, Vec3::Zero()) {}

void TreeSolver::factor(const State& state) {
  const std::vector<int>& parent = model_.parent;

  // Base to tip: world inertias, lever arms, and each body's own mass block M_i = diag(m E, I).
  for (int i = 1; i < n_; ++i) {
    const int p = parent[i];
    world_inertia_pair(state.orientation[i], model_.principal_moments[i], inertia_[i], inverse_inertia_[i]);
    child_arm_[i] = state.orientation[i] * model_.joint_in_child[i];
    parent_arm_[i] = state.orientation[p] * model_.joint_in_parent[i];
    block_a_[i] = model_.mass[i] * Mat3::Identity();
    block_b_[i].setZero();
    block_c_[i] = inertia_[i];
    has_children_[i] = 0;
  }

  // Tip to base: factor D_i, eliminate joint i, fold A^T K_i^-1 A (A = [E, -[s_i]x]) into the parent.
  for (int i = n_ - 1; i >= 1; --i) {
    const Mat3 rx = skew(child_arm_[i]);
    Mat3 k;
    if (!has_children_[i]) {
      // A leaf: D_i = M_i = diag(m E, I), so W_i = [E/m; I^-1 [r]x] and K_i = E/m - [r]x I^-1 [r]x.
      a_inv_[i] = Mat3::Identity() / model_.mass[i];
      t_[i].setZero();
      s_inv_[i] = inverse_inertia_[i];
      const Mat3 w_bottom = inverse_inertia_[i] * rx;
      w_[i].topRows<3>() = a_inv_[i];
      w_[i].bottomRows<3>() = w_bottom;
      k = a_inv_[i] - rx * w_bottom;
    } else {
      // W_i = D^-1 [E; [r]x]: with Z = [r]x - T^T, W_bottom = S^-1 Z, W_top = A^-1 - T W_bottom, and
      // K_i = W_top - [r]x W_bottom = A^-1 + Z^T S^-1 Z.
      a_inv_[i] = block_a_[i].inverse();
      t_[i] = a_inv_[i] * block_b_[i];
      s_inv_[i] = (block_c_[i] - block_b_[i].transpose() * t_[i]).inverse();
      const Mat3 z = rx - t_[i].transpose();
      const Mat3 w_bottom = s_inv_[i] * z;
      w_[i].topRows<3>() = a_inv_[i] - t_[i] * w_bottom;
      w_[i].bottomRows<3>() = w_bottom;
      k = a_inv_[i] + z.transpose() * w_bottom;
    }
    const Mat3 k_inv = k.inverse();
    k_inv_[i] = k_inv;
    const int p = parent[i];
    if (p != 0) {
      // A^T K^-1 A = [K^-1, -K^-1 [s]x; [s]x K^-1, -[s]x K^-1 [s]x] (K^-1 symmetric).
      const Mat3 sx = skew(parent_arm_[i]);
      const Mat3 k_sx = k_inv * sx;
      block_a_[p] += k_inv;
      block_b_[p] -= k_sx;
      block_c_[p] -= sx * k_sx;
      has_children_[p] = 1;
    }
  }
}

void TreeSolver::solve(const std::vector<Vec6>& f, const std::vector<Vec3>& c, std::vector<Vec6>& u,
                       std::vector<Vec3>* lambda) {
  const std::vector<int>& parent = model_.parent;
  for (int i = 1; i < n_; ++i) g_[i] = f[i];

  // Tip to base: y_i = D_i^-1 g_i, a_i = K_i^-1 (c_i - J_ii y_i), and g_p += J_ip^T a_i.
  for (int i = n_ - 1; i >= 1; --i) {
    const Vec3 g1 = g_[i].head<3>();
    const Vec3 y2 = s_inv_[i] * (g_[i].tail<3>() - t_[i].transpose() * g1);
    y_[i].head<3>() = a_inv_[i] * g1 - t_[i] * y2;
    y_[i].tail<3>() = y2;
    const Vec3 r = child_arm_[i];
    const Vec3 j_y = y_[i].head<3>() + y_[i].tail<3>().cross(r);  // v + w x r
    a_[i] = k_inv_[i] * (c[i] - j_y);
    const int p = parent[i];
    if (p != 0) {
      g_[p].head<3>() -= a_[i];
      g_[p].tail<3>() -= parent_arm_[i].cross(a_[i]);
    }
  }

  // Base to tip: lambda_i = a_i - K_i^-1 J_ip u_p, u_i = y_i + W_i lambda_i.
  u[0].setZero();
  for (int i = 1; i < n_; ++i) {
    const int p = parent[i];
    Vec3 lam = a_[i];
    if (p != 0) {
      const Vec3 parent_point_velocity = u[p].head<3>() + u[p].tail<3>().cross(parent_arm_[i]);
      lam += k_inv_[i] * parent_point_velocity;  // J_ip u_p = -(v_p + w_p x s_i)
    }
    u[i] = y_[i] + w_[i] * lam;
    if (lambda) (*lambda)[i] = lam;
  }
}

Eigen::MatrixXd dense_kkt_matrix(const Model& model, const State& state) {
  const int m = model.count - 1;  // moving bodies 1..n-1 -> blocks 0..m-1
  const int size = 9 * m;
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(size, size);
  for (int i = 1; i < model.count; ++i) {
    const int b = 6 * (i - 1);
    h.block<3, 3>(b, b) = model.mass[i] * Mat3::Identity();
    Mat3 inertia, inverse;
    world_inertia_pair(state.orientation[i], model.principal_moments[i], inertia, inverse);
    h.block<3, 3>(b + 3, b + 3) = inertia;
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
