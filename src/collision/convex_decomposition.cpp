// Convex decomposition of a simple polygon: ear-clipping triangulation, then Hertel-Mehlhorn merging
// (remove a diagonal when both polygons it separates stay convex at its two ends). The result has at
// most four times the minimum number of convex parts, and is exactly the polygon's region.

#include <cstddef>

#include "aloft/geometry.hpp"
#include "collision/convex_pieces.hpp"

namespace aloft::internal {

namespace {

double cross(const Vec2& a, const Vec2& b, const Vec2& c) {
  return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
}

// Polygon `p` (counter-clockwise) is convex: no clockwise turn beyond round-off (relative to its size).
bool convex(const std::vector<int>& p, const std::vector<Vec2>& pts, double tolerance) {
  const std::size_t n = p.size();
  for (std::size_t k = 0; k < n; ++k) {
    if (cross(pts[p[k]], pts[p[(k + 1) % n]], pts[p[(k + 2) % n]]) < -tolerance) return false;
  }
  return true;
}

// Merge `q` into `p` across their shared edge when the union is convex. Returns true when merged.
bool try_merge(std::vector<int>& p, const std::vector<int>& q, const std::vector<Vec2>& pts,
               double tolerance) {
  const std::size_t n = p.size(), m = q.size();
  for (std::size_t i = 0; i < n; ++i) {
    const int u = p[i], v = p[(i + 1) % n];
    for (std::size_t j = 0; j < m; ++j) {
      if (q[j] != v || q[(j + 1) % m] != u) continue;
      // p: ... u v ...; q: ... v u ...; the union walks p up to u, then q from u round to v, then on.
      std::vector<int> merged;
      merged.reserve(n + m - 2);
      for (std::size_t k = 0; k <= i; ++k) merged.push_back(p[k]);               // ... u
      for (std::size_t k = 2; k < m; ++k) merged.push_back(q[(j + k) % m]);      // q's vertices between u and v
      for (std::size_t k = i + 1; k < n; ++k) merged.push_back(p[k]);            // v ...
      if (!convex(merged, pts, tolerance)) return false;
      p = std::move(merged);
      return true;
    }
  }
  return false;
}

}  // namespace

std::vector<std::vector<int>> convex_decomposition(const std::vector<Vec2>& points) {
  std::vector<std::vector<int>> parts;
  for (const auto& t : triangulate_polygon(points)) parts.push_back({t[0], t[1], t[2]});
  // Round-off allowance for "convex": a turn of 1e-12 of the squared size of the polygon.
  double size2 = 0;
  for (const Vec2& p : points) size2 = std::max(size2, (p - points[0]).squaredNorm());
  const double tolerance = 1e-12 * size2;
  // The quadratic scan is for the small polygons of sheet-metal plates; large ones stay triangles.
  constexpr std::size_t kMaxMergedTriangles = 256;
  if (parts.size() > kMaxMergedTriangles) return parts;
  for (bool merged_any = true; merged_any;) {
    merged_any = false;
    for (std::size_t i = 0; i < parts.size(); ++i) {
      for (std::size_t j = i + 1; j < parts.size();) {
        if (try_merge(parts[i], parts[j], points, tolerance)) {
          parts.erase(parts.begin() + static_cast<std::ptrdiff_t>(j));
          merged_any = true;
        } else {
          ++j;
        }
      }
    }
  }
  return parts;
}

}  // namespace aloft::internal
