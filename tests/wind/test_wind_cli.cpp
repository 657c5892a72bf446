// `aloft simulate` with wind: the flags work end to end, and bad wind input is a clear message with the
// right exit code (1: bad input file, 2: wrong usage), never a crash.

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "audio/wav_bytes.hpp"
#include "support/run_aloft.hpp"

namespace aloft::test {
namespace {

using Result = CliResult;
const auto aloft = run_aloft;  // aloft("simulate ...")

const std::string fish = std::string(ALOFT_SOURCE_DIR) + "/mobiles/steel-fish.json";

TEST(WindCli, SteadyWindRunsAndReports) {
  const Result r = aloft("simulate " + fish + " -t 0.3 --wind 2.5 --wind-beta 0 --no-collisions");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("wind              v0 = 2.5 m/s, steady"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("occlusion         18 refreshes"), std::string::npos) << r.output;  // 300 steps / 17
  // The wind does work, so the energy's change is no drift, and the summary does not call it one.
  EXPECT_EQ(r.output.find("energy drift"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("energy change"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the wind does work and damping is on (no wind and --damping-off to check conservation)"),
            std::string::npos)
      << r.output;
}

TEST(WindCli, SpeedSeriesAndAudioDriveTheWind) {
  const std::string dir = ::testing::TempDir();
  std::ofstream(dir + "speeds.csv") << "t,v0\n0,0\n0.1,3\n";
  Result r = aloft("simulate " + fish + " -t 0.2 --wind-speed " + dir + "speeds.csv");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("2 samples over 0.1 s"), std::string::npos) << r.output;
  std::ofstream(dir + "bad_speeds.csv") << "0,1\n0.1,fast\n";
  r = aloft("simulate " + fish + " -t 0.2 --wind-speed " + dir + "bad_speeds.csv");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("bad_speeds.csv:2: expected two numbers"), std::string::npos) << r.output;
  std::ofstream(dir + "gale.csv") << "t,v0\n0,1\n0.1,1e5\n";
  r = aloft("simulate " + fish + " -t 0.2 --wind-speed " + dir + "gale.csv");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("gale.csv:3: the speed v0 must be from 0 to 100 m/s"), std::string::npos) << r.output;
  std::ofstream(dir + "not.wav") << "this is not a wav file";
  r = aloft("simulate " + fish + " -t 0.2 --wind-audio " + dir + "not.wav");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("not.wav: byte 0: not a WAV file"), std::string::npos) << r.output;
  r = aloft("simulate " + fish + " -t 0.2 --wind-audio /nonexistent/blow.wav");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("/nonexistent/blow.wav: cannot open the audio file"), std::string::npos) << r.output;
}

// Bad input files exit 1 with the file named: a WAV without samples, one no longer than its noise-floor
// calibration, and a file that is not a regular file (/dev/zero was read until memory ran out, "aloft:
// error: out of memory", no file named). Each of these used to run without wind and without a word.
TEST(WindCli, AudioAndSpeedFilesThatGiveNoWindAreErrors) {
  const std::string dir = ::testing::TempDir();
  const auto write = [&](const std::string& name, const std::vector<std::uint8_t>& bytes) {
    std::ofstream(dir + name, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                                      static_cast<std::streamsize>(bytes.size()));
  };
  write("empty.wav", wav_bytes(1, 1, 8000, 16, {}));
  Result r = aloft("simulate " + fish + " -t 0.05 --no-collisions --wind-audio " + dir + "empty.wav");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("empty.wav: byte 36: the \"data\" chunk is empty (0 bytes): the file holds no samples"),
            std::string::npos)
      << r.output;

  // 0.5 s (4000 frames at 8000 Hz) of a square wave of amplitude 0.5: RMS 0.5, v0 = 25 * 0.5 = 12.5 m/s.
  std::vector<std::uint8_t> square;
  for (int i = 0; i < 4000; ++i) put16(square, static_cast<std::uint16_t>(i % 2 == 0 ? 16384 : -16384));
  write("short.wav", wav_bytes(1, 1, 8000, 16, square));
  const std::string run = "simulate " + fish + " -t 0.05 --no-collisions --wind-audio " + dir + "short.wav";
  const std::string why = "short.wav: the recording lasts 0.5 s, no longer than the 1 s of noise-floor calibration "
                          "at its start (--wind-calibrate), so no wind would blow; give --wind-calibrate 0 (or a "
                          "shorter time) or --wind-noise-floor";
  r = aloft(run);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("aloft: error: " + dir + why), std::string::npos) << r.output;
  r = aloft(run + " --wind-calibrate 0.5");  // as long as the recording: still nothing after it
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("lasts 0.5 s, no longer than the 0.5 s"), std::string::npos) << r.output;
  // What the message suggests works. The envelope reaches the square's RMS within its 5 ms attack, and the
  // summary prints 3 significant digits.
  r = aloft(run + " --wind-noise-floor 0");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("peak v0 12.5 m/s"), std::string::npos) << r.output;
  r = aloft(run + " --wind-calibrate 0");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("peak v0 12.5 m/s"), std::string::npos) << r.output;

  for (const char* flag : {"--wind-audio", "--wind-speed"}) {
    r = aloft("simulate " + fish + " -t 0.05 " + flag + " /dev/zero");
    EXPECT_EQ(r.code, 1) << flag << "\n" << r.output;
    EXPECT_NE(r.output.find("aloft: error: /dev/zero: not a regular file"), std::string::npos) << flag << "\n"
                                                                                               << r.output;
  }
}

TEST(WindCli, BadFlagsAreUsageErrors) {
  Result r = aloft("simulate " + fish + " -t 0.2 --wind 1 --wind-from 1,2");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("must be a point x,y,z in metres"), std::string::npos) << r.output;
  r = aloft("simulate " + fish + " -t 0.2 --wind 1 --wind-speed x.csv");
  EXPECT_EQ(r.code, 2) << r.output;
  r = aloft("simulate " + fish + " -t 0.2 --wind -1");
  EXPECT_EQ(r.code, 2) << r.output;
  // Faster than the cone model's incompressible air: refused by name, not run until a component spins
  // too fast (as --wind 1e5 did, exit 3, at the first step).
  r = aloft("simulate " + fish + " -t 0.2 --wind 1e5");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--wind: must be from 0 to 100 m/s (the cone model treats the air as incompressible"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(aloft("simulate " + fish + " -t 0.01 --wind 100 --no-collisions").code, 0);  // the limit itself
  r = aloft("simulate " + fish + " -t 0.2 --wind 1 --wind-from 0,2,0 --wind-to 0,2,0");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("two different points"), std::string::npos) << r.output;
  // Flags that shape a wind that was not asked for are refused, not ignored without a word.
  r = aloft("simulate " + fish + " -t 0.2 --wind-from 1,2,3");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--wind-from: places the wind of --wind, --wind-speed or --wind-audio, and none of them "
                          "was given"),
            std::string::npos)
      << r.output;
  r = aloft("simulate " + fish + " -t 0.2 --wind 1 --wind-gain 50");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--wind-gain requires --wind-audio"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace aloft::test
