#pragma once
// How far the pieces of a contact can move into each other in one step: what Simulation checks before
// it accepts a step of h with collisions on (a contact is a constraint at one point, with one normal,
// from the closest features at the start of the step; a step must not let the pieces sink past that
// plane by more than the thin sheets and wires of a mobile can take).
//
// The bound. A contact between convex pieces X (of component a) and Y (of b) has the unit normal n
// (from b towards a), the signed distance d and the point p midway between the two supporting points;
// at the start of the step Y lies on one side of its supporting plane, X on the other:
//     Y ⊂ {x : (x - p_b) . n <= 0},   X ⊂ {x : (x - p_a) . n >= 0},   p_a - p_b = d n.
// Seen from b's frame, a moves rigidly, with the relative velocity v_rel(p) = (v_a + w_a x (p - x_a)) -
// (v_b + w_b x (p - x_b)) at p and the relative angular velocity w_a - w_b. To first order in h a point
// q of X moves along n by
//     h [ v_rel(p) . n + ((w_a - w_b) x (q - p)) . n ] = h [ v_rel(p) . n - (q - p) . (n x (w_a - w_b)) ],
// and it starts at least max(d, 0) above Y's plane, so it sinks past it by at most
// max(0, (approach) -h v_rel . n + (turn) the largest of -h (q - p) . (n x (w_a - w_b)) over X - max(d, 0))
// (a contact separating at p may have its turn offset by that; a gap is credited against both). The turn
// term is linear in q: its largest value over a box around X is at a corner. Only the points of X that can
// reach Y within the step count, the near part of X (collision/near_part.hpp), so the box is one around
// that. It is the same expression for Y's points sinking past X's plane as seen from a's frame, over a box
// around Y's near part; the overlap along either plane's normal bounds the pieces' penetration depth, so
// the smaller of the two boxes' values does too. A translation that does not
// approach at p cannot make convex pieces overlap more than they do (it keeps X on its side of a plane
// Y is on the other side of), and a turn about the contact normal (a plate spinning flat against a
// wire) moves nothing towards the plane: neither counts, where a bound on how far any point travels
// (Simulation's travel limit, which a contact may pass instead) counts both.
//
// The rest is second order in the turns (theta = h |w| + g, rad), bounded generously (the curvature
// allowance):
//  - each body's drift turns it by h w_m, where w_m = I(q_m)^-1 L, the midpoint rule's angular
//    velocity, departs from w by about (h/2) |I^-1 (w x L)| (the precession of a body not spinning
//    about a principal axis): g = (h^2 / 2) |I^-1 (w x I w)| rad more, moving a point r from the centre
//    of mass by g r;
//  - an arc leaves its tangent by at most theta^2 r / 2;
//  - seen from b's frame, b's plane turns by theta_b while a's points move across it by up to h |v_rel|
//    plus their turn, (theta_a + theta_b) D_a, D_a the farthest corner of a's box from p; and the
//    normal itself leaves its tangent by theta_b^2 / 2, over D_a. (From a's frame the same with a and b
//    exchanged.)
// So the bound is max(0, the approach, plus (g_a + theta_a^2 / 2) r_a + (g_b + theta_b^2 / 2) r_b, r_a and
// r_b the largest distances from each centre of mass to its pieces in contact, plus the smaller of
//     turn over a's box + theta_b (h |v_rel| + (theta_a + theta_b) D_a + theta_b D_a / 2)   (b's frame)
//     turn over b's box + theta_a (h |v_rel| + (theta_a + theta_b) D_b + theta_a D_b / 2)   (a's frame),
// less the gap max(d, 0)).
//
// tests/dynamics/test_contact_travel.cpp checks the bound against the drift itself.

#include "aloft/collision.hpp"
#include "aloft/math.hpp"

namespace aloft {

// One side of a contact at the start of a step, with the velocities the step's drift will use.
struct ContactSide {
  Vec3 position = Vec3::Zero();            // centre of mass, world (m)
  Quat orientation = Quat::Identity();     // principal frame -> world
  Vec3 velocity = Vec3::Zero();            // m/s, world
  Vec3 angular = Vec3::Zero();             // rad/s, world
  // rad/s^2, world: how the step's turn departs from h times `angular`, by (h^2 / 2) |precession| rad at
  // most: I^-1 (w x I w) when `angular` is the kick's w and the drift turns at the midpoint rule's w_m
  // (the header's first allowance); zero for a fixed component. (Simulation passes the drift's own w_m,
  // plus the overlap push's turn w_p, and w_p x w_m: the second-order term of composing the two turns.)
  Vec3 precession = Vec3::Zero();
  double reach = 0;                        // m: the largest distance from the centre of mass to its pieces
                                           // in contact (or to the whole component)
  Vec3 near_low = Vec3::Zero(), near_high = Vec3::Zero();  // a box around their near parts, principal frame (m)
};

// How much deeper (m) than they are at the start of a step of h (s) the contact's pieces can get into
// each other (past each other's supporting planes), from the bound above. With approach false the
// approach at p is taken to close exactly the gap: the velocities are those before the contact impulses,
// which let it close no more (the turn and the curvature allowance stay).
double contact_deepening_bound(const Contact& contact, const ContactSide& a, const ContactSide& b, double h,
                               bool approach);

}  // namespace aloft
