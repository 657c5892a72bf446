// The viewer's session without a window: reload on change (a broken file keeps the old mobile running),
// drag-and-drop loads, recompiling with another total mass, the mouse spring and physics pacing.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "mobile_session.hpp"
#include "support/test_dir.hpp"
#include "support/leaning_balls.hpp"

namespace aloft::view {
namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Write `text` and move the file's modification time on by `seconds`, so a reload sees a change even on
// file systems with coarse timestamps.
void write_later(const fs::path& p, const std::string& text, int seconds) {
  std::ofstream(p, std::ios::binary) << text;
  fs::last_write_time(p, fs::last_write_time(p) + std::chrono::seconds(seconds));
}

class Session : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::make_test_dir("session");
    fish_text_ = read(fs::path(ALOFT_SOURCE_DIR) / "mobiles/steel-fish.json");
    fish_ = dir_ / "fish.json";
    std::ofstream(fish_, std::ios::binary) << fish_text_;
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_, fish_;
  std::string fish_text_;
};

TEST_F(Session, BrokenReloadKeepsTheOldMobileRunningAndFixedReloadReplacesIt) {
  // Balance "none": the Steel Fish as built swings, so "running" shows in its motion too.
  MobileSession session(fish_.string(), BuildSettings{BalanceMode::None, {}, {}, {}, {}});
  EXPECT_FALSE(session.reload_if_changed()) << "nothing changed yet";
  session.advance(0.05, 1e9);
  const int generation = session.model_generation();
  const State before = session.simulation().state();
  EXPECT_NEAR(before.time, 0.05, 1e-9);  // whole 1 ms steps: 50 of them

  // The designer saves a file with a syntax error (cut in the middle).
  write_later(fish_, fish_text_.substr(0, fish_text_.size() / 2), 2);
  EXPECT_TRUE(session.reload_if_changed());
  EXPECT_NE(session.error().find(fish_.string()), std::string::npos) << session.error();
  EXPECT_EQ(session.model().name, "Steel Fish");
  EXPECT_EQ(session.model_generation(), generation) << "the old model must stay";
  EXPECT_FALSE(session.reload_if_changed()) << "a broken file is read once, not every poll";

  // The old mobile keeps moving.
  session.advance(0.05, 1e9);
  const State& after = session.simulation().state();
  EXPECT_NEAR(after.time, 0.10, 1e-9);
  double moved = 0;
  for (int i = 1; i < session.model().count; ++i) moved = std::max(moved, (after.position[i] - before.position[i]).norm());
  // Released off balance, the lowest pieces fall away from the drawn pose at g/2 t^2 scale: over 0.05 s
  // well above 1e-7 m (the motion is millimetres by t = 0.1 s).
  EXPECT_GT(moved, 1e-7);

  // A fixed file (renamed mobile) replaces it, from rest, and the error goes.
  std::string renamed = fish_text_;
  renamed.replace(renamed.find("Steel Fish"), 10, "Steel Carp");
  write_later(fish_, renamed, 4);
  EXPECT_TRUE(session.reload_if_changed());
  EXPECT_EQ(session.error(), "");
  EXPECT_EQ(session.model().name, "Steel Carp");
  EXPECT_EQ(session.model_generation(), generation + 1);
  EXPECT_EQ(session.simulation().state().time, 0.0);
}

// The panel's settings keep the mobile file's rules (the panel's sliders clamp too, but a value typed
// into one used to pass unclamped): out of range, the session refuses with a message and keeps what runs.
TEST_F(Session, SettingsFromTheWindowKeepTheFilesRules) {
  MobileSession session(fish_.string());
  const int generation = session.model_generation();
  const std::pair<BuildSettings, const char*> refused[] = {
      {BuildSettings{{}, 1e300, {}, {}, {}}, "the total mass must be a number from 1e-06 to 1e+06 (kg)"},
      {BuildSettings{{}, {}, 5.0, {}, {}}, "the restitution must be a number from 0 to 1"},
      {BuildSettings{{}, {}, {}, -1.0, {}}, "the friction coefficient must be a number >= 0"},
  };
  for (const auto& [build, message] : refused) {
    EXPECT_FALSE(session.rebuild(build)) << message;
    EXPECT_EQ(session.error(), message);
    EXPECT_EQ(session.model_generation(), generation) << "the old model must stay";
  }
  const DampingSpec damping = session.damping();
  EXPECT_FALSE(session.set_damping(DampingSpec{1e300, 0.1}));
  EXPECT_EQ(session.error(), "the damping rates must be a number from 0 to 100 (1/s)");
  EXPECT_EQ(session.damping().linear, damping.linear);
  // Within the rules both are taken, and the error goes.
  EXPECT_TRUE(session.set_damping(DampingSpec{0.5, 0.5}));
  EXPECT_EQ(session.damping().linear, 0.5);
  EXPECT_TRUE(session.rebuild(BuildSettings{{}, {}, 0.5, {}, {}}));
  EXPECT_EQ(session.error(), "");
  EXPECT_EQ(session.model().restitution.at(1), 0.5);
#if ALOFT_HAVE_WIND
  // A set alpha follows a shorter l0 down to water's (kDensestWind l0^4 = 1000 * 0.5^4 = 62.5 kg m, exact).
  session.wind_control.settings.alpha = 500;
  session.wind_control.l0 = 0.5;
  ASSERT_TRUE(session.update_wind(Vec3(0, 0, -1))) << session.error();
  EXPECT_EQ(session.wind()->alpha(), 62.5);
  session.wind_control.settings.alpha = 10;  // within the rule: kept
  ASSERT_TRUE(session.update_wind(Vec3(0, 0, -1))) << session.error();
  EXPECT_EQ(session.wind()->alpha(), 10);
#endif
}

TEST_F(Session, ErrorsNameTheFileAndPlace) {
  MobileSession session(fish_.string());
  // A negative radius: a meaning error with a JSON path and a line.
  std::string bad = fish_text_;
  bad.replace(bad.find("\"radius\": 0.012"), 15, "\"radius\": -0.012");
  const fs::path other = dir_ / "bad.json";
  std::ofstream(other, std::ios::binary) << bad;
  EXPECT_FALSE(session.load(other.string()));
  EXPECT_NE(session.error().find("bad.json:"), std::string::npos) << session.error();
  EXPECT_NE(session.error().find("radius"), std::string::npos) << session.error();
  EXPECT_EQ(session.path(), fish_.string()) << "the dropped broken file is not adopted";

  EXPECT_FALSE(session.load((dir_ / "missing.json").string()));
  EXPECT_NE(session.error().find("missing.json"), std::string::npos) << session.error();
  EXPECT_EQ(session.model().name, "Steel Fish");
}

TEST_F(Session, DroppedFileReplacesTheMobile) {
  MobileSession session(fish_.string());
  const std::string cross = (fs::path(ALOFT_SOURCE_DIR) / "mobiles/southern-cross.json").string();
  EXPECT_TRUE(session.load(cross));
  EXPECT_EQ(session.path(), cross);
  EXPECT_EQ(session.model().name, "Southern Cross");
}

TEST_F(Session, TotalMassRecompilesAndKeepsTheMotion) {
  MobileSession session(fish_.string());
  const Model before = session.model();
  session.advance(0.02, 1e9);
  BuildSettings doubled = session.build_settings();
  doubled.total_mass = 2 * before.balance.total_mass;
  ASSERT_TRUE(session.rebuild(doubled)) << session.error();
  // Balance by mass is linear in the total: every derived mass doubles (to rounding).
  for (int i = 1; i < before.count; ++i) EXPECT_NEAR(session.model().mass[i], 2 * before.mass[i], 1e-12 * before.mass[i]);
  EXPECT_NEAR(session.simulation().state().time, 0.02, 1e-12) << "same geometry: the state carries over";

  BuildSettings bad = doubled;
  bad.total_mass = -1;
  EXPECT_FALSE(session.rebuild(bad));
  EXPECT_FALSE(session.error().empty());
  EXPECT_NEAR(session.model().balance.total_mass, 2 * before.balance.total_mass, 1e-12);
}

TEST_F(Session, GrabSpringPullsTheComponentTowardsTheCursor) {
  MobileSession session(fish_.string());  // balanced: at rest it does not move by itself
  const int c = session.model().count - 1;  // the last piece in depth-first order: a leaf
  const Vec3 start = session.simulation().state().position[c];
  const Vec3 pull(0.1, 0, 0);              // 10 cm sideways
  session.grab(Grab{c, Vec3::Zero(), start + pull});
  EXPECT_GT(session.grab_force().dot(pull), 0);
  for (int i = 0; i < 30; ++i) session.advance(1.0 / 60, 1e9);
  const Vec3 moved = session.simulation().state().position[c] - start;
  // After 0.5 s the spring has moved the piece a good part of the way (a free end of a mobile is soft
  // sideways: its pendulum stiffness m g / L is far below the spring's); 2 cm is a fifth of the pull.
  EXPECT_GT(moved.dot(pull.normalized()), 0.02);
  session.release();
  EXPECT_EQ(session.grab_force(), Vec3::Zero());
}

TEST_F(Session, PacingFollowsTheWallClockAndTheTimeScale) {
  MobileSession session(fish_.string());
  const double h = session.simulation().timestep();
  EXPECT_NEAR(session.advance(0.05, 1e9), 0.05, h);   // real time, to a step
  session.time_scale = 0.25;
  EXPECT_NEAR(session.advance(0.04, 1e9), 0.01, h);   // slow motion
  session.time_scale = 1;
  EXPECT_NEAR(session.advance(5.0, 1e9), 0.1, h);     // a stall does not cause a jump: 0.1 s at most
  session.paused = true;
  EXPECT_EQ(session.advance(0.05, 1e9), 0.0);
  const double t = session.simulation().state().time;
  session.single_step();
  EXPECT_NEAR(session.simulation().state().time - t, h, 1e-12);
  session.reset();
  EXPECT_EQ(session.simulation().state().time, 0.0);
}

// The Contacts panel's tally: the leaning balls knock at 0.34 s and rest on each other; the pair is
// touching at the last step; a reset starts the tally afresh.
TEST_F(Session, CountsThePairsThatTouchAndStartsAfreshOnReset) {
  const fs::path balls = dir_ / "balls.json";
  std::ofstream(balls, std::ios::binary) << aloft::test::kLeaningBalls;
  MobileSession session(balls.string());
  for (int step = 0; step < 3000; ++step) session.single_step();
  const std::vector<ContactTally::Pair> pairs = session.contact_tally().pairs();
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(session.model().names[pairs[0].a], "left");
  EXPECT_EQ(session.model().names[pairs[0].b], "right");
  EXPECT_GT(pairs[0].steps, 1000);
  EXPECT_EQ(pairs[0].last, session.last_step_time()) << "touching now";
  std::vector<std::uint8_t> touching;
  session.touching_now(touching);
  EXPECT_EQ(touching, (std::vector<std::uint8_t>{0, 1, 1}));  // hook, left, right: the glow's pieces
  session.reset();
  EXPECT_TRUE(session.contact_tally().pairs().empty());
  session.touching_now(touching);
  EXPECT_EQ(touching, (std::vector<std::uint8_t>{0, 0, 0}));
  session.single_step();  // at rest in the drawn pose, 10 degrees apart: nothing touches
  EXPECT_TRUE(session.contact_tally().pairs().empty());
}

}  // namespace
}  // namespace aloft::view
