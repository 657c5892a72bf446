// The wind's item buffer rasterizer: near-plane clipping, projection, edge functions, 1/z depth test.

#include "wind/item_rasterizer.hpp"

#include <algorithm>
#include <cmath>

namespace aloft::internal {

void ItemRasterizer::reset(int width, double half, double near) {
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(width);
  if (width != width_ || half != half_) {
    width_ = width;
    half_ = half;
    pixel_ = 2 * half / width;
    row_first_.assign(width, 0);
    row_last_.assign(width, -1);
    // A pixel counts when its centre is inside the disc: |u|^2 + |v|^2 <= half^2.
    for (int y = 0; y < width; ++y) {
      const double v = v_of(y);
      const double r2 = half * half - v * v;
      if (r2 < 0) continue;
      int first = width, last = -1;
      for (int x = 0; x < width; ++x) {
        const double u = u_of(x);
        if (u * u <= r2) {
          first = std::min(first, x);
          last = x;
        }
      }
      row_first_[y] = first;
      row_last_[y] = last;
    }
  }
  near_ = near;
  blocks_ = (width + kBlock - 1) / kBlock;
  touched_.assign(static_cast<std::size_t>(blocks_) * blocks_, 0);
  ids_.assign(n, 0);
  depth_.assign(n, 0.0f);
}

bool ItemRasterizer::any_touched(int x0, int y0, int x1, int y1) const {
  for (int by = y0 / kBlock; by <= y1 / kBlock; ++by)
    for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx)
      if (touched_[static_cast<std::size_t>(by) * blocks_ + bx]) return true;
  return false;
}

void ItemRasterizer::draw(const Vec3& a, const Vec3& b, const Vec3& c, std::uint32_t id) {
  // Sutherland-Hodgman against z >= near: a triangle becomes a polygon of at most 4 vertices.
  const Vec3 in[3] = {a, b, c};
  Vec3 out[4];
  int count = 0;
  for (int i = 0; i < 3; ++i) {
    const Vec3& p = in[i];
    const Vec3& q = in[(i + 1) % 3];
    const bool p_in = p.z() >= near_, q_in = q.z() >= near_;
    if (p_in) out[count++] = p;
    if (p_in != q_in) {
      const double t = (near_ - p.z()) / (q.z() - p.z());
      out[count++] = p + t * (q - p);
    }
  }
  if (count < 3) return;
  Vec3 tri[3] = {out[0], out[1], out[2]};
  draw_clipped(tri, id);
  if (count == 4) {
    Vec3 second[3] = {out[0], out[2], out[3]};
    draw_clipped(second, id);
  }
}

// Screen coordinates in pixels: (u + half) / pixel with u = x near / z; w = 1/z is affine in screen space.
void ItemRasterizer::draw_clipped(const Vec3* v, std::uint32_t id) {
  double sx[3], sy[3], w[3];
  for (int i = 0; i < 3; ++i) {
    w[i] = 1.0 / v[i].z();
    sx[i] = (v[i].x() * near_ * w[i] + half_) / pixel_;
    sy[i] = (v[i].y() * near_ * w[i] + half_) / pixel_;
  }
  double area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
  if (!(std::abs(area) > 0)) return;  // edge-on (or NaN): covers no pixel centre's area
  if (area < 0) {                     // make the edge functions positive inside
    std::swap(sx[1], sx[2]);
    std::swap(sy[1], sy[2]);
    std::swap(w[1], w[2]);
    area = -area;
  }
  // Pixel centres (x + 0.5, y + 0.5) inside the bounding box, clamped to the buffer.
  const double lo_x = std::min({sx[0], sx[1], sx[2]}), hi_x = std::max({sx[0], sx[1], sx[2]});
  const double lo_y = std::min({sy[0], sy[1], sy[2]}), hi_y = std::max({sy[0], sy[1], sy[2]});
  const double limit = width_;
  const int y0 = std::max(0, static_cast<int>(std::ceil(std::clamp(lo_y - 0.5, -1.0, limit))));
  const int y1 = std::min(width_ - 1, static_cast<int>(std::floor(std::clamp(hi_y - 0.5, -1.0, limit))));
  const int x_lo = std::max(0, static_cast<int>(std::ceil(std::clamp(lo_x - 0.5, -1.0, limit))));
  const int x_hi = std::min(width_ - 1, static_cast<int>(std::floor(std::clamp(hi_x - 0.5, -1.0, limit))));
  if (y0 > y1 || x_lo > x_hi) return;
  const double inv_area = 1.0 / area;
  // Edge function e_i(x, y) for the edge opposite vertex i, linear in x: e = A_i x + B_i y + C_i.
  double ea[3], eb[3], ec[3];
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    ea[i] = sy[j] - sy[k];
    eb[i] = sx[k] - sx[j];
    ec[i] = sx[j] * sy[k] - sx[k] * sy[j];
  }
  for (int y = y0; y <= y1; ++y) {
    const double py = y + 0.5;
    // The span of this row where every edge function is >= 0: each is linear in x, so each bounds x on
    // one side. Widened by one pixel against rounding; the exact test below decides each pixel.
    double from = x_lo, to = x_hi;
    for (int i = 0; i < 3; ++i) {
      const double k = eb[i] * py + ec[i];
      if (ea[i] > 0)
        from = std::max(from, -k / ea[i] - 0.5 - 1);
      else if (ea[i] < 0)
        to = std::min(to, -k / ea[i] - 0.5 + 1);
      else if (k < 0)
        to = from - 1;  // parallel to the row and outside
    }
    // Clamped to [-1, width] before the conversion to int (a nearly parallel edge gives huge bounds).
    const int x0 = std::max({x_lo, row_first_[y], static_cast<int>(std::ceil(std::clamp(from, -1.0, double(width_))))});
    const int x1 = std::min({x_hi, row_last_[y], static_cast<int>(std::floor(std::clamp(to, -1.0, double(width_))))});
    std::uint32_t* id_row = ids_.data() + static_cast<std::size_t>(y) * width_;
    float* depth_row = depth_.data() + static_cast<std::size_t>(y) * width_;
    std::uint8_t* touched_row = touched_.data() + static_cast<std::size_t>(y / kBlock) * blocks_;
    for (int x = x0; x <= x1; ++x) {
      const double px = x + 0.5;
      const double e0 = ea[0] * px + eb[0] * py + ec[0];
      const double e1 = ea[1] * px + eb[1] * py + ec[1];
      const double e2 = ea[2] * px + eb[2] * py + ec[2];
      if (e0 < 0 || e1 < 0 || e2 < 0) continue;
      const float depth = static_cast<float>((e0 * w[0] + e1 * w[1] + e2 * w[2]) * inv_area);
      if (depth > depth_row[x]) {
        depth_row[x] = depth;
        id_row[x] = id;
        touched_row[x / kBlock] = 1;
      }
    }
  }
}

}  // namespace aloft::internal
