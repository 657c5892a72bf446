// Compiling a mobile file's components: mass properties that keep small parts' inertia, and balance
// modes that name the right cause when they cannot balance (or have nothing to balance: no gravity).

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "aloft/error.hpp"
#include "aloft/model.hpp"
#include "aloft/spec.hpp"

namespace aloft {
namespace {

// A bar hanging from the hook at (0, 2, 0), with 'a' and 'b' hanging from its ends at x = -0.5 and 0.5
// m; `a_shapes` and `b_shapes` are their shapes, `extra` more top-level keys (each ending in a comma).
std::string bar_mobile(const std::string& mode, const std::string& a_shapes, const std::string& b_shapes,
                       const std::string& extra = "") {
  return R"({"name": "t", )" + extra + R"( "balance": {"mode": ")" + mode + R"(", "total_mass": 0.3},
 "components": [
  {"name": "hook", "fixed": true, "shapes": [{"sphere": {"center": [0, 2, 0], "radius": 0.01}}]},
  {"name": "bar", "parent": "hook", "joint": [0, 2, 0],
   "shapes": [{"wire": {"from": [0, 2, 0], "to": [0, 1.8, 0], "radius": 0.0005}},
              {"wire": {"from": [-0.5, 1.8, 0], "to": [0.5, 1.8, 0], "radius": 0.002}}]},
  {"name": "a", "parent": "bar", "joint": [-0.5, 1.8, 0], "shapes": [)" +
         a_shapes + R"(]},
  {"name": "b", "parent": "bar", "joint": [0.5, 1.8, 0], "shapes": [)" +
         b_shapes + R"(]}
 ]})";
}

const std::string kBall = R"({"sphere": {"center": [0.5, 1.55, 0], "radius": 0.05}},
                             {"wire": {"from": [0.5, 1.8, 0], "to": [0.5, 1.6, 0], "radius": 0.0005}})";

Model compile_text(const std::string& text) { return compile(parse_mobile_text(text, "t.json", ".")); }

// The InputError compiling `text` throws, or a test failure.
InputError compile_error(const std::string& text) {
  try {
    compile_text(text);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError for:\n" << text;
  return InputError("", {}, "");
}

TEST(Compile, SmallPartFarFromTheOriginKeepsItsInertia) {
  // A 1e-10 m ball 1.8 m up: summed about the world origin its moments came out -2.3e-41 kg m^2 (the
  // true 1.3e-46 lost under m |c|^2 ~ 1e-25), and the first step went NaN.
  const double r = 1e-10;
  const Model m = compile_text(bar_mobile(
      "none", R"({"sphere": {"center": [-0.5, 1.8, 0], "radius": 1e-10}})", kBall));
  const int a = 2;
  ASSERT_EQ(m.names[a], "a");
  const double want = 0.4 * m.mass[a] * r * r;  // 2/5 m r^2
  // 1e-9 relative: one shape, so only the rounding of the closed form and of the eigen solve.
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.principal_moments[a][k] / want, 1, 1e-9) << k;
}

TEST(Compile, InertiaBelowDoublePrecisionIsRefused) {
  // r = 1e-80 m: a volume of 4e-240 m^3, but 2/5 m r^2 underflows to 0 kg m^2.
  const InputError e =
      compile_error(bar_mobile("none", R"({"sphere": {"center": [-0.5, 1.8, 0], "radius": 1e-80}})", kBall));
  EXPECT_EQ(e.place().path, "components[2].shapes") << e.what();
  EXPECT_NE(e.problem().find("the component's inertia is not positive"), std::string::npos) << e.what();
}

TEST(Compile, WithoutGravityEveryPoseBalances) {
  // 'a' hangs 0.3 m off its joint's vertical: under gravity "mass" cannot balance it and "joints" moves
  // its joint. Without gravity there is no arm: both keep the design and the densities' mass ratios.
  const std::string off = R"({"sphere": {"center": [-0.2, 1.7, 0], "radius": 0.05}},
                             {"wire": {"from": [-0.5, 1.8, 0], "to": [-0.2, 1.7, 0], "radius": 0.0005}})";
  EXPECT_NE(compile_error(bar_mobile("mass", off, kBall)).problem().find("cannot balance"), std::string::npos);
  const Model none = compile_text(bar_mobile("none", off, kBall, R"("gravity": [0, 0, 0],)"));
  for (const std::string mode : {"mass", "joints"}) {
    const Model m = compile_text(bar_mobile(mode, off, kBall, R"("gravity": [0, 0, 0],)"));
    EXPECT_EQ(m.balance.max_imbalance, 0) << mode;
    for (int i = 1; i < m.count; ++i) {
      // 1e-12 relative: "none" and the balance modes scale the same base masses to the same total.
      EXPECT_NEAR(m.mass[i] / none.mass[i], 1, 1e-12) << mode << " " << m.names[i];
      EXPECT_EQ(m.joint_world[i], none.joint_world[i]) << mode << " " << m.names[i];
    }
  }
}

TEST(Compile, BalanceNamesWhyItCannot) {
  // A 0.1 mm bead against a 4 kg ball on equal arms: a balance exists, but the ball would have to weigh
  // 1e8 times less than drawn. It used to say the pieces do not lie on both sides of the joint.
  const InputError unequal = compile_error(
      bar_mobile("mass", R"({"sphere": {"center": [-0.5, 1.8, 0], "radius": 1e-4}})", kBall));
  EXPECT_EQ(unequal.place().path, "components[1].joint") << unequal.what();
  EXPECT_NE(unequal.problem().find("the weight of 'b' would have to be"), std::string::npos) << unequal.what();
  EXPECT_NE(unequal.problem().find("masses are too unequal"), std::string::npos) << unequal.what();
  EXPECT_EQ(unequal.problem().find("both sides"), std::string::npos) << unequal.what();

  // Both children on the right of the bar's joint: no positive masses balance it.
  std::string one_sided = bar_mobile("mass", R"({"sphere": {"center": [0.2, 1.55, 0], "radius": 0.05}},
      {"wire": {"from": [0.2, 1.8, 0], "to": [0.2, 1.6, 0], "radius": 0.0005}})", kBall);
  one_sided.replace(one_sided.find("[-0.5, 1.8, 0], \"shapes\""), 14, "[0.2, 1.8, 0]");
  const InputError sided = compile_error(one_sided);
  EXPECT_EQ(sided.place().path, "components[1].joint") << sided.what();
  EXPECT_NE(sided.problem().find("do not lie on both sides of the joint"), std::string::npos) << sided.what();
}

}  // namespace
}  // namespace aloft
