#pragma once
// The interactive viewer behind `aloft view`: a GLFW window with an OpenGL 3.3 core context, the gallery
// renderer, a Dear ImGui panel, mouse and keys. The window, input and (future) audio layers are kept
// thin; what they act on is MobileSession (no GL) and Renderer (GL only).

#include <functional>
#include <optional>
#include <string>

#include "aloft/render/camera.hpp"
#include "mobile_session.hpp"

namespace aloft::view {

struct ViewerOptions {
  std::string file;
  BuildSettings build;
  int width = 1280, height = 720;        // window size, screen pixels
  int samples = 4;                       // MSAA samples (0: off)
  bool shadows = true;
  double time_scale = 1.0;
  // Applied to the framing camera after the file's "camera" (the flags: they override the file per key).
  std::function<render::OrbitCamera(render::OrbitCamera)> adjust_camera;
  bool wind = true;                      // the wind module (if built in) on at start
  double breeze = 0;                     // m/s, steady wind at start (0 to kStrongestBreeze)
  bool show_cone = false;                // the wind cone drawn at start (K toggles it)
  bool show_occlusion = false;           // what the wind reaches drawn at start (O toggles it)
  bool microphone = true;                // open the default capture device (its absence is fine)
  bool file_wind = true;                 // the mobile file's wind sources on at start (each toggles in the panel)

  // Test hooks. frames > 0: run exactly that many frames with a fixed 1/60 s of simulated time per
  // frame (deterministic), save `screenshot` (the scene) and `window_screenshot` (with the panel) of the
  // last one, print a status line and exit 0.
  int frames = 0;
  std::string screenshot;
  std::string window_screenshot;
  bool hide_mobile = false;              // draw the room only (the "empty scene" of the tests)
  int drop_frame = -1;                   // at this frame, drop `drop_file` on the window
  std::string drop_file;
  int quit_frame = -1;                   // at this frame, press the quit key
};

// Runs until the window closes. Returns the process exit code; throws only for a bad first file.
int run_viewer(const ViewerOptions& options);

}  // namespace aloft::view
