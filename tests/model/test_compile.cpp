// Compiling a mobile file's components: mass properties that keep small parts' inertia.

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

}  // namespace
}  // namespace aloft
