#include "aloft/render/frame_target.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "aloft/render/gl.hpp"
#include "gl_program.hpp"

namespace aloft::render {

namespace {

// The target last bound on this thread (FrameTarget::bound() checks it is still the draw framebuffer).
thread_local FrameTarget* last_bound = nullptr;

// An RGBA8 texture to render into (glTexImage2D: glTexStorage2D is not in OpenGL 3.3).
GLuint make_color_texture(int width, int height) {
  GLuint texture = 0;
  glGenTextures(1, &texture);
  glBindTexture(GL_TEXTURE_2D, texture);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  // Read with texelFetch only, but a texture needs complete filtering state to be sampled at all.
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glBindTexture(GL_TEXTURE_2D, 0);
  return texture;
}

GLuint make_renderbuffer(GLenum format, int width, int height, int samples) {
  GLuint buffer = 0;
  glGenRenderbuffers(1, &buffer);
  glBindRenderbuffer(GL_RENDERBUFFER, buffer);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, width, height);
  glBindRenderbuffer(GL_RENDERBUFFER, 0);
  return buffer;
}

void check_complete(const char* what) {
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error(std::string("the driver cannot make ") + what);
}

}  // namespace

FrameTarget::~FrameTarget() {
  release();
  if (last_bound == this) last_bound = nullptr;
}

void FrameTarget::release() {
  for (GLuint fbo : {frame_fbo_, background_fbo_, msaa_fbo_})
    if (fbo) glDeleteFramebuffers(1, &fbo);
  for (GLuint texture : {frame_color_, background_lit_, background_unlit_})
    if (texture) glDeleteTextures(1, &texture);
  for (GLuint buffer : {frame_depth_, background_depth_, msaa_color_[0], msaa_color_[1], msaa_depth_})
    if (buffer) glDeleteRenderbuffers(1, &buffer);
  frame_fbo_ = frame_color_ = frame_depth_ = 0;
  background_fbo_ = background_lit_ = background_unlit_ = background_depth_ = 0;
  msaa_fbo_ = msaa_color_[0] = msaa_color_[1] = msaa_depth_ = 0;
  background_key_.clear();
  pending_resolve_.clear();
}

void FrameTarget::resize(int width, int height, int samples) {
  width = std::max(width, 1);
  height = std::max(height, 1);
  if (width == width_ && height == height_ && samples == requested_samples_) return;
  release();
  GLint max_samples = 1;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  samples_ = std::clamp(samples, 0, static_cast<int>(max_samples));
  if (samples_ <= 1) samples_ = 0;
  width_ = width;
  height_ = height;
  requested_samples_ = samples;

  frame_color_ = make_color_texture(width, height);
  frame_depth_ = make_renderbuffer(GL_DEPTH_COMPONENT24, width, height, 0);
  glGenFramebuffers(1, &frame_fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, frame_fbo_);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, frame_color_, 0);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, frame_depth_);
  check_complete("a framebuffer to draw into");

  const GLenum both[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  background_lit_ = make_color_texture(width, height);
  background_unlit_ = make_color_texture(width, height);
  background_depth_ = make_renderbuffer(GL_DEPTH_COMPONENT24, width, height, 0);
  glGenFramebuffers(1, &background_fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, background_fbo_);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, background_lit_, 0);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, background_unlit_, 0);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, background_depth_);
  glDrawBuffers(2, both);
  check_complete("a framebuffer for the background");

  if (samples_ > 0) {
    msaa_color_[0] = make_renderbuffer(GL_RGBA8, width, height, samples_);
    msaa_color_[1] = make_renderbuffer(GL_RGBA8, width, height, samples_);
    msaa_depth_ = make_renderbuffer(GL_DEPTH_COMPONENT24, width, height, samples_);
    glGenFramebuffers(1, &msaa_fbo_);
    glBindFramebuffer(GL_FRAMEBUFFER, msaa_fbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, msaa_color_[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_RENDERBUFFER, msaa_color_[1]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, msaa_depth_);
    glDrawBuffers(2, both);
    check_complete("a multisampled framebuffer");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("creating the frame buffers");
}

void FrameTarget::bind() {
  glBindFramebuffer(GL_FRAMEBUFFER, frame_fbo_);
  glViewport(0, 0, width_, height_);
  last_bound = this;
}

FrameTarget* FrameTarget::bound() {
  if (!last_bound || !last_bound->frame_fbo_) return nullptr;
  GLint draw_fbo = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_fbo);
  return static_cast<GLuint>(draw_fbo) == last_bound->frame_fbo_ ? last_bound : nullptr;
}

void FrameTarget::resolve() {
  if (!pending_resolve_.empty()) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, msaa_fbo_);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, frame_fbo_);
    // Same rectangle on both sides, as OpenGL ES requires for a multisample resolve.
    for (const auto& [x, y, w, h] : pending_resolve_)
      glBlitFramebuffer(x, y, x + w, y + h, x, y, x + w, y + h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  pending_resolve_.clear();
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void FrameTarget::read_rgba(std::vector<std::uint8_t>& out) {
  out.resize(static_cast<std::size_t>(width_) * height_ * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, frame_fbo_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, out.data());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
}

void FrameTarget::blit_to(unsigned target, int target_width, int target_height) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, frame_fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, target_width, target_height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, target);
}

}  // namespace aloft::render
