// The near part of a convex piece (src/collision/near_part.hpp): the box it gives must enclose every point
// of the piece within rho of the other piece, measured independently (distance_to_shape of src/geometry,
// which shares no code with src/collision), and it must be sharp where it matters: two wires crossing meet
// over millimetres, not over their lengths.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "aloft/geometry.hpp"
#include "collision/convex_pieces.hpp"
#include "collision/narrow_phase.hpp"
#include "collision/near_part.hpp"

namespace aloft::internal {
namespace {

using Rng = std::mt19937;

Vec3 random_unit(Rng& rng) {
  std::normal_distribution<double> g;
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

Quat random_orientation(Rng& rng) {
  std::normal_distribution<double> g;
  return Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
}

// A shape of the kind the mobiles are made of, about the origin of its body frame: a wire (a thread or a
// bar), a ball, a box, or a plate (a regular polygon of 3 to 8 sides, 1-3 mm thick).
Shape random_shape(Rng& rng, int kind) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  switch (kind) {
    case 0: {
      const Vec3 d = random_unit(rng) * (0.02 + 0.15 * u(rng));
      return Wire{-0.5 * d, 0.5 * d, 0.0005 + 0.003 * u(rng)};
    }
    case 1:
      return Sphere{Vec3(0.01 * u(rng), 0, 0), 0.005 + 0.03 * u(rng)};
    case 2:
      return Box{Vec3::Zero(), Vec3(0.002 + 0.05 * u(rng), 0.002 + 0.05 * u(rng), 0.002 + 0.05 * u(rng)),
                 random_orientation(rng).toRotationMatrix()};
    default: {
      Plate p;
      const int sides = 3 + static_cast<int>(6 * u(rng));
      const double r = 0.02 + 0.04 * u(rng);
      for (int k = 0; k < sides; ++k)
        p.points.push_back(r * Vec2(std::cos(2 * M_PI * k / sides), std::sin(2 * M_PI * k / sides)));
      const Mat3 frame = random_orientation(rng).toRotationMatrix();
      p.u_axis = frame.col(0), p.v_axis = frame.col(1);
      p.thickness = 0.001 + 0.002 * u(rng);
      return p;
    }
  }
}

// A random point of the piece (body frame): a point of its axis and disc, of its ball, or a random convex
// combination of a polytope's vertices, biased to its boundary (where the near part's edge is).
Vec3 random_point(Rng& rng, const ConvexPiece& piece) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  switch (piece.kind) {
    case ConvexPiece::Kind::Cylinder: {
      const Vec3 axis = piece.b - piece.a;
      Vec3 across = random_unit(rng).cross(axis).normalized();
      return piece.a + u(rng) * axis + std::sqrt(u(rng)) * piece.radius * across;
    }
    case ConvexPiece::Kind::Sphere:
      return piece.a + std::cbrt(u(rng)) * piece.radius * random_unit(rng);
    case ConvexPiece::Kind::Polytope: {
      std::exponential_distribution<double> e(1.0);
      Vec3 p = Vec3::Zero();
      double total = 0;
      for (const Vec3& v : piece.vertices) {
        const double w = std::pow(e(rng), 4.0);  // a few vertices dominate: near faces and edges
        p += w * v;
        total += w;
      }
      return p / total;
    }
  }
  return piece.a;
}

// The shape placed by a pose (its body frame -> world), for distance_to_shape.
Shape placed(const Shape& shape, const Pose& pose) {
  const auto at = [&](const Vec3& p) { return pose.to_world(p); };
  if (const auto* w = std::get_if<Wire>(&shape)) return Wire{at(w->from), at(w->to), w->radius};
  if (const auto* s = std::get_if<Sphere>(&shape)) return Sphere{at(s->center), s->radius};
  if (const auto* b = std::get_if<Box>(&shape)) return Box{at(b->center), b->size, pose.rotation * b->rotation};
  Plate p = std::get<Plate>(shape);
  p.origin = at(p.origin), p.u_axis = pose.rotation * p.u_axis, p.v_axis = pose.rotation * p.v_axis;
  return p;
}

TEST(NearPart, EnclosesEveryPointWithinRhoOfTheOtherPiece) {
  // 2000 pairs of random pieces (every pair of kinds), the second placed near the first (their centres
  // within the sum of their sizes), rho from 0.5 to 10 mm; 1000 points of the first piece each, those
  // within rho of the second (measured exactly) must lie in the box. Rounding: positions of 0.1 m,
  // distances to 1e-15 m; the box is grown by 1e-9 m inside near_part_box and 1e-12 m here.
  Rng rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int near_points = 0, cut = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Shape sx = random_shape(rng, trial % 4), sy = random_shape(rng, (trial / 4) % 4);
    const std::vector<ConvexPiece> px = build_component_geometry({{sx, {}}}).pieces;
    const std::vector<ConvexPiece> py = build_component_geometry({{sy, {}}}).pieces;
    const Pose pose_x{random_orientation(rng).toRotationMatrix(), Vec3(0, 1, 0)};
    const double size = px[0].bound_radius + py[0].bound_radius;
    const Pose pose_y{random_orientation(rng).toRotationMatrix(), pose_x.position + 0.8 * size * u(rng) * random_unit(rng)};
    const double rho = 0.0005 + 0.0095 * u(rng);
    const Shape y_world = placed(sy, pose_y);
    for (const ConvexPiece& x : px) {
      for (const ConvexPiece& y : py) {
        Vec3 low, high;
        near_part_box(x, pose_x, y, pose_y, rho, low, high);
        ASSERT_TRUE((low.array() >= x.box_low.array() - 1e-15).all() && (high.array() <= x.box_high.array() + 1e-15).all())
            << "trial " << trial << ": the box is larger than the piece's own";
        if ((high - low).maxCoeff() < 0.999 * (x.box_high - x.box_low).maxCoeff()) ++cut;
        for (int k = 0; k < 1000; ++k) {
          const Vec3 p = random_point(rng, x);
          if (distance_to_shape(y_world, pose_x.to_world(p)) > rho) continue;
          ++near_points;
          ASSERT_TRUE((p.array() >= low.array() - 1e-12).all() && (p.array() <= high.array() + 1e-12).all())
              << "trial " << trial << ": a point within " << rho << " m of the other piece lies outside the box ["
              << low.transpose() << "] - [" << high.transpose() << "]: " << p.transpose();
        }
      }
    }
  }
  // The test must test something: many points are near, and the box is often cut.
  std::printf("%d points near the other piece, all in their boxes; %d of the boxes cut\n", near_points, cut);
  EXPECT_GT(near_points, 100000);
  EXPECT_GT(cut, 500);
}

TEST(NearPart, CrossingWiresMeetOverMillimetres) {
  // Two 16 cm wires (a bar and a thread, 0.8 and 0.5 mm radius) crossing at right angles, touching (their
  // axes 1.3 mm apart): with rho = 2 mm, the near part of each is where its axis lies within
  // R = r_x + r_y + rho = 3.3 mm of the other's, sqrt(R^2 - 1.3^2) = 3.03 mm each way from the crossing,
  // plus its radius; against 8 cm each way for the whole wire.
  const Wire bar{Vec3(-0.08, 0, 0), Vec3(0.08, 0, 0), 0.0008};
  const Wire thread{Vec3(0.03, 0.0013, -0.08), Vec3(0.03, 0.0013, 0.08), 0.0005};
  const ConvexPiece x = build_component_geometry({{bar, {}}}).pieces[0];
  const ConvexPiece y = build_component_geometry({{thread, {}}}).pieces[0];
  const Pose identity;
  Vec3 low, high;
  near_part_box(x, identity, y, identity, 0.002, low, high);
  const double along = std::sqrt(0.0033 * 0.0033 - 0.0013 * 0.0013);
  EXPECT_NEAR(low.x(), 0.03 - along - 0.0008, 1e-8);  // the box is exact here but for its 1e-9 m slack
  EXPECT_NEAR(high.x(), 0.03 + along + 0.0008, 1e-8);
  near_part_box(y, identity, x, identity, 0.002, low, high);
  EXPECT_NEAR(high.z() - low.z(), 2 * (along + 0.0005), 1e-8);
}

TEST(NearPart, APlateBesideAWireKeepsOnlyTheStripAlongIt) {
  // A hexagonal plate (radius 4 cm, 2 mm thick, in the x-y plane) and a wire along x just above its face:
  // the plate's near part is the strip within 1 mm + 0.5 mm of the wire; the wire's, the stretch over the
  // plate (grown by the same).
  Plate plate;
  for (int k = 0; k < 6; ++k) plate.points.push_back(0.04 * Vec2(std::cos(M_PI * k / 3), std::sin(M_PI * k / 3)));
  plate.thickness = 0.002;
  const Wire wire{Vec3(-0.1, 0.01, 0.0016), Vec3(0.1, 0.01, 0.0016), 0.0005};
  const ConvexPiece x = build_component_geometry({{plate, {}}}).pieces[0];
  const ConvexPiece y = build_component_geometry({{wire, {}}}).pieces[0];
  const Pose identity;
  Vec3 low, high;
  near_part_box(x, identity, y, identity, 0.001, low, high);
  EXPECT_NEAR(low.y(), 0.01 - 0.0015, 1e-8);
  EXPECT_NEAR(high.y(), 0.01 + 0.0015, 1e-8);
  near_part_box(y, identity, x, identity, 0.001, low, high);
  EXPECT_LT(high.x() - low.x(), 0.1);  // the hexagon is 8 cm wide at most: the wire's 20 cm are cut
  EXPECT_GT(high.x() - low.x(), 0.07);
}

}  // namespace
}  // namespace aloft::internal
