// The mobile file's "camera" in `aloft render` (no display, EGL) and `aloft view` (Xvfb): a file camera
// gives another picture than the framing camera, the camera flags override it key by key, and a bad
// camera in the file is an error naming the file, line and path.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/png_image.hpp"
#include "support/test_dir.hpp"
#include "support/run_aloft.hpp"

namespace {

namespace fs = std::filesystem;

const auto quote = aloft::test::shell_quote;
const auto read = aloft::test::read_file;

using aloft::test::Image;
using aloft::test::load_png;

// Pixels whose colour differs by more than 8 levels in some channel (llvmpipe is deterministic, so equal
// scenes give equal pictures; 8 levels only keeps the count from hinging on a rounding of the last bit).
int differing_pixels(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height) return -1;
  int n = 0;
  for (std::size_t i = 0; i < a.rgb.size(); i += 3)
    for (int c = 0; c < 3; ++c)
      if (std::abs(int(a.rgb[i + c]) - int(b.rgb[i + c])) > 8) {
        ++n;
        break;
      }
  return n;
}

class FileCamera : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = aloft::test::make_test_dir("file-camera");
    // The Fan Room with its camera, and the same without it.
    fan_room_ = fs::path(ALOFT_SOURCE_DIR) / "mobiles/fan-room.json";
    nlohmann::json doc = nlohmann::json::parse(read(fan_room_));
    camera_ = doc.at("camera");
    doc.erase("camera");
    no_camera_ = dir_ / "no-camera.json";
    std::ofstream(no_camera_) << doc.dump(2);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // `aloft view FILE --frames 4` under a virtual X display: its last frame's scene in `out`.
  int view(const fs::path& file, const std::string& out, const std::string& flags) {
    const char* asan = std::getenv("ASAN_OPTIONS");
    const std::string asan_options = std::string(asan ? asan : "") + (asan && *asan ? ":" : "") + "detect_leaks=0";
    const std::string command = "cd " + quote(dir_.string()) + " && ASAN_OPTIONS=" + quote(asan_options) +
                                " SDL_AUDIODRIVER=dummy xvfb-run -a -s '-screen 0 1280x720x24' " + quote(ALOFT_CLI) +
                                " view " + quote(file.string()) +
                                " --frames 4 --width 320 --height 180 --msaa 0 --no-shadows --no-mic --screenshot " +
                                out + " " + flags + " > /dev/null 2>&1";
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  // The file's camera as command-line flags.
  std::string camera_flags() const {
    const auto& target = camera_.at("target");
    return "--yaw " + camera_.at("yaw").dump() + " --pitch " + camera_.at("pitch").dump() + " --distance " +
           camera_.at("distance").dump() + " --fov " + camera_.at("fov").dump() + " --target " + target[0].dump() +
           " " + target[1].dump() + " " + target[2].dump();
  }

  // `aloft render FILE` of one still with no display (detect_leaks=0 for the child only: Mesa's driver
  // leaks at exit from an unloaded module, see test_viewer_cli.cpp). Returns the exit code.
  int render(const fs::path& file, const std::string& out, const std::string& flags, std::string* output = nullptr) {
    const char* asan = std::getenv("ASAN_OPTIONS");
    const std::string asan_options = std::string(asan ? asan : "") + (asan && *asan ? ":" : "") + "detect_leaks=0";
    const fs::path log = dir_ / "out.txt";
    const std::string command = "cd " + quote(dir_.string()) + " && ASAN_OPTIONS=" + quote(asan_options) +
                                " env -u DISPLAY " + quote(ALOFT_CLI) + " render " + quote(file.string()) +
                                " --duration 0.001 --width 192 --height 108 --msaa 0 --no-shadows -q --no-file-wind"
                                " --out " + out + " " + flags + " > " + quote(log.string()) + " 2>&1";
    const int status = std::system(command.c_str());
    if (output) *output = read(log);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  fs::path dir_, fan_room_, no_camera_;
  nlohmann::json camera_;
};

TEST_F(FileCamera, FileCameraIsUsedAndFlagsOverrideItKeyByKey) {
  ASSERT_EQ(render(fan_room_, "file.png", ""), 0);
  ASSERT_EQ(render(no_camera_, "framed.png", ""), 0);
  const Image file = load_png(dir_ / "file.png"), framed = load_png(dir_ / "framed.png");
  ASSERT_EQ(file.width, 192);
  ASSERT_EQ(framed.width, 192);
  // Another viewpoint moves most of the room (the floor line, the wall, the mobile): a tenth of the
  // picture is far less than it changes and far more than rounding could.
  EXPECT_GT(differing_pixels(file, framed), 192 * 108 / 10);

  // The file's camera given as flags on the file without one: the same picture.
  const std::string as_flags = camera_flags();
  ASSERT_EQ(render(no_camera_, "flags.png", as_flags), 0);
  EXPECT_EQ(differing_pixels(file, load_png(dir_ / "flags.png")), 0);
  // --target also takes X,Y,Z, as --wind-from does.
  const auto& target = camera_.at("target");
  std::string with_commas = as_flags.substr(0, as_flags.find("--target"));
  with_commas += "--target " + target[0].dump() + "," + target[1].dump() + "," + target[2].dump();
  ASSERT_EQ(render(no_camera_, "commas.png", with_commas), 0);
  EXPECT_EQ(differing_pixels(file, load_png(dir_ / "commas.png")), 0);

  // One flag overrides one key: --yaw 60 on the file == all the file's keys as flags but yaw 60.
  ASSERT_EQ(render(fan_room_, "file-yaw.png", "--yaw 60"), 0);
  std::string yaw60 = as_flags;
  const std::size_t yaw = yaw60.find("--yaw ");
  ASSERT_NE(yaw, std::string::npos) << as_flags;
  const std::size_t value = yaw + 6, value_end = std::min(yaw60.find(' ', value), yaw60.size());
  yaw60.replace(value, value_end - value, "60");
  ASSERT_EQ(render(no_camera_, "flags-yaw.png", yaw60), 0);
  const Image file_yaw = load_png(dir_ / "file-yaw.png");
  EXPECT_EQ(differing_pixels(file_yaw, load_png(dir_ / "flags-yaw.png")), 0);
  EXPECT_GT(differing_pixels(file_yaw, file), 192 * 108 / 10);  // and it did turn the camera
}

// The viewer starts from the file's camera too (the same view as its keys given as flags, another than
// the framing camera's), and its wind sources blow there as in render (both runs have them).
TEST_F(FileCamera, ViewerStartsFromTheFileCamera) {
  ASSERT_EQ(view(fan_room_, "file.png", ""), 0);
  ASSERT_EQ(view(no_camera_, "flags.png", camera_flags()), 0);
  ASSERT_EQ(view(no_camera_, "framed.png", ""), 0);
  const Image file = load_png(dir_ / "file.png");
  ASSERT_EQ(file.width, 320);
  EXPECT_EQ(differing_pixels(file, load_png(dir_ / "flags.png")), 0);
  EXPECT_GT(differing_pixels(file, load_png(dir_ / "framed.png")), 320 * 180 / 10);  // as in render, above
}

TEST_F(FileCamera, BadCameraInTheFileIsAnError) {
  nlohmann::json doc = nlohmann::json::parse(read(fan_room_));
  doc["camera"]["pitch"] = 95;
  const fs::path bad = dir_ / "bad-camera.json";
  std::ofstream(bad) << doc.dump(1);
  std::string output;
  EXPECT_EQ(render(bad, "bad.png", "", &output), 1);
  EXPECT_NE(output.find("bad-camera.json:"), std::string::npos) << output;
  EXPECT_NE(output.find(": camera.pitch: must be a number from -85 to 85 (degrees), got 95"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir_ / "bad.png"));
}

}  // namespace
