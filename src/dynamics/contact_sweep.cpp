// Sampling a contact's motion through a step (see contact_sweep.hpp).

#include "dynamics/contact_sweep.hpp"

#include <algorithm>
#include <cmath>

#include "dynamics/rotation.hpp"

namespace aloft {

namespace {
// The distance below which the narrow phase measures exactly (m): every overlap, and gaps up to a
// millimetre (beyond, a lower bound is enough: the pair is apart).
constexpr double kNear = 1e-3;
}  // namespace

void swept_pose(const SweptBody& body, double t, Vec3& position, Quat& orientation) {
  position = body.position;
  orientation = body.orientation;
  if (body.fixed) return;
  position += t * body.velocity;
  orientation = turned(t * body.push_angular, turned(t * body.drift_angular, body.orientation));
}

SweepResult sweep_contact(const CollisionDetector& detector, int a, const SweptBody& body_a, int b,
                          const SweptBody& body_b, double h, double start_overlap, double allowed, double thinnest) {
  SweepResult result;
  const double end_limit = start_overlap + allowed;  // the most the pair may overlap at any sample
  const double room = thinnest - end_limit;          // how much deeper it may get between two samples
  const double travel = body_a.travel + body_b.travel;
  if (!(room > 0) || !std::isfinite(travel)) return result;
  const double needed = std::ceil(travel / room);
  if (!(needed <= kMaxSweepSamples)) return result;
  const int samples = std::max(1, static_cast<int>(needed));
  for (int k = 1; k <= samples; ++k) {
    const double t = h * k / samples;
    Vec3 xa, xb;
    Quat qa, qb;
    swept_pose(body_a, t, xa, qa);
    swept_pose(body_b, t, xb, qb);
    const double overlap = -detector.signed_distance(a, xa, qa, b, xb, qb, kNear);
    ++result.samples;
    result.deepest = std::max(result.deepest, overlap);
    if (!(overlap <= end_limit)) return result;  // (NaN too)
  }
  result.shallow = true;
  return result;
}

}  // namespace aloft
