#pragma once
// An offscreen picture to draw the scene into: a single-sample colour + depth framebuffer that can be
// read back (screenshots, video frames) or shown (blitted to a window), plus what the Renderer keeps
// with it to draw fast on a software rasteriser:
//  - a cached background: the room shaded once, fully lit and fully shadowed (two pictures), reused
//    while the camera, the size and the model stay the same (the room does not move; only the mobile
//    and its shadow do);
//  - a multisampled buffer for anti-aliasing, used only over the screen rectangle that holds the
//    mobile (and any overlay lines), then resolved into the picture.
//
// Use: bind(); Renderer::draw(...); resolve(); then read_rgba() or blit_to(). A Renderer drawing while
// a FrameTarget is bound (bind()) finds it and uses these buffers; anything else drawn after bind()
// goes into the single-sample picture.

#include <array>
#include <cstdint>
#include <vector>

namespace aloft::render {

class Renderer;

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

  void bind();            // draw into the picture (a Renderer drawing now uses this target's buffers)
  void resolve();         // finish the picture: average the anti-aliased rectangle's samples into it
  // The picture as RGBA8, rows bottom-up as OpenGL stores them (call resolve() first).
  void read_rgba(std::vector<std::uint8_t>& out);
  // Copy the picture into framebuffer `target` (0: the window) at the same size.
  void blit_to(unsigned target, int target_width, int target_height);

  // The FrameTarget whose picture is the current draw framebuffer (bound with bind() on this thread),
  // or nullptr.
  static FrameTarget* bound();

 private:
  friend class Renderer;
  void release();

  // The picture: colour texture (read by the anti-aliasing pass) and depth.
  unsigned frame_fbo_ = 0, frame_color_ = 0, frame_depth_ = 0;
  // The cached background: attachment 0 the room fully lit, 1 fully shadowed (textures), and depth.
  unsigned background_fbo_ = 0, background_lit_ = 0, background_unlit_ = 0, background_depth_ = 0;
  // Multisampled colour (two attachments, as the background) and depth; none when samples_ is 0.
  unsigned msaa_fbo_ = 0, msaa_color_[2] = {0, 0}, msaa_depth_ = 0;
  int width_ = 0, height_ = 0, samples_ = 0, requested_samples_ = -1;

  // Kept by the Renderer: what the cached background shows (empty: nothing yet), the samples it was
  // drawn with, whether it was redrawn on the last frame, and the rectangles (x, y, width, height in
  // pixels) of the multisampled buffer still to resolve into the picture.
  std::vector<float> background_key_;
  int background_samples_ = 0;
  bool background_redrawn_ = false;
  std::vector<std::array<int, 4>> pending_resolve_;
};

}  // namespace aloft::render
