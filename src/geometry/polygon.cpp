// Plate polygons in plane coordinates (u, v), metres: validation and ear-clipping triangulation.

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "aloft/geometry.hpp"

namespace aloft {
namespace {

// Twice the signed area of triangle (a, b, c): > 0 when counter-clockwise.
double orient(const Vec2& a, const Vec2& b, const Vec2& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

double signed_area(const std::vector<Vec2>& pts) {
  double s = 0;
  for (size_t i = 1; i + 1 < pts.size(); ++i) s += orient(pts[0], pts[i], pts[i + 1]);
  return s / 2;
}

int sign(double x) { return (x > 0) - (x < 0); }

// Whether p, known to be on the line through a and b, lies on the closed segment [a, b].
bool on_segment(const Vec2& a, const Vec2& b, const Vec2& p) {
  return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= p.y() &&
         p.y() <= std::max(a.y(), b.y());
}

// Whether the closed segments [a, b] and [c, d] share at least one point.
bool segments_meet(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const int o1 = sign(orient(a, b, c)), o2 = sign(orient(a, b, d));
  const int o3 = sign(orient(c, d, a)), o4 = sign(orient(c, d, b));
  // c and d on different sides of (or one on) line ab, and likewise a, b of line cd: the segments meet
  // (a proper crossing, or an end touching the other segment).
  if (o1 != o2 && o3 != o4) return true;
  // Otherwise they can only meet if an end lies on the other segment, collinear with it.
  if (o1 == 0 && on_segment(a, b, c)) return true;
  if (o2 == 0 && on_segment(a, b, d)) return true;
  if (o3 == 0 && on_segment(c, d, a)) return true;
  if (o4 == 0 && on_segment(c, d, b)) return true;
  return false;
}

std::string edge_name(int i, int n) {
  return "edge " + std::to_string(i) + " (points " + std::to_string(i) + "-" + std::to_string((i + 1) % n) + ")";
}

std::string point_text(const Vec2& p) {
  std::ostringstream s;
  s << "(" << p.x() << ", " << p.y() << ")";
  return s.str();
}

}  // namespace

std::optional<std::string> polygon_problem(const std::vector<Vec2>& points) {
  const int n = static_cast<int>(points.size());
  if (n < 3) return "a polygon needs at least 3 points, got " + std::to_string(n);
  for (int i = 0; i < n; ++i)
    if (!points[i].allFinite()) return "point " + std::to_string(i) + " has a non-finite coordinate";

  // Repeated points: consecutive ones first (the common mistake of closing the loop explicitly).
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    if (points[i] == points[j])
      return "points " + std::to_string(std::min(i, j)) + " and " + std::to_string(std::max(i, j)) +
             " are the same point " + point_text(points[i]);
  }
  {
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    auto less = [&](int a, int b) {
      return points[a].x() < points[b].x() || (points[a].x() == points[b].x() && points[a].y() < points[b].y());
    };
    std::sort(order.begin(), order.end(), less);
    for (int k = 0; k + 1 < n; ++k) {
      const int a = std::min(order[k], order[k + 1]), b = std::max(order[k], order[k + 1]);
      if (points[a] == points[b])
        return "points " + std::to_string(a) + " and " + std::to_string(b) + " are the same point " +
               point_text(points[a]) + ": the polygon touches itself";
    }
  }

  // All points on one line: relative to the polygon's extent, every point is within 1e-12 of the line
  // through point 0 and the point farthest from it (a tolerance of rounding, not of modelling).
  {
    int far = 0;
    for (int i = 1; i < n; ++i)
      if ((points[i] - points[0]).squaredNorm() > (points[far] - points[0]).squaredNorm()) far = i;
    const double len2 = (points[far] - points[0]).squaredNorm();
    double max_cross = 0;
    for (int i = 0; i < n; ++i) max_cross = std::max(max_cross, std::abs(orient(points[0], points[far], points[i])));
    if (max_cross <= 1e-12 * len2) return std::string("the polygon has zero area: its points are collinear");
  }

  // Self-intersection: non-adjacent edges must not meet; adjacent edges must not fold back on each other.
  for (int i = 0; i < n; ++i) {
    const Vec2 &a = points[i], &b = points[(i + 1) % n];
    for (int j = i + 1; j < n; ++j) {
      const Vec2 &c = points[j], &d = points[(j + 1) % n];
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      if (adjacent) {
        // Shared vertex s, other ends p and q: they overlap when collinear and on the same side of s.
        const Vec2& s = j == i + 1 ? b : a;
        const Vec2& p = j == i + 1 ? a : b;
        const Vec2& q = j == i + 1 ? d : c;
        if (orient(p, s, q) == 0 && (p - s).dot(q - s) > 0)
          return edge_name(i, n) + " and " + edge_name(j, n) + " overlap: the polygon folds back on itself";
      } else if (segments_meet(a, b, c, d)) {
        return edge_name(i, n) + " and " + edge_name(j, n) + " cross: the polygon intersects itself";
      }
    }
  }

  double extent2 = 0;
  for (int i = 1; i < n; ++i) extent2 = std::max(extent2, (points[i] - points[0]).squaredNorm());
  if (std::abs(signed_area(points)) <= 1e-12 * extent2) return std::string("the polygon has zero area");
  return std::nullopt;
}

std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<Vec2>& points) {
  const int n = static_cast<int>(points.size());
  std::vector<std::array<int, 3>> triangles;
  if (n < 3) return triangles;
  triangles.reserve(n - 2);

  // Circular doubly linked list of the remaining vertices, in counter-clockwise order.
  const bool ccw = signed_area(points) >= 0;
  std::vector<int> vertex(n), prev(n), next(n);
  for (int k = 0; k < n; ++k) {
    vertex[k] = ccw ? k : n - 1 - k;
    prev[k] = (k + n - 1) % n;
    next[k] = (k + 1) % n;
  }
  auto P = [&](int k) -> const Vec2& { return points[vertex[k]]; };
  auto convexity = [&](int k) { return orient(P(prev[k]), P(k), P(next[k])); };

  // An ear: strictly convex at k, and no other remaining vertex in the closed triangle.
  auto is_ear = [&](int k) {
    if (!(convexity(k) > 0)) return false;
    const Vec2 &a = P(prev[k]), &b = P(k), &c = P(next[k]);
    for (int j = next[next[k]]; j != prev[k]; j = next[j]) {
      const Vec2& p = P(j);
      if (orient(a, b, p) >= 0 && orient(b, c, p) >= 0 && orient(c, a, p) >= 0) return false;
    }
    return true;
  };
  auto clip = [&](int k) {
    triangles.push_back({vertex[prev[k]], vertex[k], vertex[next[k]]});
    next[prev[k]] = next[k];
    prev[next[k]] = prev[k];
  };

  int remaining = n;
  int k = 0;
  while (remaining > 3) {
    // Look for an ear going once around from k.
    int found = -1;
    int j = k;
    for (int step = 0; step < remaining; ++step, j = next[j])
      if (is_ear(j)) {
        found = j;
        break;
      }
    if (found < 0) {
      // No clean ear: only possible through rounding on nearly degenerate input, or for a polygon that
      // polygon_problem rejects. Clip the most convex vertex so that the triangulation still finishes.
      found = k;
      double best = convexity(k);
      for (int step = 0, i = k; step < remaining; ++step, i = next[i])
        if (convexity(i) > best) {
          best = convexity(i);
          found = i;
        }
    }
    k = prev[found];  // the neighbours are the vertices whose ear status changed
    clip(found);
    --remaining;
  }
  triangles.push_back({vertex[prev[k]], vertex[k], vertex[next[k]]});
  return triangles;
}

}  // namespace aloft
