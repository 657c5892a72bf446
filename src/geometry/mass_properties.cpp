// Mass properties of uniform solids (density 1 kg/m^3, so mass == volume in m^3):
//  - polyhedra by Mirtich (1996), "Fast and accurate computation of polyhedral mass properties",
//    J. Graphics Tools 1(2): the divergence theorem turns each volume integral into a sum of face
//    integrals, each face integral becomes an integral over the face's projection onto a coordinate
//    plane, and Green's theorem turns that into a sum over the projected edges;
//  - closed forms for spheres, solid cylinders (wires) and boxes;
//  - the parallel axis theorem (MassAccumulator).

#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>

#include "aloft/geometry.hpp"
#include "common/overloaded.hpp"

namespace aloft {
namespace {

constexpr double kPi = std::numbers::pi;

// ---------------------------------------------------------------------------------------------------
// Projection integrals. For a polygon Pi in the (alpha, beta) plane, pi_pq = integral over Pi of
// alpha^p beta^q d(alpha) d(beta), signed: positive when Pi is counter-clockwise in (alpha, beta).
//
// Green's theorem (integral over Pi of dQ/d(alpha) = closed integral of Q d(beta) for a counter-clockwise
// boundary) with Q = alpha^(p+1) beta^q / (p+1) gives
//   pi_pq = 1/(p+1) * closed integral of alpha^(p+1) beta^q d(beta).
// On the edge (a0, b0) -> (a1, b1), parametrised by t in [0, 1], d(beta) = (b1 - b0) dt and
//   integral_0^1 ((1-t) a0 + t a1)^m ((1-t) b0 + t b1)^n dt
//     = 1/(m+n+1) * sum_{i<=m, j<=n} C(m,i) C(n,j) / C(m+n, i+j) * a0^(m-i) a1^i b0^(n-j) b1^j
// (expand both powers in the Bernstein basis; integral_0^1 (1-t)^(N-k) t^k dt = 1 / ((N+1) C(N,k))).
// So pi_pq = 1 / ((p+1)(p+q+2)) * sum over edges of (b1 - b0) * S(p+1, q), S being the double sum.
// Mirtich needs every pi_pq with p + q <= 3.

constexpr int kMaxDegree = 4;  // m + n of the edge sums: (p + 1) + q <= 4

constexpr double binomial(int n, int k) {
  double r = 1;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

// weight[m][n][i][j] = C(m,i) C(n,j) / C(m+n, i+j), computed at compile time.
struct BernsteinWeights {
  double w[kMaxDegree + 1][kMaxDegree + 1][kMaxDegree + 1][kMaxDegree + 1] = {};
  constexpr BernsteinWeights() {
    for (int m = 0; m <= kMaxDegree; ++m)
      for (int n = 0; m + n <= kMaxDegree; ++n)
        for (int i = 0; i <= m; ++i)
          for (int j = 0; j <= n; ++j) w[m][n][i][j] = binomial(m, i) * binomial(n, j) / binomial(m + n, i + j);
  }
};
constexpr BernsteinWeights kWeights;

// Powers 0..kMaxDegree of one edge end coordinate.
struct Powers {
  double p[kMaxDegree + 1];
  explicit Powers(double x) {
    p[0] = 1;
    for (int k = 1; k <= kMaxDegree; ++k) p[k] = p[k - 1] * x;
  }
};

// S(m, n) for one edge: sum_{i,j} weight * a0^(m-i) a1^i b0^(n-j) b1^j. The degrees are template
// arguments so that the loops unroll over compile-time weights.
template <int m, int n>
inline double edge_sum(const Powers& a0, const Powers& a1, const Powers& b0, const Powers& b1) {
  double s = 0;
  for (int i = 0; i <= m; ++i) {
    double inner = 0;
    for (int j = 0; j <= n; ++j) inner += kWeights.w[m][n][i][j] * b0.p[n - j] * b1.p[j];
    s += a0.p[m - i] * a1.p[i] * inner;
  }
  return s;
}

struct ProjectionIntegrals {
  double p1 = 0, pa = 0, pb = 0, paa = 0, pab = 0, pbb = 0, paaa = 0, paab = 0, pabb = 0, pbbb = 0;

  void add_edge(double a0, double b0, double a1, double b1) {
    const double db = b1 - b0;
    if (db == 0) return;  // every term carries d(beta)
    const Powers pa0(a0), pa1(a1), pb0(b0), pb1(b1);
    // Each accumulates db * S(p+1, q); the constant 1 / ((p+1)(p+q+2)) is applied in finish().
    p1 += db * edge_sum<1, 0>(pa0, pa1, pb0, pb1);
    pa += db * edge_sum<2, 0>(pa0, pa1, pb0, pb1);
    pb += db * edge_sum<1, 1>(pa0, pa1, pb0, pb1);
    paa += db * edge_sum<3, 0>(pa0, pa1, pb0, pb1);
    pab += db * edge_sum<2, 1>(pa0, pa1, pb0, pb1);
    pbb += db * edge_sum<1, 2>(pa0, pa1, pb0, pb1);
    paaa += db * edge_sum<4, 0>(pa0, pa1, pb0, pb1);
    paab += db * edge_sum<3, 1>(pa0, pa1, pb0, pb1);
    pabb += db * edge_sum<2, 2>(pa0, pa1, pb0, pb1);
    pbbb += db * edge_sum<1, 3>(pa0, pa1, pb0, pb1);
  }

  void finish() {
    p1 /= 1 * 2;      // p=0, q=0
    pa /= 2 * 3;      // p=1, q=0
    pb /= 1 * 3;      // p=0, q=1
    paa /= 3 * 4;     // p=2, q=0
    pab /= 2 * 4;     // p=1, q=1
    pbb /= 1 * 4;     // p=0, q=2
    paaa /= 4 * 5;    // p=3, q=0
    paab /= 3 * 5;    // p=2, q=1
    pabb /= 2 * 5;    // p=1, q=2
    pbbb /= 1 * 5;    // p=0, q=3
  }
};

// ---------------------------------------------------------------------------------------------------
// Volume integrals over a closed polyhedron, accumulated face by face, in coordinates relative to
// `origin` (chosen near the solid so that the second moments do not lose digits to cancellation):
//   t0 = integral 1, t1[i] = integral x_i, t2[i] = integral x_i^2, tp[i] = integral x_i x_(i+1 mod 3).
// By the divergence theorem with unit outward normal n of each face F:
//   t0 = sum n_x integral_F x,  t1[i] = sum n_i integral_F x_i^2 / 2,  t2[i] = sum n_i integral_F x_i^3 / 3,
//   tp[i] = sum n_i integral_F x_i^2 x_(i+1) / 2.
class VolumeIntegrals {
 public:
  explicit VolumeIntegrals(const Vec3& origin) : origin_(origin) {}

  // Adds one planar face with `count` >= 3 vertices, counter-clockwise seen from outside;
  // vertex_at(k) gives vertex k in world coordinates. Zero-area faces contribute nothing.
  template <class VertexAt>
  void add_face(int count, const VertexAt& vertex_at) {
    // Newell's area vector (twice the area times the unit normal), exact for planar polygons; taken
    // about the first vertex for accuracy.
    const Vec3 v0 = vertex_at(0) - origin_;
    Vec3 area2 = Vec3::Zero();
    Vec3 sum = v0;
    Vec3 prev = Vec3::Zero();  // vertex k - v0
    for (int k = 1; k < count; ++k) {
      const Vec3 vk = vertex_at(k) - origin_;
      sum += vk;
      const Vec3 rel = vk - v0;
      area2 += prev.cross(rel);
      prev = rel;
    }
    const double norm = area2.norm();
    if (!(norm > 0)) return;
    const Vec3 n = area2 / norm;
    // The face's plane is n . x + w = 0; take it through the vertices' mean.
    const double w = -n.dot(sum / count);

    // Project onto the coordinate plane most parallel to the face: gamma is the normal's largest
    // component, (alpha, beta, gamma) a cyclic permutation of (x, y, z) so that the projected polygon
    // is counter-clockwise exactly when n_gamma > 0.
    int c = 0;
    if (std::abs(n.y()) > std::abs(n[c])) c = 1;
    if (std::abs(n.z()) > std::abs(n[c])) c = 2;
    const int a = (c + 1) % 3;
    const int b = (a + 1) % 3;

    ProjectionIntegrals pi;
    Vec3 first = v0;
    Vec3 cur = v0;
    for (int k = 1; k <= count; ++k) {
      const Vec3 next = k < count ? Vec3(vertex_at(k) - origin_) : first;
      pi.add_edge(cur[a], cur[b], next[a], next[b]);
      cur = next;
    }
    pi.finish();

    // Face integrals. On the face gamma = -(n_a alpha + n_b beta + w) / n_c, and
    // integral_F f dA = (1 / |n_c|) integral_Pi f d(alpha) d(beta); the signed projection integrals carry
    // the sign of n_c, hence the factor k1 = 1 / n_c below.
    const double na = n[a], nb = n[b], nc = n[c];
    const double k1 = 1 / nc, k2 = k1 * k1, k3 = k2 * k1, k4 = k3 * k1;
    const double lin1 = na * pi.pa + nb * pi.pb + w * pi.p1;                // integral of L = n_a a + n_b b + w
    const double quad2 = na * na * pi.paa + 2 * na * nb * pi.pab + nb * nb * pi.pbb;
    const double cub3 =
        na * na * na * pi.paaa + 3 * na * na * nb * pi.paab + 3 * na * nb * nb * pi.pabb + nb * nb * nb * pi.pbbb;

    const double fa = k1 * pi.pa;
    const double fb = k1 * pi.pb;
    const double fc = -k2 * lin1;
    const double faa = k1 * pi.paa;
    const double fbb = k1 * pi.pbb;
    const double fcc = k3 * (quad2 + w * (2 * (na * pi.pa + nb * pi.pb) + w * pi.p1));  // integral of L^2
    const double faaa = k1 * pi.paaa;
    const double fbbb = k1 * pi.pbbb;
    const double fccc =
        -k4 * (cub3 + 3 * w * quad2 + w * w * (3 * (na * pi.pa + nb * pi.pb) + w * pi.p1));  // L^3
    const double faab = k1 * pi.paab;
    const double fbbc = -k2 * (na * pi.pabb + nb * pi.pbbb + w * pi.pbb);  // beta^2 L
    const double fcca =
        k3 * (na * na * pi.paaa + 2 * na * nb * pi.paab + nb * nb * pi.pabb +
              w * (2 * (na * pi.paa + nb * pi.pab) + w * pi.pa));  // alpha L^2

    const double fx = a == 0 ? fa : (b == 0 ? fb : fc);
    t0_ += n.x() * fx;
    t1_[a] += na * faa;
    t1_[b] += nb * fbb;
    t1_[c] += nc * fcc;
    t2_[a] += na * faaa;
    t2_[b] += nb * fbbb;
    t2_[c] += nc * fccc;
    tp_[a] += na * faab;
    tp_[b] += nb * fbbc;
    tp_[c] += nc * fcca;
  }

  MassProperties result() const {
    const double volume = t0_;
    const Vec3 t1 = t1_ / 2, t2 = t2_ / 3, tp = tp_ / 2;
    MassProperties mp;
    mp.volume = volume;
    if (volume == 0) {
      mp.center = origin_;
      return mp;
    }
    const Vec3 c = t1 / volume;  // relative to origin_
    Mat3& I = mp.inertia;
    // Second moments about the centre: integral x_i x_j - V c_i c_j.
    const double sxx = t2.x() - volume * c.x() * c.x();
    const double syy = t2.y() - volume * c.y() * c.y();
    const double szz = t2.z() - volume * c.z() * c.z();
    const double sxy = tp.x() - volume * c.x() * c.y();
    const double syz = tp.y() - volume * c.y() * c.z();
    const double szx = tp.z() - volume * c.z() * c.x();
    I(0, 0) = syy + szz;
    I(1, 1) = szz + sxx;
    I(2, 2) = sxx + syy;
    I(0, 1) = I(1, 0) = -sxy;
    I(1, 2) = I(2, 1) = -syz;
    I(2, 0) = I(0, 2) = -szx;
    mp.center = origin_ + c;
    return mp;
  }

 private:
  Vec3 origin_;
  double t0_ = 0;
  Vec3 t1_ = Vec3::Zero(), t2_ = Vec3::Zero(), tp_ = Vec3::Zero();
};

// Signed area (m^2) of a polygon in (u, v): positive when counter-clockwise.
double signed_area(const std::vector<Vec2>& pts) {
  double s = 0;
  const size_t n = pts.size();
  if (n < 3) return 0;
  for (size_t i = 1; i + 1 < n; ++i) {
    const Vec2 a = pts[i] - pts[0], b = pts[i + 1] - pts[0];
    s += a.x() * b.y() - a.y() * b.x();
  }
  return s / 2;
}

// A plate is a right prism over its polygon: two polygonal caps and one quadrilateral per edge. Mirtich's
// integrals take the polygonal faces directly (no triangulation, no allocation).
MassProperties plate_mass_properties(const Plate& p) {
  const int n = static_cast<int>(p.points.size());
  if (n < 3) return MassProperties{};
  // Walk the polygon counter-clockwise in (u, v) whatever its stored winding.
  const bool ccw = signed_area(p.points) >= 0;
  auto point = [&](int k) -> const Vec2& {
    k = ((k % n) + n) % n;
    return p.points[ccw ? k : n - 1 - k];
  };
  Vec2 mean = Vec2::Zero();
  for (const Vec2& q : p.points) mean += q;
  mean /= n;
  const Vec3 half = p.normal() * (p.thickness / 2);
  VolumeIntegrals vi(p.to_world(mean));
  // Top cap (normal +n): counter-clockwise in (u, v) is counter-clockwise seen from +n.
  vi.add_face(n, [&](int k) { return Vec3(p.to_world(point(k)) + half); });
  // Bottom cap (normal -n): reversed.
  vi.add_face(n, [&](int k) { return Vec3(p.to_world(point(-k)) - half); });
  // Sides: bottom_i, bottom_(i+1), top_(i+1), top_i has normal (e_i x n) t, outward for a CCW polygon.
  for (int i = 0; i < n; ++i) {
    const Vec3 a = p.to_world(point(i)), b = p.to_world(point(i + 1));
    const std::array<Vec3, 4> quad = {a - half, b - half, b + half, a + half};
    vi.add_face(4, [&](int k) { return quad[k]; });
  }
  return vi.result();
}

using internal::Overloaded;

}  // namespace

MassProperties MassProperties::scaled_inertia(double density) const {
  MassProperties r = *this;
  r.inertia *= density;
  return r;
}

void MassAccumulator::add(double m, const Vec3& c, const Mat3& inertia_about_c) {
  if (parts++ == 0) reference = c;
  mass += m;
  const Vec3 d = c - reference;
  first_moment += m * d;
  // Parallel axis theorem: I_reference = I_c + m (|d|^2 1 - d d^T).
  second_moment += inertia_about_c + m * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
}

Vec3 MassAccumulator::center() const { return reference + first_moment / mass; }

Mat3 MassAccumulator::inertia_about_center() const {
  const Vec3 d = first_moment / mass;  // the centre from the reference
  return second_moment - mass * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
}

MassProperties polyhedron_mass_properties(const TriangleMesh& mesh) {
  const int nv = static_cast<int>(mesh.vertices.size());
  // Integrate about the centre of the vertices' bounding box.
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const Vec3& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  VolumeIntegrals vi(nv > 0 ? Vec3((lo + hi) / 2) : Vec3::Zero());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (int k : tri)
      if (k < 0 || k >= nv)
        throw std::invalid_argument("polyhedron_mass_properties: triangle " + std::to_string(t) +
                                    " has vertex index " + std::to_string(k) + " out of range");
    vi.add_face(3, [&](int k) -> const Vec3& { return mesh.vertices[tri[k]]; });
  }
  return vi.result();
}

MassProperties sphere_mass_properties(const Sphere& s) {
  MassProperties mp;
  const double r = s.radius;
  mp.volume = 4.0 / 3.0 * kPi * r * r * r;
  mp.center = s.center;
  mp.inertia = Mat3::Identity() * (0.4 * mp.volume * r * r);  // 2/5 m r^2
  return mp;
}

MassProperties wire_mass_properties(const Wire& w) {
  MassProperties mp;
  const Vec3 axis = w.to - w.from;
  const double length = axis.norm();
  const double r = w.radius;
  mp.volume = kPi * r * r * length;
  mp.center = (w.from + w.to) / 2;
  if (!(length > 0)) return mp;  // no volume, no inertia
  const Vec3 d = axis / length;
  const double axial = mp.volume * r * r / 2;                              // m r^2 / 2
  const double transverse = mp.volume * (3 * r * r + length * length) / 12;  // m (3 r^2 + L^2) / 12
  const Mat3 ddt = d * d.transpose();
  mp.inertia = transverse * (Mat3::Identity() - ddt) + axial * ddt;
  return mp;
}

MassProperties box_mass_properties(const Box& b) {
  MassProperties mp;
  const Vec3& s = b.size;
  mp.volume = s.x() * s.y() * s.z();
  mp.center = b.center;
  const Vec3 sq = s.cwiseProduct(s);
  const Vec3 diag = mp.volume / 12 * Vec3(sq.y() + sq.z(), sq.z() + sq.x(), sq.x() + sq.y());
  mp.inertia = b.rotation * diag.asDiagonal() * b.rotation.transpose();
  return mp;
}

MassProperties shape_mass_properties(const Shape& shape) {
  return std::visit(Overloaded{
                        [](const Sphere& s) { return sphere_mass_properties(s); },
                        [](const Wire& w) { return wire_mass_properties(w); },
                        [](const Box& b) { return box_mass_properties(b); },
                        [](const Plate& p) { return plate_mass_properties(p); },
                        [](const Mesh& m) { return polyhedron_mass_properties(m.mesh); },
                    },
                    shape);
}

}  // namespace aloft
