#pragma once
// An orbit camera: it looks at a target point from a distance, turned by yaw (about world y) and pitch
// (above the horizontal). World frame as everywhere in Aloft: metres, y up.

#include <Eigen/Core>

#include "aloft/math.hpp"

namespace aloft::render {

using Mat4f = Eigen::Matrix4f;
using Vec3f = Eigen::Vector3f;

struct OrbitCamera {
  Vec3 target = Vec3(0, 1.5, 0);   // m, world: the point looked at
  double yaw = 0;                  // rad about +y; 0 looks along -z (from +z towards the wall)
  double pitch = 0.15;             // rad above the horizontal, (-1.5, 1.5)
  double distance = 4;             // m from the target, > 0
  double fov_y = 0.7;              // rad, vertical field of view

  Vec3 eye() const;                           // m, world
  Vec3 forward() const;                       // unit, eye -> target
  Vec3 right() const;                         // unit, horizontal
  Vec3 up() const;                            // unit, completes the frame
  Mat4f view() const;                         // world -> eye
  Mat4f projection(double aspect) const;      // eye -> clip (near/far from the distance)

  void orbit(double d_yaw, double d_pitch);   // rad; pitch clamped to (-1.5, 1.5)
  void pan(double dx, double dy);             // m along right() and up()
  void zoom(double factor);                   // distance *= factor, kept in [0.05, 200] m

  // A ray from the eye through a point of the viewport given in normalised device coordinates
  // (x, y in [-1, 1], y up). Returns the unit direction; the origin is eye().
  Vec3 ray_direction(double ndc_x, double ndc_y, double aspect) const;
};

// 4x4 helpers (column vectors, OpenGL conventions).
Mat4f look_at(const Vec3& eye, const Vec3& target, const Vec3& up);
Mat4f perspective(double fov_y, double aspect, double near, double far);
Mat4f rigid_transform(const Vec3& position, const Quat& orientation);  // body -> world

}  // namespace aloft::render
