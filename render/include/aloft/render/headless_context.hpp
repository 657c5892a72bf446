#pragma once
// An OpenGL 3.3 core context with no window and no X server: EGL on Mesa's surfaceless platform. Draw
// into a FrameTarget; the context has no default framebuffer.

#include <string>

namespace aloft::render {

class HeadlessContext {
 public:
  // Creates the context and makes it current on this thread. Throws std::runtime_error saying what is
  // missing (no EGL display, no OpenGL 3.3 core support).
  HeadlessContext();
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

  // "OpenGL <version> (<renderer>)", e.g. "OpenGL 4.5 (Mesa) (llvmpipe (LLVM 15.0.6, 256 bits))".
  std::string description() const;

 private:
  void* display_ = nullptr;
  void* context_ = nullptr;
};

}  // namespace aloft::render
