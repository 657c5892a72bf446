#pragma once
// GJK distance (Gilbert, Johnson and Keerthi 1988; closest points on the simplex after Ericson, Real-Time
// Collision Detection 5.1): the closest points of two convex pieces that do not overlap. libccd 2.0
// offers intersection and penetration (EPA) but no distance, and its EPA is coarse on curved supports,
// so separated pairs (the usual speculative contact) are measured here and only overlaps go to EPA.

#include "collision/narrow_phase.hpp"

namespace aloft::internal {

struct GjkResult {
  bool overlap = false;          // the pieces intersect (or are closer than round-off)
  Vec3 on_a = Vec3::Zero();      // closest point on a, world (when !overlap)
  Vec3 on_b = Vec3::Zero();      // closest point on b, world
  double distance = 0;           // |on_a - on_b|, m
  // A certified lower bound of the distance (m): the largest separation along a search direction v
  // seen, (support of a - b against v) . v / |v|. Equal to `distance` to a relative 1e-12 when GJK
  // converged; below it when GJK stopped at its iteration limit, as it can on a wire's round side lying
  // along a plate or another wire (seen: 2.01 mm estimated, 1.57 mm certain, after 64 iterations).
  double lower = 0;
  // The search direction that separation was seen along (world, unit, from b towards a): the pieces lie
  // on either side of a band `lower` wide across it. Where GJK stops short of converging, the closest
  // points above can be far from the true ones (on two wires with an end involved, their direction has
  // been 80 degrees off), while this direction separates the pieces by exactly the certified gap.
  Vec3 lower_direction = Vec3::UnitX();
  int iterations = 0;  // support points taken (at most 64)
};

// With core_a (core_b), piece a (b) enters as its core (ConvexPiece::core_support): a sphere's centre, a
// cylinder's axis; the distance of the pieces themselves is then at least this one minus the radii.
GjkResult gjk_distance(const ConvexPiece& a, const Pose& pose_a, const ConvexPiece& b, const Pose& pose_b,
                       bool core_a = false, bool core_b = false);

}  // namespace aloft::internal
