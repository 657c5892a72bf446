// `aloft view` under a virtual X display (xvfb-run) and `aloft render` with no display at all: they start
// on each preset, draw the mobile (compared with the empty room), quit cleanly, keep the old mobile when
// a broken file is dropped, and write videos of the right length and size.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/png_image.hpp"
#include "support/test_dir.hpp"
#include "support/leaning_balls.hpp"
#include "support/run_aloft.hpp"

namespace {

namespace fs = std::filesystem;

struct Result {
  int code = -1;
  std::string out;
};

const auto quote = aloft::test::shell_quote;
const auto read = aloft::test::read_file;

using aloft::test::Image;
using aloft::test::load_png;

// Pixels of the preset colours as lit: strong red (the fish and balls, #b3261e / #c1121f), and black
// steel (#1b1b1b / #141414), counted as pixels darker than `darkest` (the empty gallery's darkest
// pixel, less a margin); the empty gallery has no red.
struct ColourCounts {
  int red = 0, black = 0;
};
int max_channel(const unsigned char* p) { return std::max({p[0], p[1], p[2]}); }
ColourCounts count_colours(const Image& image, int darkest = 60) {
  ColourCounts c;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const unsigned char* p = image.at(x, y);
      if (p[0] > 90 && p[0] > 2 * p[1] && p[0] > 2 * p[2]) ++c.red;
      if (max_channel(p) < darkest) ++c.black;
    }
  return c;
}
int darkest_less_margin(const Image& image) {
  int darkest = 255;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) darkest = std::min(darkest, max_channel(image.at(x, y)));
  return darkest - 15;  // 15 levels: more than the shading differences across the empty room's pixels
}

int differing_pixels(const Image& a, const Image& b) {
  int n = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const unsigned char *p = a.at(x, y), *q = b.at(x, y);
      // 24 levels in any channel: well above the shadow filter's per-pixel grain (a few levels).
      if (std::abs(p[0] - q[0]) > 24 || std::abs(p[1] - q[1]) > 24 || std::abs(p[2] - q[2]) > 24) ++n;
    }
  return n;
}

class Viewer : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = aloft::test::make_test_dir("viewer");
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs `prefix aloft args` in the temporary directory, stdout captured, stderr passed through.
  //  - detect_leaks=0 for these child processes only (appended, so it overrides scripts/run-tests'
  //    detect_leaks=1): Mesa's llvmpipe driver (swrast_dri.so, loaded and unloaded by libGL/libEGL)
  //    leaves ~240 bytes in 3 allocations at exit, and because the driver is unloaded by then,
  //    LeakSanitizer reports them from "<unknown module>", which no suppression can match. Every other
  //    AddressSanitizer and UBSan check stays on in the child, and the session tests (test_mobile_session,
  //    no GL) run in-process with leak detection.
  //  - SDL_AUDIODRIVER=dummy: the viewer's microphone opens a silent device (no sound server here).
  Result run(const std::string& prefix, const std::string& args) {
    const fs::path out = dir_ / "stdout.txt";
    const char* asan = std::getenv("ASAN_OPTIONS");
    const std::string asan_options = std::string(asan ? asan : "") + (asan && *asan ? ":" : "") + "detect_leaks=0";
    const std::string command = "cd " + quote(dir_.string()) + " && ASAN_OPTIONS=" + quote(asan_options) +
                                " SDL_AUDIODRIVER=dummy " + prefix + " " + quote(ALOFT_CLI) + " " + args + " > " +
                                quote(out.string());
    const int status = std::system(command.c_str());
    Result r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = read(out);
    return r;
  }
  Result view(const std::string& args) { return run("xvfb-run -a -s '-screen 0 1280x720x24'", "view " + args); }
  Result render(const std::string& args) { return run("env -u DISPLAY", "render " + args); }

  static std::string preset(const std::string& name) { return quote(std::string(ALOFT_SOURCE_DIR) + "/mobiles/" + name); }

  void expect_viewer_shows(const std::string& file) {
    const std::string common = preset(file) + " --frames 8 --width 320 --height 180 --no-shadows";
    const Result shown = view(common + " --screenshot mobile.png");
    ASSERT_EQ(shown.code, 0) << shown.out;
    EXPECT_NE(shown.out.find("view: 8 frames"), std::string::npos) << shown.out;
    const Result empty = view(common + " --hide-mobile --screenshot empty.png");
    ASSERT_EQ(empty.code, 0) << empty.out;
    const Image a = load_png(dir_ / "mobile.png"), b = load_png(dir_ / "empty.png");
    ASSERT_EQ(a.width, 320);
    ASSERT_EQ(a.height, 180);
    ASSERT_EQ(b.width, 320);
    // The mobile covers a few percent of the picture: thin wires, a few plates. 0.5 % of 57600 pixels
    // is 288, several times fewer than its plates alone cover at this size.
    EXPECT_GT(differing_pixels(a, b), 288);
    const int darkest = darkest_less_margin(b);
    const ColourCounts with = count_colours(a, darkest), without = count_colours(b, darkest);
    EXPECT_EQ(without.red, 0);
    EXPECT_EQ(without.black, 0);
    EXPECT_GT(with.red, 10) << "the red pieces";    // the smallest red piece is ~5 px across here
    EXPECT_GT(with.black, 50) << "the black plates";
  }

  fs::path dir_;
};

TEST_F(Viewer, ShowsTheSteelFish) { expect_viewer_shows("steel-fish.json"); }

TEST_F(Viewer, ShowsTheSouthernCross) { expect_viewer_shows("southern-cross.json"); }

TEST_F(Viewer, QuitsCleanlyOnTheQuitKey) {
  // Q pressed at frame 5 of at most a million: it must stop there and exit 0.
  const Result r = view(preset("steel-fish.json") + " --frames 1000000 --quit-at 5 --width 160 --height 120");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("view: 5 frames"), std::string::npos) << r.out;
}

TEST_F(Viewer, DroppedBrokenFileShowsTheErrorAndKeepsTheOldMobileRunning) {
  std::string fish = read(fs::path(ALOFT_SOURCE_DIR) / "mobiles/steel-fish.json");
  std::ofstream(dir_ / "broken.json", std::ios::binary) << fish.substr(0, fish.size() / 3);
  const Result r = view(preset("steel-fish.json") +
                        " --frames 12 --drop-at 3 --drop-file broken.json --balance none --width 640 --height 360"
                        " --window-screenshot window.png");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("mobile \"Steel Fish\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("error: broken.json:"), std::string::npos) << r.out;
  // 12 frames of 1/60 s with no reset at the drop: the old mobile ran on to t = 0.2 s.
  EXPECT_NE(r.out.find("t = 0.2000 s"), std::string::npos) << r.out;
  // The error banner (dark red, top middle) is in the window.
  const Image w = load_png(dir_ / "window.png");
  ASSERT_EQ(w.width, 640);
  int banner = 0;
  for (int y = 0; y < 60; ++y)
    for (int x = w.width / 4; x < 3 * w.width / 4; ++x) {
      const unsigned char* p = w.at(x, y);
      if (p[0] > 110 && p[0] < 170 && p[1] < 40 && p[2] < 40) ++banner;
    }
  EXPECT_GT(banner, 1000) << "a banner of at least ~300 x 20 pixels, minus its text";
}

TEST_F(Viewer, BadFirstFileIsAnErrorNotACrash) {
  std::ofstream(dir_ / "bad.json", std::ios::binary) << "{ \"name\": 3 ";
  const Result r = view("bad.json --frames 2");
  EXPECT_EQ(r.code, 1);
}

// ffprobe's count of decoded frames and the size of the first video stream: "frames,width,height".
std::string probe(const fs::path& video) {
  const std::string command = "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
                              "stream=nb_read_frames,width,height -of csv=p=0 " + quote(video.string());
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return "";
  char line[256] = {};
  std::string out = std::fgets(line, sizeof line, pipe) ? line : "";
  ::pclose(pipe);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

TEST_F(Viewer, HeadlessRenderWritesVideosOfTheRightLengthAndSize) {
  // 0.5 s at 20 fps: 10 frames; odd width 161 is padded to 162 for H.264 (yuv420p needs even sizes).
  Result r = render(preset("steel-fish.json") + " --duration 0.5 --fps 20 --width 160 --height 90 --out clip.mp4 -q");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(probe(dir_ / "clip.mp4"), "160,90,10");
  r = render(preset("southern-cross.json") + " --duration 0.4 --fps 10 --width 120 --height 80 --out clip.gif -q");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(probe(dir_ / "clip.gif"), "120,80,4");
  // Without -q, and not on a terminal: a progress line per tenth of the frames (here per frame).
  r = render(preset("steel-fish.json") + " --duration 0.3 --fps 10 --width 64 --height 48 --out frames/ 2> progress.txt");
  ASSERT_EQ(r.code, 0);
  int pngs = 0;
  for (const auto& e : fs::directory_iterator(dir_ / "frames")) pngs += e.path().extension() == ".png";
  EXPECT_EQ(pngs, 3);
  const std::string progress = read(dir_ / "progress.txt");
  EXPECT_NE(progress.find("aloft: rendering: 33% (frame 1 of 3, "), std::string::npos) << progress;
  EXPECT_NE(progress.find("aloft: rendering: 100% (frame 3 of 3, "), std::string::npos) << progress;
}

TEST_F(Viewer, HeadlessRenderPngShowsTheMobile) {
  const Result r = render(preset("steel-fish.json") + " --duration 0.1 --width 320 --height 180 --out still.png");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("written    still.png"), std::string::npos) << r.out;
  const Image image = load_png(dir_ / "still.png");
  ASSERT_EQ(image.width, 320);
  ASSERT_EQ(image.height, 180);
  const ColourCounts c = count_colours(image);
  EXPECT_GT(c.red, 10);
  EXPECT_GT(c.black, 50);
}

// --glow-touching: at 3 s the leaning balls rest on each other, so the still shows them glowing; nothing
// else in the picture changes (the hook's bar and the room are the same).
TEST_F(Viewer, HeadlessRenderGlowsThePiecesThatTouch) {
  std::ofstream(dir_ / "balls.json", std::ios::binary) << aloft::test::kLeaningBalls;
  const std::string common = "balls.json --duration 3 --width 320 --height 180 --no-shadows -q";
  ASSERT_EQ(render(common + " --out plain.png").code, 0);
  ASSERT_EQ(render(common + " --glow-touching --out glow.png").code, 0);
  const Image plain = load_png(dir_ / "plain.png"), glow = load_png(dir_ / "glow.png");
  // The two balls: a few hundred pixels at this size (they are 6 cm across in a frame about 1 m wide).
  EXPECT_GT(differing_pixels(plain, glow), 100);
  // Warmer where they differ: the glow tints towards orange (red up against blue).
  long long warmer = 0, differing = 0;
  for (int y = 0; y < plain.height; ++y)
    for (int x = 0; x < plain.width; ++x) {
      const unsigned char *p = plain.at(x, y), *q = glow.at(x, y);
      if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) continue;
      ++differing;
      warmer += (q[0] - q[2]) > (p[0] - p[2]);
    }
  EXPECT_GT(warmer, 0.9 * differing);
}

TEST_F(Viewer, HeadlessRenderRejectsAnUnknownOutput) {
  const Result r = render(preset("steel-fish.json") + " --duration 0.1 --out clip.xyz");
  EXPECT_EQ(r.code, 1);
}

}  // namespace
