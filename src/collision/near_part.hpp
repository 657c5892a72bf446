#pragma once
// The part of a convex piece that can meet another within a step.
//
// The detector reports a pair of pieces when they are closer than the pair's margin rho, which bounds how
// far any point of either component can move towards the other in one step (CollisionDetector's
// contract). So a point of piece x farther than rho from piece y at the start of the step cannot be in y at
// its end, and what Simulation bounds about a contact's pieces (how fast they travel, how much deeper
// they can get, docs/collisions.md) needs only x's points within rho of y: near_part_box() gives a box
// around them. Two wires crossing each other meet over a few millimetres around the crossing, not over
// their whole lengths, and a spinning bar's far end, which the whole piece's box would count, cannot
// reach the wire it touches near its middle.
//
// The neighbourhood N(y) = {points within rho of y} is enclosed in simple convex sets:
//   sphere y (centre c, radius r):   the ball of radius r + rho about c;
//   wire y (axis s0-s1, radius r):   the capsule of radius r + rho about its axis;
//   polytope y:                      its enclosing ball grown by rho, and for each of its face normals
//                                    (ConvexPiece::axes) the slab of the piece's extent along it, grown
//                                    by rho on both sides.
// Then for x:
//   a wire:             its axis segment is clipped to N(y) grown by x's radius (a point of x within rho
//                       of y lies within x's radius of an axis point within radius + rho of y), and the
//                       box is the clipped segment grown by the radius;
//   a sphere/polytope:  x's own box is cut by N(y)'s sets. When y is a wire, its axis is first clipped to
//                       the neighbourhood of x (x's enclosing ball and slabs): y's points nearest to x's
//                       near points are within rho of x, so x's near part lies within r + rho of the
//                       clipped axis.
// Every set used encloses what it stands for, so the box encloses the near part (tests/collision/
// test_near_part.cpp checks it against sampled points); it is never larger than x's own box.

#include "collision/convex_pieces.hpp"
#include "collision/narrow_phase.hpp"

namespace aloft::internal {

// A box (x's body frame: [low, high]) around the points of piece x (at pose_x) within rho (m) of piece y
// (at pose_y); x's own box when nothing can be cut.
void near_part_box(const ConvexPiece& x, const Pose& pose_x, const ConvexPiece& y, const Pose& pose_y, double rho,
                   Vec3& low, Vec3& high);

// The interval [t0, t1] of t in [0, 1] for which p0 + t (p1 - p0) lies within `radius` of the segment
// s0-s1 (a capsule; s0 == s1 is a ball). False when there is none.
bool clip_segment_to_capsule(const Vec3& p0, const Vec3& p1, const Vec3& s0, const Vec3& s1, double radius,
                             double& t0, double& t1);

}  // namespace aloft::internal
