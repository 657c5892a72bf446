#include "dynamics/gyroscopic.hpp"

#include <Eigen/LU>

namespace aloft {

Vec3 midpoint_gyroscopic_torque(const Quat& q, const Vec3& moments, const Vec3& w, double h) {
  const Mat3 rot = q.toRotationMatrix();
  const Vec3 wb = rot.transpose() * w;  // body frame
  // F(w') = I (w' - w) + h w_m x I w_m, at w' = w: F = h w x I w.
  const Vec3 iw = moments.cwiseProduct(wb);
  const Vec3 residual = h * wb.cross(iw);
  // dF/dw' = I + (h/2) ([w_m]x I - [I w_m]x).
  const Mat3 jac = Mat3(moments.asDiagonal()) + 0.5 * h * (skew(wb) * moments.asDiagonal() - skew(iw));
  const Vec3 w_next = wb - jac.inverse() * residual;
  const Vec3 wm = 0.5 * (wb + w_next);
  return rot * (-wm.cross(moments.cwiseProduct(wm)));
}

}  // namespace aloft
