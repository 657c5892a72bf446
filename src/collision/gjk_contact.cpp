// General convex contact: GJK distance (gjk_distance.cpp) when the pieces are apart, libccd's GJK + EPA
// when they overlap; and the dispatch between it and the closed forms.
//
// Speculative distance: each piece is inflated by margin / 2 (its support moves margin / 2 along the
// query direction: a Minkowski sum with a ball). For convex pieces the inflated signed distance is the
// true one minus margin, and the separating direction is the same, so EPA's depth on the inflated pair
// gives distance = margin - depth. The midpoint of the two inflated deepest points is the midpoint of
// the two true closest points, since both moved by margin / 2 towards each other.

#include <ccd/ccd.h>

#include <algorithm>
#include <cmath>

#include "collision/gjk_distance.hpp"
#include "collision/narrow_phase.hpp"

namespace aloft::internal {

namespace {

struct Inflated {
  const ConvexPiece* piece;
  const Pose* pose;
  double inflate;  // m
};

void support(const void* object, const ccd_vec3_t* direction, ccd_vec3_t* out) {
  const auto& o = *static_cast<const Inflated*>(object);
  const Vec3 d(direction->v[0], direction->v[1], direction->v[2]);
  const Vec3 body = o.piece->support(o.pose->rotation.transpose() * d);
  const double n = d.norm();
  const Vec3 w = o.pose->to_world(body) + (n > 0 ? Vec3((o.inflate / n) * d) : Vec3::Zero());
  ccdVec3Set(out, w.x(), w.y(), w.z());
}

void center(const void* object, ccd_vec3_t* out) {
  const auto& o = *static_cast<const Inflated*>(object);
  const Vec3 w = o.pose->to_world(o.piece->bound_center);
  ccdVec3Set(out, w.x(), w.y(), w.z());
}

// The gap between the pieces along the unit direction n (from b towards a): min over a of x.n minus
// max over b of x.n. Never larger than the signed distance, which is its maximum over n.
double gap_along(const ConvexPiece& a, const Pose& pose_a, const ConvexPiece& b, const Pose& pose_b, const Vec3& n) {
  const Vec3 on_a = pose_a.to_world(a.support(pose_a.rotation.transpose() * -n));
  const Vec3 on_b = pose_b.to_world(b.support(pose_b.rotation.transpose() * n));
  return (on_a - on_b).dot(n);
}

// Whether the unit world direction n is across piece's axis, when it is a wire: the point of its axis
// closest to the other piece, moved out by the radius against n, is then on the wire (its side, or the
// rim of an end), so the cores' distance minus the radii is the pieces' own. Tolerance: with n tilted
// by c = 1e-6 from square, that point is off the wire by r c (0.5 nm for a 0.5 mm thread), and the
// reported gap (the capsules') stays a lower bound of the true one.
bool across_axis(const ConvexPiece& piece, const Pose& pose, const Vec3& n) {
  if (piece.kind != ConvexPiece::Kind::Cylinder) return true;
  const Vec3 axis = pose.rotation * (piece.b - piece.a);
  return std::abs(n.dot(axis)) <= 1e-6 * axis.norm();
}

ccd_t make_ccd() {
  ccd_t ccd;
  CCD_INIT(&ccd);
  ccd.support1 = support;
  ccd.support2 = support;
  ccd.center1 = center;
  ccd.center2 = center;
  // Pieces are millimetres to metres: EPA stops when its polytope is within 1e-8 m of the true
  // boundary (libccd's default 1e-4 is coarser than a wire's radius); GJK stops at 1e-10 m.
  ccd.max_iterations = 200;
  ccd.epa_tolerance = 1e-8;
  ccd.dist_tolerance = 1e-10;
  ccd.mpr_tolerance = 1e-8;
  return ccd;
}

}  // namespace

bool gjk_contact(const ConvexPiece& a, const Pose& pose_a, const ConvexPiece& b, const Pose& pose_b,
                 double margin, PieceContact& out) {
  using Kind = ConvexPiece::Kind;
  // Apart: GJK distance gives the closest points themselves, first of the pieces' cores (a sphere's
  // centre, a wire's axis; ConvexPiece::core_support), the radii taken off afterwards. GJK on cores ends
  // in finitely many steps; on a round support it only converges: 27 iterations per call on average for
  // a wire against a plate or a wire's end, against 10-15 for two plates then (generated-127 and 1023
  // after the breeze; 4-7 since GJK stops on no progress). A sphere is its centre grown by its radius,
  // so the cores give its distance exactly. A wire lies inside the capsule of its axis and radius, so
  // the cores' distance minus the radii is at most the pieces' distance: enough to rule the pair out
  // beyond the margin, and equal to it when the direction between the closest points is across the
  // wire's axis (the point moved out by the radius is then on its side or the rim of an end). Otherwise
  // an end face of the wire is nearest, and GJK measures the wire whole.
  // The gap is taken from GJK's certified lower bound, never from its estimate, which is above the true
  // distance where GJK stops at its iteration limit (by up to millimetres on wires lying along plates):
  // taken as the gap, that hid contacts (estimate beyond the margin, truth within) and, remembered by the
  // detector's coherence cache as a lower bound, let it skip pairs that had come into contact. A wire of
  // the shaken Steel Fish went 7 mm into a 1.5 mm plate that way (narrow_phase.hpp; test
  // Detector.RememberedDistancesGiveTheContactsOfAFreshDetector).
  const bool round_a = a.kind != Kind::Polytope, round_b = b.kind != Kind::Polytope;
  // g apart by more than ra + rb; known_gap: a lower bound of the gap known already (m)
  const auto apart = [&](const GjkResult& g, double ra, double rb, double known_gap) {
    // At most the true gap, or 0 (touching) if unsure.
    const double gap = std::max({g.lower - ra - rb, known_gap, 0.0});
    out.normal = (g.on_a - g.on_b) / g.distance;
    out.distance = gap;  // beyond the margin: a bound for the detector's coherence (narrow_phase.hpp)
    out.point = 0.5 * ((g.on_a - ra * out.normal) + (g.on_b + rb * out.normal));
    return gap < margin;
  };
  const double ra = round_a ? a.radius : 0.0, rb = round_b ? b.radius : 0.0;
  const GjkResult cores = gjk_distance(a, pose_a, b, pose_b, round_a, round_b);
  const bool cores_apart = !cores.overlap && cores.distance > ra + rb;
  if (cores_apart) {
    const bool in_contact = apart(cores, ra, rb, 0.0);
    if (!in_contact || (across_axis(a, pose_a, out.normal) && across_axis(b, pose_b, out.normal))) return in_contact;
  }
  if (a.kind == Kind::Cylinder || b.kind == Kind::Cylinder) {
    // A wire's end is nearest, or the capsules touch: the wires whole (spheres still as centres). The
    // capsules' gap, when they are apart, bounds the gap from below too (GJK on two round supports can
    // stall with a looser bound).
    const bool sphere_a = a.kind == Kind::Sphere, sphere_b = b.kind == Kind::Sphere;
    const double sa = sphere_a ? a.radius : 0.0, sb = sphere_b ? b.radius : 0.0;
    const GjkResult g = gjk_distance(a, pose_a, b, pose_b, sphere_a, sphere_b);
    if (!g.overlap && g.distance > sa + sb) {
      // GJK on a wire whole converges slowly, and where it stops, its closest points can be far off (their
      // direction has been 80 degrees from the true normal for two wires with an end involved, on the
      // shaken Steel Fish: the speculative contact then held the wrong direction, and a thread approaching
      // at 5 m/s went 1.2 mm into a bar). The direction of its certified gap separates the pieces by
      // exactly that gap (GjkResult::lower_direction): that is the normal, and the point is midway
      // between the pieces' supports across it. Where the capsules' gap is the larger bound, the cores'
      // answer is the better one (a wire lies in its capsule).
      const double capsules = cores_apart ? cores.lower - ra - rb : -INFINITY;
      if (capsules >= g.lower - sa - sb) return apart(cores, ra, rb, 0.0);
      // No separation certified (GJK saw none along any direction): the closest points are all there is.
      if (!(g.lower - sa - sb > 0)) return apart(g, sa, sb, 0.0);
      const Vec3& n = g.lower_direction;
      const auto facing = [&](const ConvexPiece& piece, const Pose& pose, bool sphere, const Vec3& towards) {
        const Vec3 d = pose.rotation.transpose() * towards;
        return sphere ? Vec3(pose.to_world(piece.a) + piece.radius * towards.normalized())
                      : Vec3(pose.to_world(piece.support(d)));
      };
      out.normal = n;
      out.distance = std::max(g.lower - sa - sb, 0.0);
      out.point = 0.5 * (facing(a, pose_a, sphere_a, -n) + facing(b, pose_b, sphere_b, n));
      return out.distance < margin;
    }
    // Apart capsules hold apart wires: an overlap here is GJK's rounding, so the capsules answer.
    if (cores_apart) return apart(cores, ra, rb, 0.0);
  }
  // Overlapping: libccd's EPA on the pieces inflated by margin / 2 each (see the top of this file).
  out.distance = 0;  // nothing known, should this end without a contact
  static const ccd_t ccd = make_ccd();
  const Inflated ia{&a, &pose_a, 0.5 * margin}, ib{&b, &pose_b, 0.5 * margin};
  ccd_real_t depth = 0;
  ccd_vec3_t dir{}, pos{};
  // libccd: "if obj2 is translated by depth in direction dir the objects touch": dir points from a
  // towards b, so the normal from b towards a is -dir.
  // When libccd finds no overlap (its GJK misses touches of a few micrometres) or EPA ends degenerate,
  // there is no contact. Answering from the candidate directions below instead was tried: on a touch or
  // a near miss none of them need be the separating direction, and the false overlap along the best of
  // them sent wires through plates in the shaken Steel Fish (9-207 mm in 100 s; none without).
  if (ccdGJKPenetration(&ia, &ib, &ccd, &depth, &dir, &pos) != 0) return false;
  const Vec3 n(-dir.v[0], -dir.v[1], -dir.v[2]);
  if (!(n.norm() > 0) || !std::isfinite(depth)) return false;  // EPA degenerate
  out.normal = n / n.norm();
  // libccd's EPA stops 1e-5..1e-4 m short on curved supports (spheres, wire rims, the inflation
  // itself). The gap along any unit n, min over a of a.n - max over b of b.n, is at most the signed
  // distance (which is its maximum over n), and is within second order of the normal's error of it:
  // so take the gap along EPA's normal from the true supports. Conservative: never larger than the
  // true distance.
  out.distance = std::min(margin - static_cast<double>(depth), gap_along(a, pose_a, b, pose_b, out.normal));
  // EPA can also settle on a face of the Minkowski difference that is not the nearest one: on thin
  // pieces (a plate 1.5 mm thick crossed by a wire) it has answered with a direction in the plate's
  // plane and an overlap of centimetres. The signed distance is the largest gap over all directions
  // (separating axis), so every candidate can only bring the answer closer to it: try each piece's face
  // normals (a cylinder's axis), both ways, and keep the direction with the largest gap.
  const auto consider = [&](const Vec3& n) {  // n: world, unit, from b towards a
    const double gap = gap_along(a, pose_a, b, pose_b, n);
    if (gap > out.distance) {
      out.distance = gap;
      out.normal = n;
    }
  };
  auto try_axes = [&](const ConvexPiece& piece, const Pose& pose) {
    for (const Vec3& axis_body : piece.axes) {
      const Vec3 axis = pose.rotation * axis_body;
      consider(axis);
      consider(-axis);
    }
  };
  try_axes(a, pose_a);
  try_axes(b, pose_b);
  // Edge against edge: for two polytopes the separating axis is a face normal (above) or the cross
  // product of an edge direction of each, so with these the candidates are complete and the largest gap
  // is the signed distance itself (for a cylinder, its axis against the other's edges helps too). EPA
  // on the inflated pieces has settled on a wrong face where two sheets cross edge to edge: in the shaken
  // Steel Fish, an arm's plate against a fish plate overlapping by 0.0074 mm came out 2.57 mm deep, and
  // the push along that wrong normal drove a wire 0.8 mm into the fish (test
  // NarrowPhase.ThinBoxesCrossingEdgeToEdgeGetTheirExactOverlap: errors up to 2.8 mm before).
  for (const Vec3& edge_a : a.edges) {
    const Vec3 world_a = pose_a.rotation * edge_a;
    for (const Vec3& edge_b : b.edges) {
      const Vec3 axis = world_a.cross(pose_b.rotation * edge_b);
      const double length = axis.norm();
      if (!(length > 1e-6)) continue;  // parallel edges: their plane's normal is a face normal above
      consider(axis / length);
      consider(-axis / length);
    }
  }
  // A small overlap is where EPA errs most (it has answered a 0.01 mm touch of two wires with a 10 mm
  // overlap the other way, and the overlap correction then pushed one wire through the other). While a
  // wire's axis (a segment) or a sphere's centre is still outside the other piece, the direction between
  // the closest points of those cores is the separating one: try it too.
  if ((round_a || round_b) && !cores.overlap && cores.distance > 0)
    consider((cores.on_a - cores.on_b) / cores.distance);
  out.point = Vec3(pos.v[0], pos.v[1], pos.v[2]);
  // EPA's point is an average over its last face and can be centimetres off. Pull b back along the
  // normal until the gap along it is 1 um, and take the closest points of that separated pair from GJK
  // (then move b's back): the point midway between them is where the two surfaces meet.
  if (out.distance < 0) {
    const double pull = 1e-6 - out.distance;
    Pose pulled = pose_b;
    pulled.position -= pull * out.normal;
    const GjkResult apart = gjk_distance(a, pose_a, b, pulled);
    if (!apart.overlap) out.point = 0.5 * (apart.on_a + apart.on_b + pull * out.normal);
  }
  return out.distance < margin;
}

// The capsules' gap settles a pair of wires only when it exceeds the margin by more than this fraction
// of the lengths involved: far above the rounding of either measurement (GJK's 1e-12 relative on cores).
constexpr double kCapsuleBand = 1e-9;

bool piece_contact(const ConvexPiece& a, const Pose& pose_a, const ConvexPiece& b, const Pose& pose_b,
                   double margin, PieceContact& out) {
  using Kind = ConvexPiece::Kind;
  auto flip = [](PieceContact& c) { c.normal = -c.normal; };
  if (a.kind == Kind::Sphere && b.kind == Kind::Sphere) {
    out = sphere_sphere(pose_a.to_world(a.a), a.radius, pose_b.to_world(b.a), b.radius);
    return out.distance < margin;
  }
  if (a.kind == Kind::Cylinder && b.kind == Kind::Sphere) {
    out = cylinder_sphere(pose_a.to_world(a.a), pose_a.to_world(a.b), a.radius, pose_b.to_world(b.a),
                          b.radius);
    return out.distance < margin;
  }
  if (a.kind == Kind::Sphere && b.kind == Kind::Cylinder) {
    out = cylinder_sphere(pose_b.to_world(b.a), pose_b.to_world(b.b), b.radius, pose_a.to_world(a.a),
                          a.radius);
    flip(out);
    return out.distance < margin;
  }
  if (a.kind == Kind::Cylinder && b.kind == Kind::Cylinder) {
    const Vec3 from_a = pose_a.to_world(a.a), to_a = pose_a.to_world(a.b);
    const Vec3 from_b = pose_b.to_world(b.a), to_b = pose_b.to_world(b.b);
    if (cylinder_cylinder_sides(from_a, to_a, a.radius, from_b, to_b, b.radius, out)) return out.distance < margin;
    // An end is involved, or the axes are parallel (two threads, which hang vertical: most of the wire
    // pairs a tangle of a generated mobile measures). The capsules' gap is a lower bound of the wires'
    // gap; well beyond the margin it settles the pair without GJK (which would measure the same cores,
    // to a relative 1e-12: GjkResult::lower), and is the bound the detector keeps. The band keeps the
    // pairs whose gap is within round-off of the margin for GJK, so that both give the same answer.
    const SegmentClosest axes = segment_segment(from_a, to_a, from_b, to_b);
    const double capsules = axes.distance - a.radius - b.radius;
    if (capsules > margin + kCapsuleBand * (margin + axes.distance)) {
      out.normal = (axes.on_p - axes.on_q) / axes.distance;
      out.distance = capsules;
      out.point = 0.5 * ((axes.on_p - a.radius * out.normal) + (axes.on_q + b.radius * out.normal));
      return false;
    }
  }
  // A plate's part (a prism) apart from the other piece across the plate's own plane, beyond the margin:
  // the gap along that normal is a lower bound of the pieces' distance (as along any direction), and
  // settles the pair without GJK. Plates side by side on a generated mobile are most of the pairs with
  // a plate that a tangle measures apart. The band is kCapsuleBand's, for the same reason.
  const auto across_plate = [&](const ConvexPiece& plate, const Pose& pose_plate) {
    if (plate.prism_middle.empty()) return false;
    const Vec3 centers = pose_a.to_world(a.bound_center) - pose_b.to_world(b.bound_center);
    Vec3 n = pose_plate.rotation * plate.prism_half.normalized();
    if (n.dot(centers) < 0) n = -n;  // from b towards a
    const Vec3 on_a = pose_a.to_world(a.support(pose_a.rotation.transpose() * -n));
    const Vec3 on_b = pose_b.to_world(b.support(pose_b.rotation.transpose() * n));
    const double gap = (on_a - on_b).dot(n);
    if (!(gap > margin + kCapsuleBand * (margin + centers.norm()))) return false;
    out.normal = n;
    out.distance = gap;
    out.point = 0.5 * (on_a + on_b);
    return true;
  };
  if (across_plate(a, pose_a) || across_plate(b, pose_b)) return false;
  return gjk_contact(a, pose_a, b, pose_b, margin, out);
}

}  // namespace aloft::internal
