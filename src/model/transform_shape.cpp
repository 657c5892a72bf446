#include "model/transform_shape.hpp"

namespace aloft::internal {

Shape transform_shape(const Shape& shape, const Mat3& rotation, const Vec3& translation) {
  auto move = [&](const Vec3& p) { return Vec3(rotation * p + translation); };
  struct Visitor {
    const Mat3& rotation;
    decltype(move)& move;
    Shape operator()(Sphere s) const { s.center = move(s.center); return s; }
    Shape operator()(Wire w) const { w.from = move(w.from); w.to = move(w.to); return w; }
    Shape operator()(Box b) const { b.center = move(b.center); b.rotation = rotation * b.rotation; return b; }
    Shape operator()(Plate p) const {
      p.origin = move(p.origin);
      p.u_axis = rotation * p.u_axis;
      p.v_axis = rotation * p.v_axis;
      return p;
    }
    Shape operator()(Mesh m) const {
      for (Vec3& v : m.mesh.vertices) v = move(v);
      return m;
    }
  };
  return std::visit(Visitor{rotation, move}, shape);
}

}  // namespace aloft::internal
