// GJK distance on polytope pairs as mobiles make them: boxes and thin plate prisms, often with parallel
// faces (the same orientation, or turned by right angles). Checked against the gap along a few axes
// (a lower bound of the distance that needs no GJK) and along GJK's own direction.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "collision/convex_pieces.hpp"
#include "collision/gjk_distance.hpp"

namespace aloft::internal {
namespace {

// The gap between the pieces along unit n (from b towards a): <= their signed distance.
double gap_along(const ConvexPiece& a, const Pose& pa, const ConvexPiece& b, const Pose& pb, const Vec3& n) {
  const Vec3 on_a = pa.to_world(a.support(pa.rotation.transpose() * -n));
  const Vec3 on_b = pb.to_world(b.support(pb.rotation.transpose() * n));
  return (on_a - on_b).dot(n);
}

ConvexPiece polytope_of(std::vector<Vec3> vertices) {
  ConvexPiece p;
  p.kind = ConvexPiece::Kind::Polytope;
  p.vertices = std::move(vertices);
  p.bound_radius = 0.3;
  return p;
}

TEST(GjkDistance, ParallelBoxesAndThinPlatesAreNeverCalledOverlappingWhenApart) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
  int apart = 0, overlapping = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    auto make = [&] {
      std::vector<Vec3> v;
      if (trial % 2) {  // a box, up to 5 x 5 x 20 cm
        const Vec3 h(0.001 + 0.05 * unit(rng), 0.001 + 0.05 * unit(rng), 0.001 + 0.2 * unit(rng));
        for (int c = 0; c < 8; ++c)
          v.push_back(Vec3((c & 1) ? h.x() : -h.x(), (c & 2) ? h.y() : -h.y(), (c & 4) ? h.z() : -h.z()));
      } else {  // a 1.5 mm plate: an ellipse-like convex polygon of 3..22 sides, extruded
        const int n = 3 + trial % 20;
        for (int k = 0; k < n; ++k) {
          const double angle = 2 * M_PI * k / n;
          const Vec3 p(0.1 * std::cos(angle), 0.03 * std::sin(angle), 0);
          v.push_back(p + Vec3(0, 0, 0.00075));
          v.push_back(p - Vec3(0, 0, 0.00075));
        }
      }
      return polytope_of(std::move(v));
    };
    const ConvexPiece a = make(), b = make();
    const Pose pa{trial % 3 == 0 ? Mat3(Mat3::Identity())
                                 : Mat3(Eigen::AngleAxisd(M_PI / 2 * (trial % 4), Vec3::UnitY()).toRotationMatrix()),
                  Vec3::Zero()};
    const Pose pb{trial % 5 == 0 ? Mat3(Eigen::AngleAxisd(u(rng), Vec3::UnitY()).toRotationMatrix())
                                 : Mat3(Mat3::Identity()),
                  Vec3(u(rng), u(rng), u(rng)).normalized() * (0.05 + 0.3 * unit(rng))};
    const GjkResult g = gjk_distance(a, pa, b, pb);
    if (g.overlap) {
      // Truly overlapping: no axis separates them. The axes tried (the world axes, which are face normals
      // of both pieces here, and the centres' direction) are not all the separating candidates, so this
      // only catches overlaps claimed for pieces one of them shows apart; 1e-9 m is round-off.
      double widest = -1;
      for (const Vec3& n : {Vec3(Vec3::UnitX()), Vec3(Vec3::UnitY()), Vec3(Vec3::UnitZ()), Vec3(pb.position.normalized())})
        widest = std::max({widest, gap_along(a, pa, b, pb, n), gap_along(a, pa, b, pb, -n)});
      EXPECT_LE(widest, 1e-9) << "trial " << trial << ": called overlapping, but apart by " << widest << " m";
      ++overlapping;
      continue;
    }
    ++apart;
    // Converged: the distance equals the gap along its own direction (exact for polytopes: 1e-12 m of
    // round-off on distances of centimetres).
    const Vec3 n = (g.on_a - g.on_b) / g.distance;
    EXPECT_NEAR(g.distance, gap_along(a, pa, b, pb, n), 1e-12) << "trial " << trial;
  }
  EXPECT_GT(apart, 1000);
  EXPECT_GT(overlapping, 100);
}

}  // namespace
}  // namespace aloft::internal
