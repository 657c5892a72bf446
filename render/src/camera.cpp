#include "aloft/render/camera.hpp"

#include <algorithm>
#include <cmath>

namespace aloft::render {

Vec3 OrbitCamera::forward() const {
  // yaw 0, pitch 0 looks along -z; positive pitch looks down from above.
  return Vec3(-std::sin(yaw) * std::cos(pitch), -std::sin(pitch), -std::cos(yaw) * std::cos(pitch));
}
Vec3 OrbitCamera::right() const { return Vec3(std::cos(yaw), 0, -std::sin(yaw)); }
Vec3 OrbitCamera::up() const { return right().cross(forward()).normalized(); }
Vec3 OrbitCamera::eye() const { return target - distance * forward(); }

Mat4f OrbitCamera::view() const { return look_at(eye(), target, Vec3::UnitY()); }

Mat4f OrbitCamera::projection(double aspect) const {
  // Near plane a fraction of the distance keeps depth precision for a room a few metres deep.
  const double near = std::clamp(distance * 0.02, 0.01, 1.0);
  return perspective(fov_y, aspect, near, distance * 4 + 30);
}

void OrbitCamera::orbit(double d_yaw, double d_pitch) {
  yaw = std::remainder(yaw + d_yaw, 2 * 3.14159265358979323846);
  pitch = std::clamp(pitch + d_pitch, -1.5, 1.5);
}

void OrbitCamera::pan(double dx, double dy) { target += dx * right() + dy * up(); }

void OrbitCamera::zoom(double factor) { distance = std::clamp(distance * factor, 0.05, 200.0); }

Vec3 OrbitCamera::ray_direction(double ndc_x, double ndc_y, double aspect) const {
  const double t = std::tan(fov_y / 2);
  return (forward() + ndc_x * t * aspect * right() + ndc_y * t * up()).normalized();
}

Mat4f look_at(const Vec3& eye, const Vec3& target, const Vec3& up) {
  const Vec3 f = (target - eye).normalized();
  Vec3 s = f.cross(up);
  if (s.norm() < 1e-9) s = f.cross(Vec3::UnitZ());  // looking straight up or down
  s.normalize();
  const Vec3 u = s.cross(f);
  Mat4f m = Mat4f::Identity();
  m.block<1, 3>(0, 0) = s.cast<float>().transpose();
  m.block<1, 3>(1, 0) = u.cast<float>().transpose();
  m.block<1, 3>(2, 0) = -f.cast<float>().transpose();
  m(0, 3) = static_cast<float>(-s.dot(eye));
  m(1, 3) = static_cast<float>(-u.dot(eye));
  m(2, 3) = static_cast<float>(f.dot(eye));
  return m;
}

Mat4f perspective(double fov_y, double aspect, double near, double far) {
  const double f = 1 / std::tan(fov_y / 2);
  Mat4f m = Mat4f::Zero();
  m(0, 0) = static_cast<float>(f / aspect);
  m(1, 1) = static_cast<float>(f);
  m(2, 2) = static_cast<float>((far + near) / (near - far));
  m(2, 3) = static_cast<float>(2 * far * near / (near - far));
  m(3, 2) = -1;
  return m;
}

Mat4f rigid_transform(const Vec3& position, const Quat& orientation) {
  Mat4f m = Mat4f::Identity();
  m.block<3, 3>(0, 0) = orientation.toRotationMatrix().cast<float>();
  m.block<3, 1>(0, 3) = position.cast<float>();
  return m;
}

}  // namespace aloft::render
