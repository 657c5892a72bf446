#pragma once
// An offscreen, multisampled colour + depth framebuffer to draw the scene into, resolved into a
// single-sample one that can be read back (screenshots, video frames) or shown (blitted to a window).

#include <cstdint>
#include <vector>

namespace aloft::render {

class FrameTarget {
 public:
  FrameTarget() = default;
  ~FrameTarget();
  FrameTarget(const FrameTarget&) = delete;
  FrameTarget& operator=(const FrameTarget&) = delete;

  // (Re)allocate for width x height pixels and `samples` MSAA samples per pixel (clamped to what the
  // driver offers; 1 or less: no multisampling). Does nothing when unchanged. Needs a current context.
  void resize(int width, int height, int samples);
  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }

  void bind();            // draw into the multisampled buffer
  void resolve();         // average the samples into the readable buffer
  // The resolved image as RGBA8, rows bottom-up as OpenGL stores them (call resolve() first).
  void read_rgba(std::vector<std::uint8_t>& out);
  // Copy the resolved image into framebuffer `target` (0: the window) at the same size.
  void blit_to(unsigned target, int target_width, int target_height);

 private:
  void release();
  unsigned msaa_fbo_ = 0, msaa_color_ = 0, msaa_depth_ = 0;
  unsigned resolved_fbo_ = 0, resolved_color_ = 0;
  int width_ = 0, height_ = 0, samples_ = 0, requested_samples_ = -1;
};

}  // namespace aloft::render
