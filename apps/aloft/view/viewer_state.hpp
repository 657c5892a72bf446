#pragma once
// The viewer's state between frames, shared by the window layer (viewer.cpp) and the panel
// (viewer_panel.cpp).

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "aloft/render/camera.hpp"
#include "aloft/render/frame_target.hpp"
#include "aloft/render/image_output.hpp"
#include "aloft/render/renderer.hpp"
#include "aloft/wall_clock.hpp"
#include "mobile_session.hpp"

struct GLFWwindow;

namespace aloft::view {

inline constexpr double kRecordFps = 30;   // recorded videos: frames per simulated second
inline constexpr float kPanelWidth = 310;  // pixels

enum class Drag { None, Orbit, Pan, Grab, AimWind };

// Frame statistics, smoothed over about half a second.
struct FrameStats {
  double frame_seconds = 1.0 / 60;   // wall time per frame
  double realtime = 1;               // simulated / wall seconds
  double physics = 0, wind = 0, render = 0;  // s per frame
  void add(double wall, double simulated, double physics_s, double wind_s) {
    constexpr double k = 0.05;
    frame_seconds += k * (wall - frame_seconds);
    if (wall > 0) realtime += k * (simulated / wall - realtime);
    physics += k * (physics_s - physics);
    wind += k * (wind_s - wind);
  }
  void add_render(double seconds) { render += 0.05 * (seconds - render); }
};

struct MicrophoneInput;  // viewer_microphone.cpp

struct ViewerState {
  ViewerState();
  ~ViewerState();
  GLFWwindow* window = nullptr;
  std::unique_ptr<MobileSession> session;
  render::Renderer* renderer = nullptr;
  render::FrameTarget* target = nullptr;
  render::OrbitCamera camera;
  std::function<render::OrbitCamera(render::OrbitCamera)> adjust_camera;
  WallClock::time_point start;

  // Display.
  bool show_panel = true;
  bool show_help = false;
  bool shadows = true;
  bool glow_touching = true;  // pieces touching another at the last step drawn with a glow (Contacts panel)
  int samples = 4;
  bool auto_quality_done = false;    // anti-aliasing was switched off once for speed (never again)
  double slow_seconds = 0;           // how long frames have been slower than 20 ms
  bool show_cone = false;
  bool show_occlusion = false;
  FrameStats stats;
  struct {
    long long frames = 0;
    double wall = 0, physics = 0, wind = 0, render = 0;  // s, summed
    double cpu_start = 0;                                 // process CPU time when counting began, s
  } totals;

  // Input.
  Drag drag = Drag::None;
  double last_x = 0, last_y = 0;

  // Microphone (null when not opened).
  std::unique_ptr<MicrophoneInput> microphone;
  float mic_gain = 25;               // m/s of v0 per unit RMS above the noise floor

  // Capture.
  bool screenshot_requested = false;
  std::unique_ptr<render::VideoEncoder> recorder;
  double record_next = 0;            // simulated time of the next recorded frame, s

  // A short message shown for a few seconds (saved files, reloads).
  std::string message;
  double message_until = 0;

  void key(int key, int mods);
  void drop(const std::string& path);
  void notify(const std::string& text);
  void aim_wind(double dx, double dy);
  void toggle_recording();
  render::OrbitCamera framed_camera() const;
  void open_microphone();
  void poll_microphone();
  void draw_microphone_controls();
  std::vector<render::LineSet> overlay_lines() const;
  void draw_panel();
};

// Colours and spacing of the panel.
void style_panel();

}  // namespace aloft::view
