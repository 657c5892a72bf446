#include "model/transform_shape.hpp"

namespace aloft::internal {

namespace {

struct RigidMotion {
  const Mat3& rotation;
  const Vec3& translation;
  Vec3 point(const Vec3& p) const { return rotation * p + translation; }

  Shape operator()(Sphere s) const { s.center = point(s.center); return s; }
  Shape operator()(Wire w) const { w.from = point(w.from); w.to = point(w.to); return w; }
  Shape operator()(Box b) const {
    b.center = point(b.center);
    b.rotation = rotation * b.rotation;
    return b;
  }
  Shape operator()(Plate p) const {
    p.origin = point(p.origin);
    p.u_axis = rotation * p.u_axis;
    p.v_axis = rotation * p.v_axis;
    return p;
  }
  Shape operator()(Mesh m) const {
    for (Vec3& v : m.mesh.vertices) v = point(v);
    return m;
  }
};

}  // namespace

Shape transform_shape(const Shape& shape, const Mat3& rotation, const Vec3& translation) {
  return std::visit(RigidMotion{rotation, translation}, shape);
}

}  // namespace aloft::internal
