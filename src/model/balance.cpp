#include "model/balance.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include <Eigen/Dense>

namespace aloft::internal {

namespace {

// Projection onto the horizontal plane (perpendicular to gravity): the lever arms gravity acts on.
Mat3 horizontal_projector(const Vec3& gravity) {
  const double g = gravity.norm();
  if (g == 0) return Mat3::Zero();  // no gravity: no arm, every pose is an equilibrium
  const Vec3 down = gravity / g;
  return Mat3::Identity() - down * down.transpose();
}

std::string format_point(const Vec3& p) {
  std::ostringstream s;
  s << std::setprecision(9) << "[" << p.x() << ", " << p.y() << ", " << p.z() << "]";
  return s.str();
}

std::string format_mm(double metres) {
  std::ostringstream s;
  s << std::setprecision(3) << metres * 1000 << " mm";
  return s.str();
}

// Subtree masses and centres of mass, tip to base.
void subtree_sums(const BalanceInput& in, const std::vector<double>& mass, std::vector<double>& sub_mass,
                  std::vector<Vec3>& sub_center) {
  const int n = static_cast<int>(in.parent.size());
  std::vector<Vec3> moment(n);
  sub_mass.assign(n, 0);
  for (int i = 0; i < n; ++i) {
    sub_mass[i] = mass[i];
    moment[i] = mass[i] * in.center[i];
  }
  for (int i = n - 1; i >= 1; --i) {
    const int p = in.parent[i];
    if (p < 0) continue;
    sub_mass[p] += sub_mass[i];
    moment[p] += moment[i];
  }
  sub_center.resize(n);
  for (int i = 0; i < n; ++i) sub_center[i] = sub_mass[i] > 0 ? Vec3(moment[i] / sub_mass[i]) : in.center[i];
}

// Mode Mass, one component: scale factors x = (own, child_1..child_k) closest to all-ones with
// B x = 0, where B's columns are the horizontal moments about the joint of the component's own mass
// and of each child subtree (whose centre lies below the child's joint, the children being balanced
// first). x = 1 - B^+ B 1 (least-squares projection onto the null space of B).
Eigen::VectorXd balance_factors(const Mat3& horizontal, double own_mass, const Vec3& own_center,
                                const Vec3& joint, const std::vector<double>& child_mass,
                                const std::vector<Vec3>& child_joint) {
  const int k = static_cast<int>(child_mass.size());
  Eigen::MatrixXd b(3, k + 1);
  // Lever arms shorter than kBalanceTolerance count as zero (the point is on the vertical).
  auto column = [&](double m, const Vec3& point) {
    const Vec3 arm = horizontal * (point - joint);
    return Vec3(arm.norm() < kBalanceTolerance ? Vec3::Zero() : Vec3(m * arm));
  };
  b.col(0) = column(own_mass, own_center);
  for (int j = 0; j < k; ++j) b.col(j + 1) = column(child_mass[j], child_joint[j]);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(k + 1);
  if (b.norm() == 0) return ones;
  // Rank decision: directions closer than 1e-6 (relative) count as the same line. Drawn coordinates
  // carry ~1e-9 m of rounding on ~0.1 m arms, so pieces drawn in one vertical plane must come out
  // rank one; the horizontal imbalance this tolerates is ~1e-6 x 0.1 m, far below kBalanceTolerance.
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(b.rows(), b.cols());
  cod.setThreshold(1e-6);
  cod.compute(b);
  return ones - cod.pseudoInverse() * (b * ones);
}

}  // namespace

double max_imbalance(const BalanceInput& in, const std::vector<double>& mass, const std::vector<Vec3>& joint) {
  std::vector<double> sub_mass;
  std::vector<Vec3> sub_center;
  subtree_sums(in, mass, sub_mass, sub_center);
  const Mat3 horizontal = horizontal_projector(in.gravity);
  double worst = 0;
  for (int i = 1; i < static_cast<int>(in.parent.size()); ++i)
    worst = std::max(worst, (horizontal * (sub_center[i] - joint[i])).norm());
  return worst;
}

BalanceResult balance(const BalanceInput& in, BalanceMode mode, std::optional<double> total_mass,
                      const std::function<void(const std::string&, const std::string&)>& fail) {
  const int n = static_cast<int>(in.parent.size());
  const Mat3 horizontal = horizontal_projector(in.gravity);
  BalanceResult out;
  out.mass_scale.assign(n, 1.0);
  out.joint = in.joint;

  if (mode == BalanceMode::Mass) {
    // Tip to base: factors per component; sub_mass[i] = balanced subtree mass at the child's own scale.
    std::vector<double> own_factor(n, 1.0), child_factor(n, 1.0), sub_mass(n, 0.0);
    for (int i = n - 1; i >= 1; --i) {
      std::vector<double> cm;
      std::vector<Vec3> cj;
      for (int c : in.children[i]) {
        cm.push_back(sub_mass[c]);
        cj.push_back(in.joint[c]);
      }
      const Eigen::VectorXd x = balance_factors(horizontal, in.base_mass[i], in.center[i], in.joint[i], cm, cj);
      // Positive masses are required; factors below 1e-6 would mean a practically massless part.
      const double smallest = x.minCoeff();
      if (!(smallest > 1e-6)) {
        std::ostringstream why;
        if (in.children[i].empty()) {
          const Vec3 arm = horizontal * (in.center[i] - in.joint[i]);
          const Vec3 above = in.joint[i] + arm;  // the joint moved horizontally over the centre of mass
          why << "cannot balance: nothing hangs from '" << in.names[i] << "' and its centre of mass "
              << format_point(in.center[i]) << " is " << format_mm(arm.norm())
              << " from the vertical through its joint; put the joint at " << format_point(above)
              << " (above the centre of mass) or use balance mode \"joints\"";
        } else {
          // The factors closest to all ones: none negative means a balance exists, but one part would weigh
          // less than a millionth of what its shapes and density give (the parts' masses differ too much
          // for their arms); a negative one means the parts do not lie on both sides of the joint.
          const bool too_unequal = smallest > 0;
          why << (too_unequal ? "cannot balance with masses within a factor 1e6 of the drawn ones: around its joint "
                              : "cannot balance with positive masses: around its joint ")
              << format_point(in.joint[i]) << ", the weight of ";
          // The parts whose factor is too small (too unequal: the smallest alone, with its factor).
          const char* separator = "";
          for (Eigen::Index j = 0; j < x.size(); ++j) {
            if (x(j) > 1e-6 || (too_unequal && x(j) != smallest)) continue;
            if (j == 0) {
              why << separator << "'" << in.names[i] << "' itself";
            } else {
              const int child = in.children[i][static_cast<std::size_t>(j - 1)];
              why << separator << "'" << in.names[child] << "'"
                  << (in.children[child].empty() ? "" : " with what hangs from it");
            }
            separator = " and of ";
            if (too_unequal) break;
          }
          if (too_unequal)
            why << " would have to be " << std::setprecision(3) << 1 / smallest
                << " times lighter than drawn: the parts' masses are too unequal for the arms they hang from; "
                   "move the joint towards the heavier side, or use balance mode \"joints\"";
          else
            why << " would have to be zero or negative: the pieces hanging from it do not lie on both sides "
                   "of the joint; move the joint between them, or use balance mode \"joints\"";
        }
        fail(in.paths[i] + ".joint", why.str());
      }
      own_factor[i] = x(0);
      sub_mass[i] = x(0) * in.base_mass[i];
      for (size_t j = 0; j < in.children[i].size(); ++j) {
        const int c = in.children[i][j];
        child_factor[c] = x(j + 1);
        sub_mass[i] += x(j + 1) * sub_mass[c];
      }
    }
    // Base to tip: a component's scale is its own factor times the product of child factors above it.
    std::vector<double> subtree_scale(n, 1.0);
    for (int i = 1; i < n; ++i) {
      const int p = in.parent[i];
      subtree_scale[i] = (p == 0 ? 1.0 : subtree_scale[p]) * child_factor[i];
      out.mass_scale[i] = subtree_scale[i] * own_factor[i];
    }
    out.notes.push_back("masses derived so that the designed pose is an equilibrium");
  } else if (mode == BalanceMode::Joints) {
    std::vector<double> sub_mass;
    std::vector<Vec3> sub_center;
    subtree_sums(in, in.base_mass, sub_mass, sub_center);
    int moved = 0;
    for (int i = 1; i < n; ++i) {
      const Vec3 shift = horizontal * (sub_center[i] - in.joint[i]);
      if (shift.norm() >= kBalanceTolerance) ++moved;
      out.joint[i] = in.joint[i] + shift;
    }
    out.notes.push_back("hanging points moved above the centres of mass they carry (" + std::to_string(moved) +
                        " moved)");
  } else {
    out.notes.push_back("masses from densities; the designed pose need not be an equilibrium");
  }

  // Scale to the requested total mass of the moving components.
  if (total_mass) {
    double sum = 0;
    for (int i = 1; i < n; ++i) sum += out.mass_scale[i] * in.base_mass[i];
    if (sum > 0) {
      const double k = *total_mass / sum;
      for (int i = 1; i < n; ++i) out.mass_scale[i] *= k;
    }
  }

  std::vector<double> mass(n);
  for (int i = 0; i < n; ++i) mass[i] = out.mass_scale[i] * in.base_mass[i];
  out.max_imbalance = max_imbalance(in, mass, out.joint);
  return out;
}

}  // namespace aloft::internal
