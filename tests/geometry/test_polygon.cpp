// Plate polygons: polygon_problem() diagnoses, triangulate_polygon() covers concave polygons exactly.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "aloft/geometry.hpp"

namespace aloft {
namespace {

constexpr double kPi = 3.14159265358979323846;

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

double signed_area(const std::vector<Vec2>& p) {
  double s = 0;
  for (size_t i = 0; i < p.size(); ++i) s += cross(p[i], p[(i + 1) % p.size()]);
  return s / 2;
}

// Crossing-number point-in-polygon (strictly inside or outside; callers avoid boundary points).
bool inside(const std::vector<Vec2>& p, const Vec2& q) {
  bool in = false;
  for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++)
    if ((p[i].y() > q.y()) != (p[j].y() > q.y()) &&
        q.x() < p[j].x() + (q.y() - p[j].y()) * (p[i].x() - p[j].x()) / (p[i].y() - p[j].y()))
      in = !in;
  return in;
}

// Whether segments [a, b] and [c, d] cross at a point interior to both.
bool properly_cross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double o1 = cross(b - a, c - a), o2 = cross(b - a, d - a), o3 = cross(d - c, a - c), o4 = cross(d - c, b - c);
  return ((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0));
}

// A triangulation of a simple polygon: n - 2 counter-clockwise, non-degenerate triangles inside the polygon
// whose areas add up to the polygon's. Inside: each triangle's centroid is inside, no triangle edge crosses
// a polygon edge, and no polygon vertex lies strictly inside a triangle; with the areas adding up, the
// triangles cannot overlap.
void expect_valid_triangulation(const std::vector<Vec2>& p) {
  const auto tris = triangulate_polygon(p);
  const int n = static_cast<int>(p.size());
  ASSERT_EQ(static_cast<int>(tris.size()), n - 2);
  const double area = std::abs(signed_area(p));
  double sum = 0;
  for (const auto& t : tris) {
    for (int k : t) ASSERT_TRUE(k >= 0 && k < n);
    const Vec2 &a = p[t[0]], &b = p[t[1]], &c = p[t[2]];
    const double tri_area = cross(b - a, c - a) / 2;
    // Counter-clockwise and not degenerate: at least 1e-9 of the polygon's area (the smallest triangles in
    // these polygons are ~1e-4 of it).
    EXPECT_GT(tri_area, 1e-9 * area);
    sum += tri_area;
    EXPECT_TRUE(inside(p, (a + b + c) / 3));
    for (int e = 0; e < 3; ++e)
      for (int i = 0; i < n; ++i) EXPECT_FALSE(properly_cross(p[t[e]], p[t[(e + 1) % 3]], p[i], p[(i + 1) % n]));
    for (int i = 0; i < n; ++i) {
      if (i == t[0] || i == t[1] || i == t[2]) continue;
      const bool strictly_inside =
          cross(b - a, p[i] - a) > 0 && cross(c - b, p[i] - b) > 0 && cross(a - c, p[i] - c) > 0;
      EXPECT_FALSE(strictly_inside) << "vertex " << i;
    }
  }
  // 1e-12 relative: the same area summed two ways; rounding ~1e-16 per term over <= 200 terms.
  EXPECT_NEAR(sum, area, 1e-12 * area);
}

std::vector<Vec2> reversed(std::vector<Vec2> p) {
  std::reverse(p.begin(), p.end());
  return p;
}

std::vector<Vec2> ell() { return {{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 2}, {0, 2}}; }

std::vector<Vec2> fish() {
  return {{0, 0},      {0.8, -0.45}, {2, -0.55},  {3, -0.3}, {3.5, -0.05}, {4.3, -0.6},
          {4.1, 0.02}, {4.3, 0.6},   {3.5, 0.05}, {3, 0.3},  {2, 0.55},    {0.8, 0.45}};
}

// A comb: a base [0, 2k-1] x [0, 1] with k teeth of width 1 and height 2, counter-clockwise. Area 4k - 1.
std::vector<Vec2> comb(int k) {
  std::vector<Vec2> p = {{0, 0}, {2 * k - 1, 0}};
  for (int i = k - 1; i >= 0; --i) {
    p.emplace_back(2 * i + 1, 3);
    p.emplace_back(2 * i, 3);
    if (i > 0) {
      p.emplace_back(2 * i, 1);
      p.emplace_back(2 * i - 1, 1);
    }
  }
  return p;
}

// A star-shaped polygon about the origin: increasing angles, random radii.
std::vector<Vec2> random_star(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> radius(0.2, 1.0), jitter(-0.3, 0.3);
  std::vector<Vec2> p;
  for (int i = 0; i < n; ++i) {
    const double angle = 2 * kPi * (i + jitter(rng)) / n;
    const double r = radius(rng);
    p.emplace_back(r * std::cos(angle), r * std::sin(angle));
  }
  return p;
}

TEST(Polygon, AcceptsSimplePolygons) {
  EXPECT_EQ(polygon_problem({{0, 0}, {1, 0}, {0, 1}}), std::nullopt);
  EXPECT_EQ(polygon_problem(ell()), std::nullopt);
  EXPECT_EQ(polygon_problem(reversed(ell())), std::nullopt);
  EXPECT_EQ(polygon_problem(fish()), std::nullopt);
  EXPECT_EQ(polygon_problem(comb(6)), std::nullopt);
  EXPECT_EQ(polygon_problem(random_star(200, 7)), std::nullopt);
  // A redundant point in the middle of an edge is harmless.
  EXPECT_EQ(polygon_problem({{0, 0}, {1, 0}, {2, 0}, {2, 2}, {0, 2}}), std::nullopt);
}

void expect_problem(const std::vector<Vec2>& p, const std::string& words) {
  const auto problem = polygon_problem(p);
  ASSERT_TRUE(problem.has_value()) << "expected: " << words;
  EXPECT_NE(problem->find(words), std::string::npos) << *problem;
}

TEST(Polygon, DiagnosesUnusablePolygons) {
  expect_problem({}, "at least 3 points, got 0");
  expect_problem({{0, 0}, {1, 0}}, "at least 3 points, got 2");
  expect_problem({{0, 0}, {1, 1}, {1, 0}, {0, 1}}, "intersects itself");  // bow-tie
  expect_problem({{0, 0}, {1, 0}, {1, 0}, {0, 1}}, "points 1 and 2 are the same point");
  expect_problem({{0, 0}, {1, 0}, {0, 1}, {0, 0}}, "points 0 and 3 are the same point");  // closed explicitly
  // Two triangles meeting at a vertex (1, 1) visited twice.
  expect_problem({{0, 0}, {2, 0}, {1, 1}, {2, 2}, {0, 2}, {1, 1}}, "points 2 and 5 are the same point (1, 1)");
  expect_problem({{0, 0}, {1, 1}, {2, 2}}, "zero area");
  expect_problem({{0, 0}, {1, 0}, {3, 0}, {2, 0}}, "zero area");
  expect_problem({{0, 0}, {2, 0}, {1, 0}, {1, 1}}, "folds back");  // a spike doubling back along an edge
  // A vertex touching a non-adjacent edge.
  expect_problem({{0, 0}, {4, 0}, {4, 3}, {2, 0}, {0, 3}}, "edge 0 (points 0-1) and edge 2 (points 2-3)");
  expect_problem({{0, 0}, {1, std::nan("")}, {0, 1}}, "point 1 has a non-finite coordinate");
}

TEST(Polygon, TriangulatesConcavePolygonsOfEitherWinding) {
  for (const auto& [name, polygon] : {std::pair{"L", ell()}, std::pair{"fish", fish()}, std::pair{"comb", comb(8)},
                                      std::pair{"star", random_star(200, 3)},
                                      std::pair{"triangle", std::vector<Vec2>{{0, 0}, {1, 0}, {0, 1}}}}) {
    SCOPED_TRACE(name);
    {
      SCOPED_TRACE("counter-clockwise");
      expect_valid_triangulation(polygon);
    }
    {
      SCOPED_TRACE("clockwise");
      expect_valid_triangulation(reversed(polygon));
    }
  }
  // The comb's area is known independently: 4k - 1.
  double sum = 0;
  const auto c = comb(8);
  for (const auto& t : triangulate_polygon(c)) sum += cross(c[t[1]] - c[t[0]], c[t[2]] - c[t[0]]) / 2;
  EXPECT_NEAR(sum, 31, 1e-12);  // 1e-12: integer coordinates, sums of exact products
}

TEST(Polygon, CollinearPointsGiveNoDegenerateTriangles) {
  // A square with a point in the middle of every side and a run of collinear points on one side.
  expect_valid_triangulation({{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}, {4, 2}, {4, 4}, {2, 4}, {0, 4}, {0, 2}});
  expect_valid_triangulation(reversed({{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}, {4, 2}, {4, 4}, {2, 4}, {0, 4}, {0, 2}}));
}

TEST(Polygon, TriangulationOfTooFewPointsIsEmpty) {
  EXPECT_TRUE(triangulate_polygon({}).empty());
  EXPECT_TRUE(triangulate_polygon({{0, 0}, {1, 0}}).empty());
}

}  // namespace
}  // namespace aloft
