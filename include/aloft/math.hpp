#pragma once
// Aloft's numeric vocabulary. World frame: right-handed, metres, y up, gravity along -y by default.
// All quantities are SI (m, kg, s, N, rad) unless a name says otherwise.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace aloft {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;  // unit quaternion; Eigen stores (x, y, z, w), we print (w, x, y, z)

// The cross-product matrix [r]x, so that skew(r) * a == r.cross(a).
inline Mat3 skew(const Vec3& r) {
  Mat3 m;
  m << 0, -r.z(), r.y(),  //
      r.z(), 0, -r.x(),   //
      -r.y(), r.x(), 0;
  return m;
}

}  // namespace aloft
