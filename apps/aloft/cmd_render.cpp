// aloft render: the mobile as it moves, rendered with no window (OpenGL through EGL, no X server) to a
// video, a still PNG or a directory of PNG frames. The same renderer as `aloft view`.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "aloft/contact_tally.hpp"
#include "aloft/render/frame_target.hpp"
#include "aloft/render/headless_context.hpp"
#include "aloft/render/image_output.hpp"
#include "aloft/render/renderer.hpp"
#include "aloft/simulation.hpp"
#include "common.hpp"
#include "progress.hpp"
#include "view/camera_flags.hpp"
#include "wind_options.hpp"

namespace aloft::cli {

Runner add_render(CLI::App& app) {
  struct Options {
    std::string file;
    std::string balance = "file";
    double duration = 5;
    std::string out;
    int width = 1280;
    int height = 720;
    double fps = 30;
    int samples = 4;
    bool no_shadows = false;
    bool glow_touching = false;
    bool quiet = false;
    CameraFlags camera;
    WindOptions wind;
  };
  auto o = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("render", "Render a mobile as it moves to a video or images, with no window");
  sub->add_option("file", o->file, "The mobile file (JSON)")->type_name("FILE")->required();
  sub->add_option("-o,--out", o->out, "Output: a video (.mp4 .gif .webm .mkv), one image (.png: the last frame) or "
                                      "a directory for PNG frames (ends with /)")
      ->type_name("PATH")
      ->required();
  sub->add_option("-t,--duration", o->duration, format("Simulated time (s, > 0, up to %g)", kLongestDuration))
      ->type_name("T")
      ->capture_default_str()
      ->check(duration_in_seconds());
  add_balance_option(sub, o->balance);
  sub->add_option("--width", o->width, "Image width (pixels)")->capture_default_str()->check(integer_in(16, 8192));
  sub->add_option("--height", o->height, "Image height (pixels)")->capture_default_str()->check(integer_in(16, 8192));
  sub->add_option("--fps", o->fps, "Frames per simulated second (1..240)")
      ->capture_default_str()
      ->check(number_in(1.0, 240.0));
  sub->add_option("--msaa", o->samples, "Anti-aliasing samples per pixel (0 or 1: off)")
      ->capture_default_str()
      ->check(integer_in(0, 16));
  sub->add_flag("--no-shadows", o->no_shadows, "Draw without shadows");
  sub->add_flag("--glow-touching", o->glow_touching,
                "Draw the pieces that touched another since the frame before (within 1/fps s) with a warm glow");
  sub->add_flag("-q,--quiet", o->quiet, "No progress line and no summary");
  o->camera.add_to(sub);
  add_wind_options(sub, o->wind);
  sub->footer(
      "Simulates the mobile from its designed pose at rest (as 'aloft simulate') and draws a frame every\n"
      "1/fps simulated seconds: frames at t = 0, 1/fps, ... (duration x fps of them). Rendering is offscreen\n"
      "through EGL on Mesa: no display or X server is needed. Videos are encoded by ffmpeg.\n"
      "\n"
      "Examples:\n"
      "  aloft render mobiles/steel-fish.json --balance none --duration 10 --out fish.mp4\n"
      "  aloft render mobiles/southern-cross.json --duration 0.001 --out cross.png --width 1920 --height 1080\n"
      "  aloft render mobiles/steel-fish.json -t 4 --fps 15 --width 480 --height 270 --out fish.gif\n"
      "  aloft render mobiles/steel-fish.json -t 2 --out frames/ --yaw 30 --pitch 20 --distance 5\n"
      "  aloft render mobiles/steel-fish.json -t 8 --wind 2 --out breeze.mp4   # a steady breath from the front\n"
      "  aloft render big.json -t 10 --wind 3 --glow-touching --out knocks.mp4   # which pieces knock together\n"
      "\n"
      "Wind: as in 'aloft simulate' (--wind, --wind-speed, --wind-audio and the source flags); the mobile\n"
      "file's \"wind_sources\" blow too, unless --no-file-wind.\n"
      "Camera: the mobile file's \"camera\" where it has one; each camera flag overrides its key.\n");
  return [o] {
    const LoadedMobile loaded = load_mobile_with_spec(o->file, o->balance);
    const Model& model = loaded.model;
    Simulation sim(model);
    WindSet wind(model, loaded.spec, sim.state(), o->wind, sim.timestep());
    long long steps = 0;
    const double frame_time = 1 / o->fps;
    // --glow-touching: the pairs that touched in the steps of the frame interval being stepped through
    // (the 1/fps s before the frame; a still's too), taken and cleared as each frame is drawn.
    ContactTally touched;
    // Physics up to simulated time t: each wind's occlusion refreshed every refresh_every steps, the
    // forces applied at every step (as 'aloft simulate' does).
    const auto advance_to = [&](double t) {
      while (sim.state().time < t - 0.5 * sim.timestep()) {
        wind.apply(steps, sim.state(), sim.timestep(), sim.loads());
        if (!sim.step()) return false;
        ++steps;
        if (o->glow_touching && sim.collisions() && sim.state().time > t - frame_time + 0.5 * sim.timestep())
          touched.add_step(sim.contacts(), sim.pushed_pairs(), sim.state().time);
      }
      return true;
    };

    render::HeadlessContext context;
    render::Renderer renderer;
    renderer.set_model(model);
    render::FrameTarget target;
    target.resize(o->width, o->height, o->samples);
    const render::OrbitCamera camera =
        o->camera.apply(loaded.spec.camera,
                        render::framing_camera(renderer.scene(), static_cast<double>(o->width) / o->height));
    render::DrawOptions options;
    options.shadows = !o->no_shadows;

    render::FrameSink sink(o->out, o->width, o->height, o->fps);
    const long long frames = sink.wants_every_frame() ? std::max(1LL, std::llround(o->duration * o->fps)) : 1;
    std::vector<std::uint8_t> pixels;
    ProgressReport progress(!o->quiet, frames, "rendering", 0.0);
    const auto start = WallClock::now();
    const auto draw_frame = [&] {
      if (o->glow_touching) {
        touched.components_touching_since(-INFINITY, model.count, options.glowing);
        touched = ContactTally{};
      }
      target.bind();
      renderer.draw(sim.state(), camera, o->width, o->height, options);
      target.resolve();
      target.read_rgba(pixels);
      sink.add_frame(pixels);
    };
    if (!sink.wants_every_frame()) {
      // One still: the mobile at t = duration.
      if (!advance_to(o->duration)) {
        print_error(sim.failure() ? sim.failure()->message : "the simulation failed");
        return kExitSimulation;
      }
      draw_frame();
    } else {
      for (long long k = 0; k < frames; ++k) {
        // Frame k shows t = k / fps: step the physics up to that time first.
        const double t = static_cast<double>(k) * frame_time;
        if (!advance_to(t)) {
          progress.finish();
          sink.finish();
          print_error(sim.failure() ? sim.failure()->message : "the simulation failed");
          return kExitSimulation;
        }
        draw_frame();
        if (progress.due(k + 1)) progress.show(k + 1, format("frame %lld of %lld", k + 1, frames));
      }
    }
    progress.finish();
    const std::string written = sink.finish();
    const double wall = seconds_since(start);
    if (!o->quiet) {
      std::printf("mobile     %s\n", model.name.c_str());
      for (const WindDriver& d : wind.drivers()) std::printf("wind       %s\n", d.description.c_str());
      std::printf("written    %s (%s, %.3g s simulated)\n", o->out.c_str(), written.c_str(), sim.state().time);
      std::printf("wall time  %.2f s (%.1f frames/s) on %s\n", wall, static_cast<double>(frames) / wall,
                  context.description().c_str());
      std::fflush(stdout);
    }
    return kExitOk;
  };
}

static const CommandRegistration registration{"render", 60, add_render};

}  // namespace aloft::cli
