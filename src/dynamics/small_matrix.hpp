#pragma once
// Small fixed-size matrix helpers for the tree solver's 3x3 blocks, written out in scalars where Eigen's
// general products do more work than the structure needs (skew-symmetric factors, symmetric results).

#include "aloft/math.hpp"

namespace aloft {

// The symmetric matrix with the upper triangle (o00, o01, o02; o11, o12; o22). The symmetric helpers
// below keep their entries in locals and write each twice: a mirror read back from the result just
// written would stall on store forwarding (measured: 11 % slower steps on generated-127).
[[gnu::always_inline]] inline Mat3 symmetric_from_upper(double o00, double o01, double o02, double o11, double o12,
                                                        double o22) {
  Mat3 out;
  out(0, 0) = o00;
  out(1, 0) = out(0, 1) = o01;
  out(2, 0) = out(0, 2) = o02;
  out(1, 1) = o11;
  out(2, 1) = out(1, 2) = o12;
  out(2, 2) = o22;
  return out;
}

// R diag(d) R^T (world inertia from principal moments d, or its inverse from 1/d). (Its upper triangle
// alone in scalars, 27 products instead of 36, made the step 3 % slower than Eigen's product here.)
[[gnu::always_inline]] inline Mat3 rotate_diagonal(const Mat3& r, const Vec3& d) {
  const Mat3 rd = r * d.asDiagonal();
  Mat3 out;
  out.noalias() = rd * r.transpose();
  return out;
}

// m [s]x, column by column ([s]x e_j = s x e_j): 18 products instead of a full 3x3 product's 27. (Written
// in scalars: Eigen's row and column block assignments are not always inlined.)
[[gnu::always_inline]] inline Mat3 times_skew(const Mat3& m, const Vec3& s) {
  Mat3 out;
  for (int r = 0; r < 3; ++r) {
    out(r, 0) = s.z() * m(r, 1) - s.y() * m(r, 2);
    out(r, 1) = s.x() * m(r, 2) - s.z() * m(r, 0);
    out(r, 2) = s.y() * m(r, 0) - s.x() * m(r, 1);
  }
  return out;
}

// [s]x m, row by row.
[[gnu::always_inline]] inline Mat3 skew_times(const Vec3& s, const Mat3& m) {
  Mat3 out;
  for (int c = 0; c < 3; ++c) {
    out(0, c) = s.y() * m(2, c) - s.z() * m(1, c);
    out(1, c) = s.z() * m(0, c) - s.x() * m(2, c);
    out(2, c) = s.x() * m(1, c) - s.y() * m(0, c);
  }
  return out;
}

// a - p b^T where the result is known to be symmetric (K^-1 = A - P B'^T in the factorization): the upper
// triangle computed, the lower one its mirror (18 products instead of 27).
[[gnu::always_inline]] inline Mat3 minus_symmetric_product(const Mat3& a, const Mat3& p, const Mat3& b) {
  const auto entry = [&](int i, int j) {
    return a(i, j) - (p(i, 0) * b(j, 0) + p(i, 1) * b(j, 1) + p(i, 2) * b(j, 2));
  };
  const double o00 = entry(0, 0), o01 = entry(0, 1), o02 = entry(0, 2);
  const double o11 = entry(1, 1), o12 = entry(1, 2), o22 = entry(2, 2);
  return symmetric_from_upper(o00, o01, o02, o11, o12, o22);
}

// [s]x m where the result is known to be symmetric (m = K [s]x with K symmetric: [s]x K [s]x), by its
// upper triangle (12 products instead of skew_times' 18).
[[gnu::always_inline]] inline Mat3 skew_times_symmetric(const Vec3& s, const Mat3& m) {
  const double o00 = s.y() * m(2, 0) - s.z() * m(1, 0);
  const double o01 = s.y() * m(2, 1) - s.z() * m(1, 1);
  const double o02 = s.y() * m(2, 2) - s.z() * m(1, 2);
  const double o11 = s.z() * m(0, 1) - s.x() * m(2, 1);
  const double o12 = s.z() * m(0, 2) - s.x() * m(2, 2);
  const double o22 = s.x() * m(1, 2) - s.y() * m(0, 2);
  return symmetric_from_upper(o00, o01, o02, o11, o12, o22);
}

// m [s]x where the result is known to be symmetric (m = [s]x C with C symmetric), by its upper triangle
// (12 products instead of times_skew's 18).
[[gnu::always_inline]] inline Mat3 times_skew_symmetric(const Mat3& m, const Vec3& s) {
  const double o00 = s.z() * m(0, 1) - s.y() * m(0, 2);
  const double o01 = s.x() * m(0, 2) - s.z() * m(0, 0);
  const double o02 = s.y() * m(0, 0) - s.x() * m(0, 1);
  const double o11 = s.x() * m(1, 2) - s.z() * m(1, 0);
  const double o12 = s.y() * m(1, 0) - s.x() * m(1, 1);
  const double o22 = s.y() * m(2, 0) - s.x() * m(2, 1);
  return symmetric_from_upper(o00, o01, o02, o11, o12, o22);
}

// The inverse of a symmetric 3x3 matrix from the upper triangle of m, by its cofactors (6 of them: the
// inverse is symmetric too). For the positive definite blocks of the factorization (A, S, K): their
// determinants are far from zero (a mass, a moment of inertia and a lever arm's square set their scale).
[[gnu::always_inline]] inline Mat3 symmetric_inverse(const Mat3& m) {
  const double c00 = m(1, 1) * m(2, 2) - m(1, 2) * m(1, 2);
  const double c01 = m(0, 2) * m(1, 2) - m(0, 1) * m(2, 2);
  const double c02 = m(0, 1) * m(1, 2) - m(0, 2) * m(1, 1);
  const double c11 = m(0, 0) * m(2, 2) - m(0, 2) * m(0, 2);
  const double c12 = m(0, 1) * m(0, 2) - m(0, 0) * m(1, 2);
  const double c22 = m(0, 0) * m(1, 1) - m(0, 1) * m(0, 1);
  const double inverse_det = 1.0 / (m(0, 0) * c00 + m(0, 1) * c01 + m(0, 2) * c02);
  Mat3 out;
  out(0, 0) = c00 * inverse_det;
  out(1, 1) = c11 * inverse_det;
  out(2, 2) = c22 * inverse_det;
  out(0, 1) = out(1, 0) = c01 * inverse_det;
  out(0, 2) = out(2, 0) = c02 * inverse_det;
  out(1, 2) = out(2, 1) = c12 * inverse_det;
  return out;
}

}  // namespace aloft
