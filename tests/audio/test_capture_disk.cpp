// The live capture path without hardware: SDL's "disk" audio driver feeds a raw file to `aloft mic`, and
// the v0 it records must equal the file reader's for the same signal (made by sox: 1 s silence + 1 s white
// noise). Also: no device is not an error.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "aloft/audio.hpp"

namespace aloft::test {
namespace {

int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(CaptureDisk, SameSpeedThroughSdlDiskDriverAsFromTheFile) {
  const std::string dir = ::testing::TempDir() + "aloft_capture_test";
  ASSERT_EQ(run("mkdir -p " + dir), 0);
  // The signal, as in docs/platform-notes: 48 kHz mono, 16-bit WAV and the same as raw 32-bit float; -R:
  // sox seeds its noise generator with a fixed number, so the signal is the same at every run. White noise
  // (a breath is broadband): with pink noise, most power is at low frequencies and its own loudness over
  // 5 ms wanders by +-25 %, so a 10-90 % rise time measures where the signal happens to be quiet (we saw
  // 50-80 ms depending on the seed, while the follower itself had reached the level in ~20 ms).
  ASSERT_EQ(run("cd " + dir + " && sox -n -r 48000 -c 1 -b 16 sil.wav trim 0 1 && "
                "sox -R -n -r 48000 -c 1 -b 16 noise.wav synth 1 whitenoise vol 0.5 && sox sil.wav noise.wav blow.wav && "
                "sox blow.wav -t raw -e floating-point -b 32 blow_f32.raw"),
            0)
      << "sox is needed (apt-get install sox)";
  ASSERT_EQ(run("cd " + dir + " && SDL_AUDIODRIVER=disk SDL_DISKAUDIOFILEIN=blow_f32.raw " + ALOFT_CLI +
                " mic --duration 1.95 --csv mic.csv > mic.out 2>&1"),
            0)
      << read_text(dir + "/mic.out");
  const SpeedSeries live = read_speed_csv(dir + "/mic.csv");
  const SpeedSeries file = speed_from_audio(read_wav(dir + "/blow.wav"), EnvelopeSettings{}, 0.001);
  ASSERT_GE(live.t.size(), 1900u);
  // Same samples (16-bit values are exact in float both ways), same follower, same 1 ms schedule: equal
  // up to the CSV's shortest round-trip text (exact) — allow 1e-9 m/s.
  for (std::size_t i = 0; i < live.t.size(); ++i) {
    ASSERT_EQ(live.t[i], file.t[i]) << i;
    ASSERT_NEAR(live.v0[i], file.v0[i], 1e-9) << "t = " << live.t[i];
  }
  // And the signal's shape: 0 through the silent second, clearly positive a little after the onset
  // (well above 1 m/s within 50 ms: white noise at vol 0.5 has an RMS near 0.29, v0 ~ 25 * 0.29).
  EXPECT_EQ(live.at(0.99), 0.0);
  EXPECT_GT(live.at(1.05), 1.0);
  EXPECT_GT(live.at(1.5), 1.0);
  // Rise time from 10 % to 90 % of the burst's mean v0 (over 1.2-1.9 s), after the onset at 1 s: < 50 ms.
  double plateau = 0;
  int n = 0;
  for (std::size_t i = 0; i < live.t.size(); ++i)
    if (live.t[i] > 1.2 && live.t[i] < 1.9) plateau += live.v0[i], ++n;
  plateau /= n;
  double t10 = -1, t90 = -1;
  for (std::size_t i = 0; i < live.t.size(); ++i) {
    if (t10 < 0 && live.v0[i] >= 0.1 * plateau) t10 = live.t[i];
    if (t90 < 0 && live.v0[i] >= 0.9 * plateau) t90 = live.t[i];
  }
  EXPECT_GE(t10, 1.0);
  EXPECT_LT(t90 - t10, 0.050);
}

TEST(CaptureDisk, NoMicrophoneIsNotAnError) {
  const std::string dir = ::testing::TempDir();
  // ALSA with no sound card (this machine, CI): the device does not open; aloft says so once and exits 0.
  const int code = run(std::string("SDL_AUDIODRIVER=alsa ALSA_CONFIG_PATH=/nonexistent ") + ALOFT_CLI +
                       " mic --duration 0.2 > " + dir + "nomic.out 2>&1");
  const std::string out = read_text(dir + "nomic.out");
  EXPECT_EQ(code, 0) << out;
  if (out.find("capturing from") == std::string::npos) {  // a machine with a real microphone captures
    EXPECT_NE(out.find("no microphone"), std::string::npos) << out;
    EXPECT_NE(out.find("the wind stays still"), std::string::npos) << out;
  }
}

}  // namespace
}  // namespace aloft::test
