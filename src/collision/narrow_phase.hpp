#pragma once
// Narrow phase: the contact between two convex pieces at their components' poses.
//
// Every result uses the Contact convention: `normal` is a world unit vector pointing from piece b
// towards piece a, `distance` the signed gap along it (m, < 0 when overlapping: minus the penetration
// depth) and `point` the world point midway between the two closest (or deepest) points.
//
// Closed forms (exact): sphere-sphere, cylinder-sphere (flat-ended cylinder: side, rim and end faces),
// cylinder-cylinder when the closest points of the two axes lie strictly inside both axes (side to side;
// then exact when apart, the capsule depth when overlapping); two wires otherwise are settled by their
// capsules' gap (segment_segment) when that is beyond the margin. Everything else (an end of a wire
// involved, boxes, plate parts, mesh pieces) goes through support functions: GJK distance
// (gjk_distance.hpp) when apart, libccd's GJK + EPA with both pieces inflated by margin / 2 when they
// overlap (gjk_contact.cpp).

#include "collision/convex_pieces.hpp"

namespace aloft::internal {

// Rigid placement of a body frame in the world: world = position + rotation * body.
struct Pose {
  Mat3 rotation = Mat3::Identity();
  Vec3 position = Vec3::Zero();
  Vec3 to_world(const Vec3& p) const { return position + rotation * p; }
};

struct PieceContact {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitY();
  double distance = 0;
};

// Closed forms in world coordinates.
PieceContact sphere_sphere(const Vec3& center_a, double radius_a, const Vec3& center_b, double radius_b);
// a: the solid cylinder with axis from -> to, radius rc; b: the sphere.
PieceContact cylinder_sphere(const Vec3& from, const Vec3& to, double rc, const Vec3& center, double rs);
// a, b: solid cylinders. Returns false (and leaves `out`) when the closest points of the two axes are not
// both strictly inside their segments: an end face or rim is then involved and the caller uses GJK.
bool cylinder_cylinder_sides(const Vec3& from_a, const Vec3& to_a, double ra, const Vec3& from_b,
                             const Vec3& to_b, double rb, PieceContact& out);

// The closest points of two segments p0-p1 and q0-q1 (world, m), and their distance: exact at rounding
// for every configuration, parallel, crossing and degenerate (a segment of zero length is its point)
// included. Two wires lie inside the capsules of their axes and radii, so this distance minus the radii
// never exceeds the wires' own gap.
struct SegmentClosest {
  Vec3 on_p = Vec3::Zero(), on_q = Vec3::Zero();
  double distance = 0;
};
SegmentClosest segment_segment(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

// Support-function contact: GJK distance when apart, libccd's EPA when overlapping. True, with `out`,
// when the signed distance is below `margin` (> 0). When false, out.distance is a lower bound of the
// signed distance (GJK's certified bound, GjkResult::lower; >= margin when the pieces were measured
// apart; 0 when nothing is known).
bool gjk_contact(const ConvexPiece& a, const Pose& pose_a, const ConvexPiece& b, const Pose& pose_b,
                 double margin, PieceContact& out);

// The contact of two pieces when their signed distance is below `margin` (> 0): closed forms where
// they apply, GJK/EPA otherwise. When false, out.distance is a lower bound as for gjk_contact() (the
// closed forms' distance is exact).
bool piece_contact(const ConvexPiece& a, const Pose& pose_a, const ConvexPiece& b, const Pose& pose_b,
                   double margin, PieceContact& out);

}  // namespace aloft::internal
