// The window layer of `aloft view`: GLFW window and events, the frame loop (physics paced against the
// wall clock, then drawing), screenshots and recording. The panel is in viewer_panel.cpp.

#include "viewer.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <stdexcept>

#include "aloft/render/frame_target.hpp"
#include "aloft/render/gl.hpp"
#include "aloft/render/image_output.hpp"
#include "aloft/render/renderer.hpp"
#include "file_camera.hpp"
#include "viewer_state.hpp"

namespace aloft::view {

namespace {

using Clock = WallClock;
constexpr int kWarmupFrames = 10;

// CPU time of the whole process (all threads: llvmpipe rasterises on worker threads), s.
double process_cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

ViewerState& state_of(GLFWwindow* window) { return *static_cast<ViewerState*>(glfwGetWindowUserPointer(window)); }

// Cursor position -> normalised device coordinates (y up).
Vec3 cursor_ray(ViewerState& v, double x, double y) {
  int w = 0, h = 0;
  glfwGetWindowSize(v.window, &w, &h);
  const double nx = 2 * x / std::max(w, 1) - 1, ny = 1 - 2 * y / std::max(h, 1);
  return v.camera.ray_direction(nx, ny, static_cast<double>(std::max(w, 1)) / std::max(h, 1));
}

// Where the cursor ray meets the plane through `point` facing the camera.
Vec3 on_camera_plane(ViewerState& v, double x, double y, const Vec3& point) {
  const Vec3 d = cursor_ray(v, x, y);
  const Vec3 n = v.camera.forward();
  const double denom = d.dot(n);
  if (std::abs(denom) < 1e-9) return point;
  return v.camera.eye() + d * ((point - v.camera.eye()).dot(n) / denom);
}

void on_mouse_button(GLFWwindow* window, int button, int action, int mods) {
  ViewerState& v = state_of(window);
  if (action == GLFW_RELEASE) {
    if (v.drag == Drag::Grab) v.session->release();
    v.drag = Drag::None;
    return;
  }
  if (ImGui::GetIO().WantCaptureMouse) return;
  glfwGetCursorPos(window, &v.last_x, &v.last_y);
  if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_CONTROL)) {
    v.drag = Drag::AimWind;
  } else if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_SHIFT)) {
    v.drag = Drag::Pan;
  } else if (button == GLFW_MOUSE_BUTTON_LEFT) {
    const auto hit = render::pick(v.renderer->scene(), v.session->simulation().state(), v.camera.eye(),
                                  cursor_ray(v, v.last_x, v.last_y));
    if (hit) {
      v.session->grab(Grab{hit->component, hit->point_body, hit->point_world});
      v.drag = Drag::Grab;
    } else {
      v.drag = Drag::Orbit;
    }
  } else {
    v.drag = Drag::Pan;
  }
}

void on_cursor(GLFWwindow* window, double x, double y) {
  ViewerState& v = state_of(window);
  const double dx = x - v.last_x, dy = y - v.last_y;
  v.last_x = x;
  v.last_y = y;
  int h = 0;
  glfwGetWindowSize(window, nullptr, &h);
  switch (v.drag) {
    case Drag::None: break;
    case Drag::Orbit: v.camera.orbit(-dx * 0.006, dy * 0.006); break;
    case Drag::Pan: {
      // One pixel moves the target by one pixel's width at the target's distance.
      const double m_per_px = 2 * v.camera.distance * std::tan(v.camera.fov_y / 2) / std::max(h, 1);
      v.camera.pan(-dx * m_per_px, dy * m_per_px);
      break;
    }
    case Drag::Grab:
      if (v.session->grabbed())
        v.session->move_grab(on_camera_plane(v, x, y, v.session->grabbed()->target));
      break;
    case Drag::AimWind: v.aim_wind(dx, dy); break;
  }
}

void on_scroll(GLFWwindow* window, double, double dy) {
  if (ImGui::GetIO().WantCaptureMouse) return;
  state_of(window).camera.zoom(std::pow(0.88, dy));
}

void on_key(GLFWwindow* window, int key, int, int action, int mods) {
  if (action == GLFW_RELEASE || ImGui::GetIO().WantCaptureKeyboard) return;
  state_of(window).key(key, mods);
}

void on_char(GLFWwindow* window, unsigned int codepoint) {
  if (ImGui::GetIO().WantCaptureKeyboard) return;
  if (codepoint == '?') state_of(window).show_help = !state_of(window).show_help;
}

void on_drop(GLFWwindow* window, int count, const char** paths) {
  if (count > 0) state_of(window).drop(paths[0]);
}

std::string timestamp() {
  char text[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(text, sizeof text, "%Y%m%d-%H%M%S", std::localtime(&now));
  return text;
}

// Read the window's back buffer (what the window shows, panel included).
void read_window(int width, int height, std::vector<std::uint8_t>& out) {
  out.resize(static_cast<std::size_t>(width) * height * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, out.data());
}

}  // namespace

void ViewerState::key(int key, int mods) {
  switch (key) {
    case GLFW_KEY_ESCAPE:
      if (show_help) show_help = false;
      else glfwSetWindowShouldClose(window, 1);
      break;
    case GLFW_KEY_Q: glfwSetWindowShouldClose(window, 1); break;
    case GLFW_KEY_SPACE: session->paused = !session->paused; break;
    case GLFW_KEY_N:
    case GLFW_KEY_RIGHT:
      session->paused = true;
      session->single_step();
      break;
    case GLFW_KEY_R: session->reset(); break;
    case GLFW_KEY_C: camera = framed_camera(); break;
    case GLFW_KEY_H:
    case GLFW_KEY_TAB: show_panel = !show_panel; break;
    case GLFW_KEY_S: shadows = !shadows; break;
    case GLFW_KEY_P:
    case GLFW_KEY_F12: screenshot_requested = true; break;
    case GLFW_KEY_V: toggle_recording(); break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD: session->time_scale = std::min(session->time_scale * 2, 4.0); break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT: session->time_scale = std::max(session->time_scale / 2, 1.0 / 64); break;
#if ALOFT_HAVE_WIND
    case GLFW_KEY_G: session->gust(); break;
    case GLFW_KEY_W: session->wind_control.enabled = !session->wind_control.enabled; break;
    case GLFW_KEY_K: show_cone = !show_cone; break;
    case GLFW_KEY_O: show_occlusion = !show_occlusion; break;
#endif
    default: break;
  }
  (void)mods;
}

void ViewerState::drop(const std::string& path) {
  const std::string before = session->path();
  if (session->load(path)) notify("loaded " + path);
  (void)before;
}

void ViewerState::notify(const std::string& text) {
  message = text;
  message_until = seconds_since(start) + 4;
}

render::OrbitCamera ViewerState::framed_camera() const {
  int w = 1, h = 1;
  glfwGetFramebufferSize(window, &w, &h);
  render::OrbitCamera c = render::framing_camera(renderer->scene(), static_cast<double>(std::max(w, 1)) / std::max(h, 1));
  if (show_panel && w > 3 * kPanelWidth) {
    // Move the mobile right by half the panel's width so the panel does not hide it.
    const double m_per_px = 2 * c.distance * std::tan(c.fov_y / 2) / std::max(h, 1);
    c.pan(-kPanelWidth / 2 * m_per_px, 0);
  }
  c = apply_file_camera(session->spec().camera, c);  // the file's camera, then the flags, key by key
  return adjust_camera ? adjust_camera(c) : c;
}

void ViewerState::aim_wind(double dx, double dy) {
#if ALOFT_HAVE_WIND
  WindControl& w = session->wind_control;
  w.follow_camera = false;
  // Turn the wind's direction about the vertical (dx) and about the horizontal across it (dy).
  const Eigen::AngleAxisd yaw(-dx * 0.006, Vec3::UnitY());
  Vec3 across = w.along.cross(Vec3::UnitY());
  if (across.norm() < 1e-6) across = Vec3::UnitX();
  const Eigen::AngleAxisd pitch(-dy * 0.006, across.normalized());
  const Vec3 turned = (yaw * pitch * w.along).normalized();
  if (std::abs(turned.y()) < 0.95) w.along = turned;  // not straight up or down
#else
  (void)dx;
  (void)dy;
#endif
}

void ViewerState::toggle_recording() {
  if (recorder) {
    try {
      recorder->finish();
      notify("recorded " + recorder->path() + " (" + std::to_string(recorder->frames()) + " frames)");
    } catch (const std::exception& e) {
      notify(e.what());
    }
    recorder.reset();
    return;
  }
  const std::string path = "aloft-" + timestamp() + ".mp4";
  try {
    recorder = std::make_unique<render::VideoEncoder>(path, target->width(), target->height(), kRecordFps);
    record_next = session->simulation().state().time;
    notify("recording " + path + " (V to stop)");
  } catch (const std::exception& e) {
    notify(e.what());
  }
}

int run_viewer(const ViewerOptions& options) {
  ViewerState v;
  v.session = std::make_unique<MobileSession>(options.file, options.build);  // a bad first file throws here
#if ALOFT_HAVE_WIND
  v.session->set_file_winds_on_load(options.file_wind);
  for (std::size_t i = 0; i < v.session->file_winds().size(); ++i) v.session->set_file_wind_enabled(i, options.file_wind);
#endif
  v.session->time_scale = options.time_scale;
  v.adjust_camera = options.adjust_camera;
  v.shadows = options.shadows;
  v.samples = options.samples;
  v.show_cone = options.show_cone;
  v.show_occlusion = options.show_occlusion;
  v.start = Clock::now();
#if ALOFT_HAVE_WIND
  v.session->wind_control.enabled = options.wind;
  v.session->wind_control.breeze = options.breeze;
#endif
  if (options.microphone) v.open_microphone();

  glfwSetErrorCallback([](int, const char* text) { std::fprintf(stderr, "aloft: glfw: %s\n", text); });
  if (!glfwInit())
    throw std::runtime_error("cannot open a window (no display?): use 'aloft render' to make a video without one");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 0);  // anti-aliasing happens in our own multisampled framebuffer
  const std::string title = "Aloft - " + v.session->model().name;
  v.window = glfwCreateWindow(options.width, options.height, title.c_str(), nullptr, nullptr);
  if (!v.window) {
    glfwTerminate();
    throw std::runtime_error("cannot create an OpenGL 3.3 core window");
  }
  glfwMakeContextCurrent(v.window);
  glfwSwapInterval(options.frames > 0 ? 0 : 1);
  glfwSetWindowUserPointer(v.window, &v);
  // Ours first: ImGui's backend calls the callbacks installed before it.
  glfwSetMouseButtonCallback(v.window, on_mouse_button);
  glfwSetCursorPosCallback(v.window, on_cursor);
  glfwSetScrollCallback(v.window, on_scroll);
  glfwSetKeyCallback(v.window, on_key);
  glfwSetCharCallback(v.window, on_char);
  glfwSetDropCallback(v.window, on_drop);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the user's directory
  style_panel();
  ImGui_ImplGlfw_InitForOpenGL(v.window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");

  int exit_code = 0;
  {
    render::Renderer renderer;
    render::FrameTarget target;
    v.renderer = &renderer;
    v.target = &target;
    int uploaded = -1;
    long long frame = 0;
    auto last = Clock::now();
    double reload_clock = 0;
    std::vector<std::uint8_t> pixels;
    bool camera_set = false;

    while (!glfwWindowShouldClose(v.window)) {
      glfwPollEvents();
      // Test hooks act through the same paths as a user would.
      if (frame == options.drop_frame) v.drop(options.drop_file);
      if (frame == options.quit_frame) v.key(GLFW_KEY_Q, 0);
      if (glfwWindowShouldClose(v.window)) break;

      const auto now = Clock::now();
      const auto frame_start = now;
      const double wall_dt = options.frames > 0 ? 1.0 / 60 : std::chrono::duration<double>(now - last).count();
      last = now;

      int fb_w = 0, fb_h = 0;
      glfwGetFramebufferSize(v.window, &fb_w, &fb_h);
      if (fb_w <= 0 || fb_h <= 0 || glfwGetWindowAttrib(v.window, GLFW_ICONIFIED)) {
        // Minimised: nothing to draw; physics waits too (the wall clock restarts on return).
        glfwWaitEventsTimeout(0.1);
        last = Clock::now();
        continue;
      }

      // A designer edits the file: reload (polled a few times a second).
      reload_clock += wall_dt;
      if (reload_clock > 0.3) {
        reload_clock = 0;
        if (v.session->reload_if_changed() && v.session->error().empty()) v.notify("reloaded " + v.session->path());
      }
      if (uploaded != v.session->model_generation()) {
        renderer.set_model(v.session->model());
        uploaded = v.session->model_generation();
        glfwSetWindowTitle(v.window, ("Aloft - " + v.session->model().name).c_str());
        if (!camera_set) {
          v.camera = v.framed_camera();
          camera_set = true;
        }
      }

#if ALOFT_HAVE_WIND
      v.poll_microphone();
      v.session->update_wind(v.camera.forward());
#endif
      // Physics: real time (x time scale), at most 12 ms of compute per frame so the display keeps up.
      const double simulated = v.session->advance(wall_dt, options.frames > 0 ? 1e9 : 0.012);
      v.stats.add(wall_dt, simulated, v.session->last_physics_seconds(), v.session->last_wind_seconds());

      // Draw the scene into the multisampled target, resolve, show.
      const auto render_start = Clock::now();
      target.resize(fb_w, fb_h, v.samples);
      target.bind();
      render::DrawOptions draw;
      draw.shadows = v.shadows;
      draw.mobile = !options.hide_mobile;
      draw.highlighted = v.session->grabbed() ? v.session->grabbed()->component : -1;
      if (v.glow_touching) v.session->touching_now(draw.glowing);
      renderer.draw(v.session->simulation().state(), v.camera, fb_w, fb_h, draw, v.overlay_lines());
      target.resolve();
      const bool last_test_frame = options.frames > 0 && frame + 1 >= options.frames;
      if (v.screenshot_requested || v.recorder || (last_test_frame && !options.screenshot.empty()))
        target.read_rgba(pixels);
      target.blit_to(0, fb_w, fb_h);

      if (v.recorder) {
        // Frames at a fixed rate of simulated time, so the video plays at the speed the mobile moved.
        const double t = v.session->simulation().state().time;
        try {
          while (v.record_next <= t + 1e-9) {
            v.recorder->add_frame(pixels);
            v.record_next += 1.0 / kRecordFps;
          }
        } catch (const std::exception& e) {
          v.notify(e.what());
          v.recorder.reset();
        }
      }
      if (v.screenshot_requested) {
        v.screenshot_requested = false;
        const std::string path = "aloft-" + timestamp() + ".png";
        try {
          render::write_png(path, fb_w, fb_h, pixels);
          v.notify("saved " + path);
        } catch (const std::exception& e) {
          v.notify(e.what());
        }
      }

      // The panel on top.
      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      v.draw_panel();
      ImGui::Render();
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      glViewport(0, 0, fb_w, fb_h);
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
      glFinish();  // the render time below is the whole frame's drawing, not only its submission
      v.stats.add_render(seconds_since(render_start));
      if (frame == kWarmupFrames) v.totals.cpu_start = process_cpu_seconds();
      if (frame >= kWarmupFrames) {
        // Totals for the exit summary, after the first frames (shader compilation, first uploads).
        v.totals.frames += 1;
        v.totals.physics += v.session->last_physics_seconds();
        v.totals.wind += v.session->last_wind_seconds();
        v.totals.render += seconds_since(render_start);
        v.totals.wall += seconds_since(frame_start);
      }

      ++frame;
      // Keep 60 frames per second: when frames run slower than 55 per second (the margin keeps a display's
      // vsync at exactly 60 from counting) for two seconds with anti-aliasing on (the costliest part of a
      // frame on a software renderer: 19 ms against 12 ms without it, Steel Fish at 1280 x 720 on this
      // project's 2-core machine, docs/performance.md), turn it off once and say so.
      if (options.frames == 0 && v.samples > 1 && !v.auto_quality_done) {
        v.slow_seconds = v.stats.frame_seconds > 1.0 / 55 ? v.slow_seconds + wall_dt : 0;
        if (v.slow_seconds > 2) {
          v.samples = 0;
          v.auto_quality_done = true;
          v.notify("anti-aliasing off to keep the frame rate (View > anti-aliasing turns it back on)");
        }
      }
      if (options.frames > 0 && frame >= options.frames) {
        try {
          if (!options.screenshot.empty()) render::write_png(options.screenshot, fb_w, fb_h, pixels);
          if (!options.window_screenshot.empty()) {
            std::vector<std::uint8_t> window_pixels;
            read_window(fb_w, fb_h, window_pixels);
            render::write_png(options.window_screenshot, fb_w, fb_h, window_pixels);
          }
        } catch (const std::exception& e) {
          std::fprintf(stderr, "aloft: error: %s\n", e.what());
          exit_code = 1;
        }
        glfwSetWindowShouldClose(v.window, 1);
      }
      glfwSwapBuffers(v.window);
    }
    if (v.recorder) v.toggle_recording();
    if (options.frames > 0 || options.quit_frame >= 0) {
      const Simulation& sim = v.session->simulation();
      std::printf("view: %lld frames; mobile \"%s\" (%s); t = %.4f s simulated; error: %s\n", frame,
                  v.session->model().name.c_str(), v.session->path().c_str(), sim.state().time,
                  v.session->error().empty() ? "none" : v.session->error().c_str());
      if (v.totals.frames > 0) {
        const double n = static_cast<double>(v.totals.frames);
        std::printf("view: per frame (mean of %lld after %d warm-up): %.2f ms = physics %.2f + wind %.2f + render %.2f "
                    "+ other %.2f ms\n",
                    v.totals.frames, kWarmupFrames, v.totals.wall / n * 1e3, v.totals.physics / n * 1e3,
                    v.totals.wind / n * 1e3, v.totals.render / n * 1e3,
                    (v.totals.wall - v.totals.physics - v.totals.wind - v.totals.render) / n * 1e3);
        std::printf("view: process CPU time per frame (all threads) %.2f ms\n",
                    (process_cpu_seconds() - v.totals.cpu_start) / n * 1e3);
      }
      std::fflush(stdout);
    }
    v.renderer = nullptr;
    v.target = nullptr;
  }  // GL objects are deleted while the context still exists

  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(v.window);
  glfwTerminate();
  return exit_code;
}

}  // namespace aloft::view
