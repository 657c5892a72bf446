// The tree solver's 3x3 helpers (src/dynamics/small_matrix.hpp) against Eigen's general products, on
// the structures the factorization hands them: the symmetric ones must give the same matrix as the
// general product, exactly symmetric.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "dynamics/small_matrix.hpp"

namespace aloft {
namespace {

// A random symmetric positive definite matrix: its scale ~1, its condition ~10.
Mat3 random_spd(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Mat3 a;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a(i, j) = u(rng);
  return a * a.transpose() + 0.3 * Mat3::Identity();
}

Vec3 random_vector(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  return Vec3(u(rng), u(rng), u(rng));
}

bool exactly_symmetric(const Mat3& m) { return m(0, 1) == m(1, 0) && m(0, 2) == m(2, 0) && m(1, 2) == m(2, 1); }

// The general product and the upper-triangle formula differ only by rounding in a different order (the
// lower triangle of a mathematically symmetric product): a few ulps of the largest entry. Measured over
// these trials: 4e-16 on entries up to 5.6, 7e-15 on entries up to 59 (1.2e-16 relative). Allowed:
// 1e-14 of the largest entry (45 ulps).
constexpr double kRounding = 1e-14;
double relative_difference(const Mat3& got, const Mat3& expected) {
  return (got - expected).cwiseAbs().maxCoeff() / std::max(1.0, expected.cwiseAbs().maxCoeff());
}

TEST(SmallMatrix, SymmetricHelpersMatchTheGeneralProducts) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 1000; ++trial) {
    const Mat3 k = random_spd(rng), c = random_spd(rng), a = random_spd(rng);
    const Vec3 s = random_vector(rng), r = random_vector(rng);

    // [s]x K [s]x, from k_sx = K [s]x (what a joint folds into its parent).
    const Mat3 k_sx = times_skew(k, s);
    const Mat3 folded = skew_times_symmetric(s, k_sx);
    EXPECT_TRUE(exactly_symmetric(folded));
    EXPECT_LT(relative_difference(folded, skew(s) * k * skew(s)), kRounding);
    EXPECT_LT(relative_difference(folded, skew_times(s, k_sx)), kRounding);

    // A leaf's P [r]x with P = [r]x C^-1.
    const Mat3 p_leaf = skew_times(r, c);
    const Mat3 leaf = times_skew_symmetric(p_leaf, r);
    EXPECT_TRUE(exactly_symmetric(leaf));
    EXPECT_LT(relative_difference(leaf, skew(r) * c * skew(r)), kRounding);

    // K^-1 = A - P B^T with P = B C^-1 (C symmetric): symmetric.
    const Mat3 b = a * skew(r) + random_spd(rng);
    const Mat3 p = b * c;
    const Mat3 k_inv = minus_symmetric_product(a, p, b);
    EXPECT_TRUE(exactly_symmetric(k_inv));
    const Mat3 general = a - p * b.transpose();
    EXPECT_LT(relative_difference(k_inv, general), kRounding);
  }
}

// On a general (non-symmetric) m the symmetric skew helpers' upper triangles still equal those of the
// general products: this catches an entry transcribed from the wrong row or column, which the
// symmetric inputs above could hide.
TEST(SmallMatrix, SkewHelpersEqualTheirDefinitionsOnGeneralMatrices) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 100; ++trial) {
    Mat3 m;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m(i, j) = u(rng);
    const Vec3 s = random_vector(rng);
    // Upper triangles of the general products.
    const Mat3 left = skew(s) * m, right = m * skew(s);
    const Mat3 sym_left = skew_times_symmetric(s, m), sym_right = times_skew_symmetric(m, s);
    for (int i = 0; i < 3; ++i)
      for (int j = i; j < 3; ++j) {
        EXPECT_NEAR(sym_left(i, j), left(i, j), kRounding);
        EXPECT_NEAR(sym_right(i, j), right(i, j), kRounding);
      }
  }
}

}  // namespace
}  // namespace aloft
