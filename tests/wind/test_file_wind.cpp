// Wind sources placed by the mobile file ("wind_sources"): a plate facing a file source gets eq. 4's force,
// the same numbers a WindSource built by hand gives; the viewer's session blows them (each switched on and
// off, kept across a reload); `aloft simulate` names them, moves a mobile with a fan and leaves it still
// with --no-file-wind.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "support/test_dir.hpp"
#include "support/run_aloft.hpp"

#include "mobile_session.hpp"
#include "wind/wind_scenes.hpp"

namespace aloft::test {
namespace {

namespace fs = std::filesystem;

// A square plate, 0.2 m, face-on to +z, centred at (0, 1, 0), hanging at the middle of its top edge from a
// small hook just above it (the hook is above the plate's edge, so it hides none of the plate from the
// source). `sources` is the "wind_sources" array.
std::string plate_mobile(const std::string& sources) {
  return R"({
  "name": "plate in a draught",
  "wind_sources": )" + sources + R"(,
  "components": [
    {"name": "hook", "fixed": true, "shapes": [{"sphere": {"center": [0, 1.104, 0], "radius": 0.003}}]},
    {"name": "plate", "parent": "hook", "joint": [0, 1.1, 0],
     "shapes": [{"plate": {"plane": "xy", "thickness": 0.002,
                           "points": [[-0.1, 0.9], [0.1, 0.9], [0.1, 1.1], [-0.1, 1.1]]}}]}
  ]
}
)";
}

// S0 centred 2.5 m in front of the plate on its axis, blowing at it: l0 = 1 m, so l1 = 3.5 m at the plate.
// r0 = 0.06 m: the cone is 0.21 m wide there, so the whole plate (half-diagonal 0.141 m) is inside it.
const Vec3 kFrom(0, 1, 2.5), kTo(0, 1, 0);
constexpr double kR0 = 0.06, kL0 = 1.0, kSpeed = 3.0;
const std::string kFan = R"([{"name": "fan", "from": [0, 1, 2.5], "to": [0, 1, 0], "r0": 0.06, "l0": 1,
                              "speed": 3, "beta": 0}])";

class FileWindTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::make_test_dir("file-wind");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  fs::path dir_;
};

TEST_F(FileWindTest, PlateGetsTheForceOfAHandBuiltSourceAndOfEquationFour) {
  view::MobileSession session(write("plate.json", plate_mobile(kFan)).string());
  ASSERT_EQ(session.file_winds().size(), 1u);
  const State rest = session.simulation().state();
  session.single_step();
  const Vec3 from_file = session.simulation().loads().force[1];

  // The same source built by hand, with the viewer's settings (default resolution and tiles, no turbulence).
  WindSettings settings;
  settings.beta = 0;
  Wind by_hand(session.model(), WindSource::aimed(kFrom, kTo, kR0, kL0), settings);
  by_hand.refresh_occlusion(rest);
  ExternalLoads loads;
  loads.resize(session.model().count);
  loads.clear();
  by_hand.apply(rest, kSpeed, session.simulation().timestep(), loads);
  // The same deterministic computation on the same inputs: the same numbers, to the last bit.
  EXPECT_EQ(from_file, loads.force[1]);
  EXPECT_EQ(session.simulation().loads().torque[1], loads.torque[1]);

  // Eq. 4 integrated over the plate's face, alpha of air for l0 = 1 m. Tolerance 2 %: the plate covers
  // 0.2 / 3.5 * 1 m = 0.057 m of the 0.12 m S0 square, 122 of 256 pixels a side, so pixel-centre sampling
  // misplaces at most half a pixel at each edge, 4 * 0.5 / 122 = 1.6 % of the area; the face is 1 mm
  // nearer than the mid-plane the quadrature uses (4 * 1 mm / 3.5 m = 0.1 %).
  const PlacedPlate plate{Vec3(0, 1, 0), 0.2};
  const WindSource source = WindSource::aimed(kFrom, kTo, kR0, kL0);
  const Vec3 exact = exact_plate_force(plate, source, kAirDensity * std::pow(kL0, 4), kSpeed);
  ASSERT_LT(exact.z(), 0);  // blowing along -z
  EXPECT_NEAR(from_file.z(), exact.z(), 0.02 * std::abs(exact.z()));
  // Continuity and drag by hand for the centre: rho A v1^2, v1 = v0 (l0 / l1)^2 (0.5 % from the exact
  // integral: l1 varies across the face).
  const double v1 = kSpeed * std::pow(kL0 / 3.5, 2);
  EXPECT_NEAR(-from_file.z(), kAirDensity * 0.04 * v1 * v1, 0.025 * kAirDensity * 0.04 * v1 * v1);
}

TEST_F(FileWindTest, SessionSwitchesSourcesAndKeepsTheSwitchAcrossAReload) {
  const std::string two = R"([{"name": "fan", "from": [0, 1, 2.5], "to": [0, 1, 0], "r0": 0.06, "speed": 3, "beta": 0},
     {"name": "vent", "from": [0, 1, -2.5], "to": [0, 1, 0], "r0": 0.06, "speed": 2, "beta": 0,
      "profile": {"type": "on_off", "period": 1, "on": 0.5}}])";
  const fs::path file = write("two.json", plate_mobile(two));
  view::MobileSession session(file.string());
  ASSERT_EQ(session.file_winds().size(), 2u);
  EXPECT_EQ(session.file_winds()[0].source.name, "fan");
  EXPECT_EQ(session.file_winds()[1].source.name, "vent");
  EXPECT_TRUE(session.file_winds()[0].enabled && session.file_winds()[1].enabled);
  EXPECT_EQ(session.file_wind_v0(1), 2.0);  // t = 0: the vent is in the "on" half of its period

  // Only the vent: it blows along +z from behind.
  session.set_file_wind_enabled(0, false);
  session.single_step();
  EXPECT_GT(session.simulation().loads().force[1].z(), 0);
  // Only the fan: along -z.
  session.set_file_wind_enabled(0, true);
  session.set_file_wind_enabled(1, false);
  session.single_step();
  EXPECT_LT(session.simulation().loads().force[1].z(), 0);
  EXPECT_EQ(session.file_wind_v0(1), 0.0);  // off
  // The window's wind switch stops them all.
  session.wind_control.enabled = false;
  session.single_step();
  EXPECT_EQ(session.simulation().loads().force[1], Vec3::Zero());
  session.wind_control.enabled = true;

  // A reload keeps each source's switch by name.
  std::ofstream(file, std::ios::binary) << plate_mobile(two) << "\n";
  fs::last_write_time(file, fs::last_write_time(file) + std::chrono::seconds(5));
  ASSERT_TRUE(session.reload_if_changed());
  ASSERT_EQ(session.error(), "");
  ASSERT_EQ(session.file_winds().size(), 2u);
  EXPECT_TRUE(session.file_winds()[0].enabled);
  EXPECT_FALSE(session.file_winds()[1].enabled);

  // `aloft view --no-file-wind`: a file loaded afterwards starts with its sources off.
  session.set_file_winds_on_load(false);
  ASSERT_TRUE(session.load(write("other.json", plate_mobile(kFan)).string()));
  ASSERT_EQ(session.file_winds().size(), 1u);
  EXPECT_FALSE(session.file_winds()[0].enabled);
  session.single_step();
  EXPECT_EQ(session.simulation().loads().force[1], Vec3::Zero());
}

using Result = CliResult;
const auto aloft = run_aloft;  // aloft("simulate ...")

// The largest displacement from rest that `aloft simulate` reports (m), in its line "motion <x> m largest
// displacement, ...", or -1.
double largest_move(const std::string& output) {
  for (std::size_t at = output.find("motion "); at != std::string::npos; at = output.find("motion ", at + 1)) {
    std::istringstream words(output.substr(at + 7));
    double metres = 0;
    std::string unit, largest, displacement;
    if (words >> metres >> unit >> largest >> displacement && unit == "m" && largest == "largest" &&
        displacement.rfind("displacement", 0) == 0)  // "displacement," in the report
      return metres;
  }
  return -1;
}

const std::string fan_room = std::string(ALOFT_SOURCE_DIR) + "/mobiles/fan-room.json";

TEST(FileWindCli, FanMovesTheFanRoomAndNoFileWindLeavesItStill) {
  // Two simulated seconds, collisions off (they play no part here).
  Result r = aloft("simulate " + fan_room + " -t 2 --no-collisions");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("wind              \"desk fan\" (file): v0 = 4 m/s, steady"), std::string::npos) << r.output;
  // The fan's wind, about 0.9 m/s at the mobile, turns the low bar and swings the pieces: measured 0.22 m
  // of largest displacement in 2 s. 5 mm is 40 times less than that, and 10^10 times more than the
  // mobile moves without wind (below).
  EXPECT_GT(largest_move(r.output), 0.005) << r.output;

  r = aloft("simulate " + fan_room + " -t 2 --no-collisions --no-file-wind");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.find("wind              "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1 source(s) in the file ignored (--no-file-wind)"), std::string::npos) << r.output;
  // Balanced by mass, so the designed pose is an equilibrium: without wind it stays there (measured
  // 6.5e-13 m: rounding). 1e-6 m leaves room for rounding on another compiler, 5000 times less than the
  // threshold above.
  EXPECT_LT(largest_move(r.output), 1e-6) << r.output;
  EXPECT_GE(largest_move(r.output), 0) << r.output;
}

TEST(FileWindCli, FlagsWindAndFileSourcesBlowTogether) {
  const Result r = aloft("simulate " + fan_room + " -t 0.05 --wind 1 --wind-beta 0");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("wind              v0 = 1 m/s, steady"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("wind              \"desk fan\" (file)"), std::string::npos) << r.output;
  // 50 steps, each wind refreshed every 17 steps (60 Hz at 1 ms): 3 refreshes each.
  EXPECT_NE(r.output.find("occlusion         6 refreshes"), std::string::npos) << r.output;
}

// A file source blows with the run's settings and its own alpha, beta and seed where it gives them; one
// without a seed takes the run's + 1 + its index, so that two sources do not gust in step.
TEST(FileWindSettings, FileSourcesTakeTheRunsSettingsAndTheirOwn) {
  WindSettings run;
  run.alpha = 2;
  run.beta = 0.1;
  run.seed = 10;
  run.resolution = 64;
  WindSourceSpec plain;
  const WindSettings a = file_source_settings(plain, 3, run);
  EXPECT_EQ(a.alpha, 2);
  EXPECT_EQ(a.beta, 0.1);
  EXPECT_EQ(a.seed, 14u);
  EXPECT_EQ(a.resolution, 64);
  WindSourceSpec own = plain;
  own.alpha = 0.5;
  own.beta = 0.7;
  own.seed = 99;
  const WindSettings b = file_source_settings(own, 3, run);
  EXPECT_EQ(b.alpha, 0.5);
  EXPECT_EQ(b.beta, 0.7);
  EXPECT_EQ(b.seed, 99u);
  EXPECT_EQ(b.resolution, 64);
  own.from = Vec3(1, 1, 0);
  own.to = Vec3(0, 1, 0);
  own.r0 = 0.2;
  own.l0 = 0.5;
  const WindSource cone = file_source_cone(own);
  EXPECT_EQ(cone.disc_center(), own.from);  // vertex l0 behind from, along the unit x axis: exact
  EXPECT_EQ(cone.direction, Vec3(-1, 0, 0));
  EXPECT_EQ(cone.r0, 0.2);
  EXPECT_EQ(cone.l0, 0.5);
}

// --wind-alpha also sets the alpha of file sources that give none, so it is checked against each one's
// l0: the fan room's fan has l0 = 1.2 m, so water's alpha 1000 * 1.2^4 = 2073.6 kg m. (With no --wind
// there is no wind of the flags' own to check it against --wind-l0 for.)
TEST(FileWindCli, FlagAlphaIsCheckedAgainstEachFileSourcesL0) {
  const Result r = aloft("simulate " + fan_room + " -t 0.05 --wind-alpha 3000");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("fan-room.json: wind_sources[0] (l0 = 1.2 m) takes --wind-alpha, which must be a positive "
                          "number of at most 2073.6 kg m"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("got 3000"), std::string::npos) << r.output;
  // Within the rule it runs (water's alpha for l0 = 1.2 m).
  EXPECT_EQ(aloft("simulate " + fan_room + " -t 0.05 --wind-alpha 2000").code, 0);
}

}  // namespace
}  // namespace aloft::test
