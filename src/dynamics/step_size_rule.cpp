#include "dynamics/step_size_rule.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace aloft {

Vec3 drift_error(const Vec3& angular, const Mat3& inertia, const Mat3& inverse_inertia, double h) {
  const Vec3& w = angular;
  const Vec3 momentum = inertia * w;                  // L (kg m^2/s)
  const Vec3 momentum_cross_w = momentum.cross(w);    // L x w = I w'
  const Vec3 rate = inverse_inertia * momentum_cross_w;  // w' (rad/s^2)
  const Vec3 bracket =
      w.cross(rate) / 6.0 + inverse_inertia * (w.cross(momentum_cross_w) / 24.0 - momentum.cross(rate) / 6.0);
  return (h * h * h) * bracket;
}

namespace {

// The largest drift error (rad) the old rule accepted for a body of principal moments `moments`: the
// maximum, over the axis of turn, of the error measure for a turn of kOldTurnLimit. The error is cubic in
// the turn and its measure invariant under rotation, so this is kOldTurnLimit^3 times the maximum over
// unit vectors u of the measure of e(u) (h = 1, body frame), here over kAxisSamples axes spread evenly
// over a hemisphere (e(-u) = -e(u)): about 0.3 rad apart, so the maximum found is a few percent low at
// worst, which only makes the rule a little stricter.
constexpr int kAxisSamples = 96;

double old_rule_error(const Vec3& moments) {
  const Mat3 inertia = moments.asDiagonal();
  const Mat3 inverse = moments.cwiseInverse().asDiagonal();
  const double half_trace = 0.5 * moments.sum();
  const double golden = 2.399963229728653;  // rad, the golden angle
  double worst = 0;
  for (int k = 0; k < kAxisSamples; ++k) {
    const double z = 1.0 - (k + 0.5) / kAxisSamples, r = std::sqrt(1.0 - z * z);
    const Vec3 u(r * std::cos(golden * k), r * std::sin(golden * k), z);
    const Vec3 e = drift_error(u, inertia, inverse, 1.0);
    worst = std::max(worst, e.dot(inertia * e) / half_trace);
  }
  return kOldTurnLimit * kOldTurnLimit * kOldTurnLimit * std::sqrt(worst);
}

}  // namespace

StepSizeRule::StepSizeRule(const Model& model)
    : children_(model.children),
      half_trace_(model.count, 0.0),
      drift_tolerance_(model.count, 0.0),
      quiet_turn_squared_(model.count, 0.0),
      child_arm_squared_(model.count, 0.0),
      parent_arm_squared_(model.count, 0.0) {
  for (int i = 1; i < model.count; ++i) {
    const Vec3& moments = model.principal_moments[i];
    half_trace_[i] = 0.5 * moments.sum();
    child_arm_squared_[i] = model.joint_in_child[i].squaredNorm();
    parent_arm_squared_[i] = model.joint_in_parent[i].squaredNorm();
    const double low = moments.minCoeff(), high = moments.maxCoeff();
    if (!(low > 0)) continue;  // degenerate: tolerance 0 and always evaluated (only a zero error passes)
    drift_tolerance_[i] = std::max(kMinDriftError, old_rule_error(moments));
    // A bound on |e| for a turn t = h |w| (rad), with the principal moments' extremes l <= u and
    // k = u / l: writing L x w = (I - c E) w x w with c = (l + u) / 2 gives |L x w| <= (u - l) / 2 |w|^2,
    // so |w'| <= (k - 1) / 2 |w|^2 and |L x w'| <= u |w| |w'|; term by term,
    //   |e| <= t^3 (k - 1) / 2 (1/6 + 1/24 + k/6) = t^3 B.
    // The measure of the error is <= |e|, so t^2 <= (tolerance / B)^(2/3) needs no evaluation.
    const double k = high / low;
    const double bound = 0.5 * (k - 1.0) * (5.0 / 24.0 + k / 6.0);
    quiet_turn_squared_[i] =
        bound > 0 ? std::pow(drift_tolerance_[i] / bound, 2.0 / 3.0) : std::numeric_limits<double>::infinity();
  }
}

double StepSizeRule::error_measure(int body, const Vec3& e, const Mat3& inertia) const {
  // The mass's RMS displacement over its RMS distance from the centre: sqrt(e^T I e / (tr I / 2)).
  return half_trace_[body] > 0 ? std::sqrt(e.dot(inertia * e) / half_trace_[body]) : e.norm();
}

bool StepSizeRule::slow_checks(int i, double h, double turn2, const Vec3& angular, const Mat3& inertia,
                               const Mat3& inverse_inertia, const std::vector<Vec3>& child_arm,
                               const std::vector<Vec3>& parent_arm) const {
  const double h2 = h * h;
  constexpr double anchor2 = kMaxAnchorTurn * kMaxAnchorTurn;
  // No anchor turns more than the body, h |w x a| / |a| <= h |w|: look at them only when the body turns
  // more than kMaxAnchorTurn. Compared squared and multiplied out: h^2 |w x a|^2 <= turn^2 |a|^2.
  if (turn2 > anchor2) {
    if (h2 * angular.cross(child_arm[i]).squaredNorm() > anchor2 * child_arm_squared_[i]) return false;
    for (int j : children_[i])
      if (h2 * angular.cross(parent_arm[j]).squaredNorm() > anchor2 * parent_arm_squared_[j]) return false;
  }
  if (turn2 > quiet_turn_squared_[i]) {
    const Vec3 e = drift_error(angular, inertia, inverse_inertia, h);
    if (!(error_measure(i, e, inertia) <= drift_tolerance_[i])) return false;
  }
  return true;
}

bool StepSizeRule::accepts(double h, const std::vector<Vec3>& angular, const std::vector<Mat3>& inertia,
                           const std::vector<Mat3>& inverse_inertia, const std::vector<Vec3>& child_arm,
                           const std::vector<Vec3>& parent_arm) const {
  const int n = static_cast<int>(angular.size());
  for (int i = 1; i < n; ++i)
    if (!accepts_body(i, h, angular[i], inertia[i], inverse_inertia[i], child_arm, parent_arm)) return false;
  return true;
}

StepSizeMeasures StepSizeRule::measure(double h, const std::vector<Vec3>& angular, const std::vector<Mat3>& inertia,
                                       const std::vector<Mat3>& inverse_inertia, const std::vector<Vec3>& child_arm,
                                       const std::vector<Vec3>& parent_arm) const {
  StepSizeMeasures out;
  const int n = static_cast<int>(angular.size());
  const auto raise = [](double value, int body, double& worst, int& where) {
    if (value > worst || !std::isfinite(value)) {
      worst = value;
      where = body;
    }
  };
  for (int i = 1; i < n; ++i) {
    const Vec3& w = angular[i];
    raise(h * w.norm() / kMaxTurn, i, out.turn, out.turn_body);
    if (child_arm_squared_[i] > 0)
      raise(h * w.cross(child_arm[i]).norm() / std::sqrt(child_arm_squared_[i]) / kMaxAnchorTurn, i, out.anchor_turn,
            out.anchor_turn_body);
    for (int j : children_[i])
      if (parent_arm_squared_[j] > 0)
        raise(h * w.cross(parent_arm[j]).norm() / std::sqrt(parent_arm_squared_[j]) / kMaxAnchorTurn, i,
              out.anchor_turn, out.anchor_turn_body);
    const Vec3 e = drift_error(w, inertia[i], inverse_inertia[i], h);
    raise(error_measure(i, e, inertia[i]) / drift_tolerance_[i], i, out.drift_error,
          out.drift_error_body);
  }
  return out;
}

}  // namespace aloft
