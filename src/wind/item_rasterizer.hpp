#pragma once
// A small deterministic CPU rasterizer for the wind's item buffer: triangles given in the source's camera
// frame (x right, y up, z along the wind, vertex at the origin, m) are clipped to z >= near (the S0
// plane), projected onto that plane, and written as 32-bit ids with a 1/z depth test into a square
// buffer covering [-half, half]^2 of the plane. Only pixels whose centre lies inside the disc of radius
// `half` (S0) are written. Pixel centres are sampled (x + 0.5, y + 0.5); a pixel on a shared edge goes to
// the nearer triangle, and on a tie to the one drawn first (strict depth test): deterministic.

#include <cstdint>
#include <vector>

#include "aloft/math.hpp"

namespace aloft::internal {

class ItemRasterizer {
 public:
  // width x width pixels over the square [-half, half]^2 of the plane z = near.
  void reset(int width, double half, double near);
  // Draw one triangle (camera frame) with `id` (> 0), either winding. Back-face culling is the caller's
  // (the camera frame is left-handed, x right, y up, z forward, so it is clearer done in the world frame).
  void draw(const Vec3& a, const Vec3& b, const Vec3& c, std::uint32_t id);

  int width() const { return width_; }
  double pixel_size() const { return pixel_; }          // m on the plane z = near
  double near() const { return near_; }
  // Plane coordinates (u, v) of pixel (x, y)'s centre.
  double u_of(int x) const { return -half_ + (x + 0.5) * pixel_; }
  double v_of(int y) const { return -half_ + (y + 0.5) * pixel_; }
  // Inclusive x range of row y inside the disc (first > last when none).
  int row_first(int y) const { return row_first_[y]; }
  int row_last(int y) const { return row_last_[y]; }

  // Whether any pixel of the kBlock x kBlock block containing pixel (x, y) was written since reset()
  // (lets the caller skip empty parts of the buffer).
  static constexpr int kBlock = 8;
  bool touched(int x, int y) const { return touched_[static_cast<std::size_t>(y / kBlock) * blocks_ + x / kBlock] != 0; }
  // Whether any block overlapping pixels [x0, x1] x [y0, y1] (inclusive) was written.
  bool any_touched(int x0, int y0, int x1, int y1) const;

  std::vector<std::uint32_t>& ids() { return ids_; }
  const std::vector<std::uint32_t>& ids() const { return ids_; }

 private:
  void draw_clipped(const Vec3* v, std::uint32_t id);

  int width_ = 0;
  double half_ = 0, near_ = 0, pixel_ = 0;
  std::vector<std::uint32_t> ids_;
  std::vector<float> depth_;   // 1/z of the nearest surface so far; 0: none
  std::vector<int> row_first_, row_last_;
  int blocks_ = 0;                      // blocks per row
  std::vector<std::uint8_t> touched_;   // per block
};

}  // namespace aloft::internal
