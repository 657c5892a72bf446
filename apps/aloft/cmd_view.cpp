// aloft view: the interactive viewer (a window: the mobile in a gallery, moving in real time; blow on
// it, pull it, change it, record it). The window code is in view/.

#include <cmath>
#include <memory>

#include "common.hpp"
#include "view/camera_flags.hpp"
#include "view/viewer.hpp"
#include "wind_options.hpp"

namespace aloft::cli {

Runner add_view(CLI::App& app) {
  struct Options {
    view::ViewerOptions viewer;
    std::string balance = "file";
    CameraFlags camera;
    bool no_shadows = false;
    bool no_wind = false;
    bool no_mic = false;
    bool no_file_wind = false;
  };
  auto o = std::make_shared<Options>();
  o->viewer.file = source_dir() + "/mobiles/steel-fish.json";
  CLI::App* sub = app.add_subcommand("view", "Open a window on a mobile: watch it move, blow on it, pull it");
  sub->add_option("file", o->viewer.file, "The mobile file (JSON); default: the Steel Fish")->type_name("FILE");
  add_balance_option(sub, o->balance);
  sub->add_option("--width", o->viewer.width, "Window width (pixels)")->capture_default_str()->check(integer_in(64, 8192));
  sub->add_option("--height", o->viewer.height, "Window height (pixels)")
      ->capture_default_str()
      ->check(integer_in(64, 8192));
  sub->add_option("--msaa", o->viewer.samples, "Anti-aliasing samples per pixel (0: off)")
      ->capture_default_str()
      ->check(integer_in(0, 16));
  sub->add_flag("--no-shadows", o->no_shadows, "Start with shadows off (S toggles them)");
  sub->add_option("--time-scale", o->viewer.time_scale, "Simulated seconds per second (1/64 to 4; 1: real time; < 1: slow motion)")
      ->capture_default_str()
      ->check(number_in(1.0 / 64, 4.0));
  sub->add_option("--breeze", o->viewer.breeze,
                  format("Steady wind speed v0 at S0 at start (m/s, 0 to %g)", view::kStrongestBreeze))
      ->capture_default_str()
      ->check(number_in(0.0, view::kStrongestBreeze));
  sub->add_flag("--no-wind", o->no_wind, "Start with the wind off (W toggles it)");
  sub->add_flag("--no-mic", o->no_mic, "Do not open the microphone");
  add_no_file_wind_flag(sub, o->no_file_wind);
  sub->add_flag("--show-cone", o->viewer.show_cone, "Show the wind's cone from the start (K toggles it)");
  sub->add_flag("--show-occlusion", o->viewer.show_occlusion,
                "Show what the wind reaches (the occlusion result) from the start (O toggles it)");
  o->camera.add_to(sub);
  sub->add_option("--frames", o->viewer.frames,
                  "Run exactly N frames (1/60 s of simulated time each), save --screenshot and exit")
      ->type_name("N")
      ->check(integer_in(1, 100000000))
      ->group("Testing");
  sub->add_option("--screenshot", o->viewer.screenshot, "With --frames: save the last frame's scene (PNG)")
      ->type_name("FILE")
      ->group("Testing");
  sub->add_option("--window-screenshot", o->viewer.window_screenshot,
                  "With --frames: save the last frame's whole window, panel included (PNG)")
      ->type_name("FILE")
      ->group("Testing");
  sub->add_flag("--hide-mobile", o->viewer.hide_mobile, "Draw the empty room only")->group("Testing");
  sub->add_option("--drop-at", o->viewer.drop_frame, "At frame K, drop --drop-file on the window")
      ->type_name("K")
      ->check(integer_in(0, 100000000))
      ->group("Testing");
  sub->add_option("--drop-file", o->viewer.drop_file, "The file dropped at --drop-at")->type_name("FILE")->group("Testing");
  sub->add_option("--quit-at", o->viewer.quit_frame, "At frame K, press the quit key (Q)")
      ->type_name("K")
      ->check(integer_in(0, 100000000))
      ->group("Testing");
  sub->footer(
      "Opens a window (OpenGL 3.3; software rendering is fine) with the mobile in a gallery, simulated in\n"
      "real time. Press ? in the window for the keys. Drop a mobile file on the window to open it; the file\n"
      "shown is reloaded whenever it changes on disk, and errors in it are shown in the window while the\n"
      "last good mobile keeps moving. Without a display, use 'aloft render'.\n"
      "\n"
      "The mobile file's \"camera\" sets the starting camera (and the one C goes back to); each camera\n"
      "flag overrides its key. The file's \"wind_sources\" (fans, vents) blow along with your own wind;\n"
      "the panel lists them, each with its switch (--no-file-wind: all start off).\n"
      "\n"
      "Examples:\n"
      "  aloft view\n"
      "  aloft view mobiles/southern-cross.json --breeze 1.5\n"
      "  aloft view my-mobile.json --balance none --time-scale 0.25\n"
      "  aloft view mobiles/steel-fish.json --frames 120 --screenshot fish.png   # for tests\n");
  return [o] {
    view::ViewerOptions options = o->viewer;
    if (o->balance == "mass") options.build.balance = BalanceMode::Mass;
    if (o->balance == "joints") options.build.balance = BalanceMode::Joints;
    if (o->balance == "none") options.build.balance = BalanceMode::None;
    options.shadows = !o->no_shadows;
    options.wind = !o->no_wind;
    options.microphone = !o->no_mic;
    options.file_wind = !o->no_file_wind;
    const CameraFlags camera = o->camera;
    options.adjust_camera = [camera](render::OrbitCamera c) { return camera.apply(c); };
    if (options.drop_frame >= 0 && options.drop_file.empty()) throw Failure("--drop-at needs --drop-file");
    return view::run_viewer(options);
  };
}

static const CommandRegistration registration{"view", 50, add_view};

}  // namespace aloft::cli
