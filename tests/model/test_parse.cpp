// The mobile-file parser: values and defaults, every class of error (with file, JSON path and line), the
// JSON locator, robustness on hostile input, speed on a large file, and agreement of the documentation
// (example and JSON Schema) with the parser.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "aloft/model.hpp"
#include "aloft/spec.hpp"
#include "model/format_keys.hpp"
#include "model/json_locator.hpp"
#include "support/test_dir.hpp"

namespace aloft {
namespace {

namespace fs = std::filesystem;

// 1-based line of the first occurrence of `needle` in `text` (computed independently of the locator).
int line_of(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << "test text lacks " << needle;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

// A fresh directory under the system's temporary directory, removed at the end of the test.
class TempDir {
 public:
  TempDir() : path_(test::make_test_dir("parse")) {}
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  fs::path write(const std::string& name, const std::string& content) const {
    const fs::path p = path_ / name;
    std::ofstream(p, std::ios::binary) << content;
    return p;
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// Parses `text` expecting an InputError; checks it names `file`, the exact `path` and `line`, and that its
// problem contains `problem_part`. Returns what() for further checks.
std::string expect_error(const std::string& text, const std::string& path, int line, const std::string& problem_part,
                         const std::string& base_dir = ".") {
  const std::string file = "mobiles/test.json";
  try {
    parse_mobile_text(text, file, base_dir);
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), file) << what;
    EXPECT_EQ(e.place().path, path) << what;
    EXPECT_EQ(e.place().line, line) << what;
    EXPECT_NE(what.find(file + ":" + std::to_string(line) + ":"), std::string::npos) << what;
    if (!path.empty()) {
      EXPECT_NE(what.find(": " + path + ": "), std::string::npos) << what;
    }
    EXPECT_NE(e.problem().find(problem_part), std::string::npos) << what;
    return what;
  }
  ADD_FAILURE() << "no InputError for:\n" << text;
  return "";
}

// A two-component mobile with `component` as the second component (hanging from the hook).
std::string with_component(const std::string& component) {
  return R"({
  "name": "test",
  "components": [
    {"name": "hook", "fixed": true,
     "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.01}}]},
)" + component + R"(
  ]
}
)";
}

// ... and with `shape` as that component's only shape.
std::string with_shape(const std::string& shape) {
  return with_component(R"(    {"name": "thing", "parent": "hook", "joint": [0, 1, 0],
     "shapes": [
       )" + shape + R"(
     ]})");
}

constexpr const char* kTetrahedronVertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
constexpr const char* kTetrahedronFaces = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

TEST(Parse, ValidMobileHasItsValuesAndDefaults) {
  const std::string text = R"({
  "name": "small",
  "aloft": 1,
  "components": [
    {"name": "hook", "fixed": true, "shapes": [{"sphere": {"center": [0, 2, 0], "radius": 0.02}}]},
    {"name": "bar", "parent": "hook", "joint": [0, 2, 0], "color": "#ff8000", "density": 2700,
     "restitution": 0.5, "friction": 0.1,
     "shapes": [
       {"wire": {"from": [0, 2, 0], "to": [0, 1.8, 0], "radius": 0.001}, "density": 8900},
       {"box": {"center": [0, 1.8, 0], "size": [0.4, 0.01, 0.02],
                "rotation": {"axis": [0, 0, 2], "degrees": 90}}}
     ]},
    {"name": "leaf", "parent": "bar", "joint": [0.1, 1.8, 0], "color": [0.1, 0.2, 0.3],
     "shapes": [{"plate": {"plane": "yz", "x": 0.1, "thickness": 0.002,
                           "points": [[1.8, 0], [1.7, 0.1], [1.7, -0.1]]}},
                {"plate": {"plane": {"origin": [1, 2, 3], "u": [2, 0, 0], "v": [1, 1, 0]},
                           "thickness": 0.001, "points": [[0, 0], [1, 0], [0, 1]]}}]},
    {"name": "dot", "parent": "bar", "joint": [-0.1, 1.8, 0], "color": "#fff",
     "shapes": [{"plate": {"plane": "xz", "y": 1.5, "thickness": 0.003,
                           "points": [[0, 0], [1, 0], [0, 1]]}}]}
  ]
}
)";
  const MobileSpec spec = parse_mobile_text(text, "small.json");
  EXPECT_EQ(spec.file, "small.json");
  EXPECT_EQ(spec.name, "small");
  EXPECT_EQ(spec.gravity, Vec3(0, -9.81, 0));
  EXPECT_EQ(spec.balance.mode, BalanceMode::None);  // no "balance": the mobile swings as designed
  EXPECT_FALSE(spec.balance.total_mass);
  EXPECT_EQ(spec.density, 7850);
  EXPECT_EQ(spec.damping.linear, 0);
  EXPECT_EQ(spec.damping.angular, 0);
  EXPECT_DOUBLE_EQ(spec.contact.restitution, 0.3);
  EXPECT_DOUBLE_EQ(spec.contact.friction, 0.4);
  EXPECT_TRUE(spec.contact.enabled);
  EXPECT_DOUBLE_EQ(spec.timestep, 0.001);
  EXPECT_DOUBLE_EQ(spec.joint_tolerance, 0.005);
  ASSERT_EQ(spec.components.size(), 4u);

  const ComponentSpec& hook = spec.components[0];
  EXPECT_EQ(hook.name, "hook");
  EXPECT_TRUE(hook.fixed);
  EXPECT_FALSE(hook.parent);
  EXPECT_FALSE(hook.joint);
  EXPECT_FLOAT_EQ(hook.color.r, 0.6f);  // neutral grey by default
  EXPECT_FALSE(hook.density);
  EXPECT_EQ(hook.path, "components[0]");
  ASSERT_EQ(hook.shapes.size(), 1u);
  const auto& sphere = std::get<Sphere>(hook.shapes[0].shape);
  EXPECT_EQ(sphere.center, Vec3(0, 2, 0));
  EXPECT_DOUBLE_EQ(sphere.radius, 0.02);
  EXPECT_EQ(hook.shapes[0].path, "components[0].shapes[0]");

  const ComponentSpec& bar = spec.components[1];
  EXPECT_FALSE(bar.fixed);
  EXPECT_EQ(bar.parent, "hook");
  EXPECT_EQ(*bar.joint, Vec3(0, 2, 0));
  EXPECT_FLOAT_EQ(bar.color.r, 1.0f);
  EXPECT_FLOAT_EQ(bar.color.g, 128 / 255.0f);
  EXPECT_FLOAT_EQ(bar.color.b, 0.0f);
  EXPECT_EQ(bar.density, 2700);
  EXPECT_EQ(bar.restitution, 0.5);
  EXPECT_EQ(bar.friction, 0.1);
  ASSERT_EQ(bar.shapes.size(), 2u);
  const auto& wire = std::get<Wire>(bar.shapes[0].shape);
  EXPECT_EQ(wire.to, Vec3(0, 1.8, 0));
  EXPECT_EQ(bar.shapes[0].density, 8900);
  EXPECT_FALSE(bar.shapes[1].density);
  const auto& box = std::get<Box>(bar.shapes[1].shape);
  EXPECT_EQ(box.size, Vec3(0.4, 0.01, 0.02));
  // 90 degrees about z: the box's x axis points along world y.
  EXPECT_TRUE((box.rotation * Vec3::UnitX()).isApprox(Vec3::UnitY(), 1e-12));
  EXPECT_TRUE((box.rotation * Vec3::UnitZ()).isApprox(Vec3::UnitZ(), 1e-12));

  const ComponentSpec& leaf = spec.components[2];
  EXPECT_FLOAT_EQ(leaf.color.g, 0.2f);
  const auto& yz = std::get<Plate>(leaf.shapes[0].shape);
  EXPECT_EQ(yz.origin, Vec3(0.1, 0, 0));
  EXPECT_EQ(yz.u_axis, Vec3::UnitY());
  EXPECT_EQ(yz.v_axis, Vec3::UnitZ());
  EXPECT_TRUE(yz.to_world(Vec2(1.7, 0.1)).isApprox(Vec3(0.1, 1.7, 0.1)));
  EXPECT_DOUBLE_EQ(yz.thickness, 0.002);
  ASSERT_EQ(yz.points.size(), 3u);
  EXPECT_EQ(yz.points[1], Vec2(1.7, 0.1));
  const auto& frame = std::get<Plate>(leaf.shapes[1].shape);
  EXPECT_EQ(frame.origin, Vec3(1, 2, 3));
  EXPECT_TRUE(frame.u_axis.isApprox(Vec3::UnitX()));
  EXPECT_TRUE(frame.v_axis.isApprox(Vec3::UnitY()));  // [1, 1, 0] made orthogonal to u

  const ComponentSpec& dot = spec.components[3];
  EXPECT_FLOAT_EQ(dot.color.b, 1.0f);
  const auto& xz = std::get<Plate>(dot.shapes[0].shape);
  EXPECT_TRUE(xz.to_world(Vec2(2, 3)).isApprox(Vec3(2, 1.5, 3)));
}

TEST(Parse, TopLevelSettings) {
  const std::string text = R"({"name": "s", "gravity": [0, -1.62, 0], "density": 1000, "timestep": 0.002,
    "joint_tolerance": 0.01, "damping": {"linear": 0.1, "angular": 0.2},
    "contact": {"restitution": 0.9, "friction": 0, "enabled": false},
    "balance": {"mode": "joints", "total_mass": 2},
    "components": [{"name": "h", "fixed": true, "shapes": [{"sphere": {"center": [0,0,0], "radius": 1}}]}]})";
  const MobileSpec spec = parse_mobile_text(text);
  EXPECT_EQ(spec.gravity, Vec3(0, -1.62, 0));
  EXPECT_EQ(spec.density, 1000);
  EXPECT_EQ(spec.timestep, 0.002);
  EXPECT_EQ(spec.joint_tolerance, 0.01);
  EXPECT_EQ(spec.damping.linear, 0.1);
  EXPECT_EQ(spec.damping.angular, 0.2);
  EXPECT_EQ(spec.contact.restitution, 0.9);
  EXPECT_EQ(spec.contact.friction, 0);
  EXPECT_FALSE(spec.contact.enabled);
  EXPECT_EQ(spec.balance.mode, BalanceMode::Joints);
  EXPECT_EQ(spec.balance.total_mass, 2);
}

TEST(Parse, BalanceModes) {
  const std::string head = R"({"name": "s", "components": [{"name": "h", "fixed": true,
    "shapes": [{"sphere": {"center": [0,0,0], "radius": 1}}]}],
    "balance": )";
  EXPECT_EQ(parse_mobile_text(head + R"({"mode": "mass", "total_mass": 0.5}})").balance.mode, BalanceMode::Mass);
  EXPECT_EQ(parse_mobile_text(head + R"({"total_mass": 0.5}})").balance.mode, BalanceMode::Mass);
  const MobileSpec none = parse_mobile_text(head + R"({"mode": "none"}})");
  EXPECT_EQ(none.balance.mode, BalanceMode::None);
  EXPECT_FALSE(none.balance.total_mass);
  expect_error(head + "\n{\"mode\": \"mass\"}}", "balance", 4, "missing key \"total_mass\"");
  expect_error(head + "\n{}}", "balance", 4, "missing key \"total_mass\"");
  expect_error(head + "\n{\"mode\": \"heavy\"}}", "balance.mode", 4, "must be \"mass\", \"joints\" or \"none\"");
  expect_error(head + "\n{\"mode\": \"none\", \"total_mass\": 0}}", "balance.total_mass", 4,
               "must be a number from 1e-06 to 1e+06 (kg), got 0");
}

TEST(Parse, SyntaxErrorHasLineAndPlainMessage) {
  const std::string text = "{\n  \"name\": \"x\",\n  \"components\": [\n    {\"name\": \"a\" \"fixed\": true}\n  ]\n}\n";
  const std::string what = expect_error(text, "", 4, "expected '}'");
  EXPECT_EQ(what.find("json.exception"), std::string::npos) << what;
  EXPECT_EQ(what.find("parse error at"), std::string::npos) << what;
  // The column is that of the unexpected string: `    {"name": "a" "fixed"` -> column 18.
  try {
    parse_mobile_text(text, "f.json");
  } catch (const InputError& e) {
    EXPECT_EQ(e.place().column, 18) << e.what();
  }

  const std::string truncated = "{\n  \"name\": \"x\",\n  \"components\": [\n";
  const std::string eof = expect_error(truncated, "", 4, "unexpected end of input");
  expect_error("", "", 1, "unexpected end of input");
  expect_error("{\"name\": \"x\"}\n\n  garbage", "", 3, "expected end of input");
  expect_error("{\"name\": tru}", "", 1, "invalid literal");
}

TEST(Parse, MissingKey) {
  const std::string text = with_shape(R"({"sphere": {"center": [0, 1, 0]}})");
  expect_error(text, "components[1].shapes[0].sphere", line_of(text, "{\"center\": [0, 1, 0]}"),
               "missing key \"radius\"");
  const std::string no_name = "{\n\"components\": []}";
  expect_error(no_name, "", 1, "missing key \"name\"");
  const std::string no_joint = with_component(R"(    {"name": "thing", "parent": "hook",
     "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.1}}]})");
  expect_error(no_joint, "components[1]", line_of(no_joint, "\"thing\""), "missing key \"joint\"");
  const std::string no_parent = with_component(R"(    {"name": "thing", "joint": [0, 1, 0],
     "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.1}}]})");
  expect_error(no_parent, "components[1]", line_of(no_parent, "\"thing\""), "missing key \"parent\"");
}

TEST(Parse, UnknownKeyWithHint) {
  const std::string text = with_component(R"(    {"name": "thing", "parent": "hook", "joint": [0, 1, 0],
     "colour": "#ff0000",
     "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.1}}]})");
  const std::string what = expect_error(text, "components[1]", line_of(text, "colour"), "unknown key \"colour\"");
  EXPECT_NE(what.find("(did you mean \"color\"?)"), std::string::npos) << what;

  const std::string typo = with_shape(R"({"sphere": {"center": [0, 1, 0],
          "raduis": 0.1}})");
  const std::string w2 = expect_error(typo, "components[1].shapes[0].sphere", line_of(typo, "raduis"),
                                      "unknown key \"raduis\" (did you mean \"radius\"?)");
  // Far from every key: the message lists the keys instead.
  const std::string far = "{\"name\": \"x\",\n \"wobble\": 3, \"components\": []}";
  expect_error(far, "", 2, "unknown key \"wobble\" (expected one of: name, aloft, gravity");
}

TEST(Parse, WrongType) {
  const std::string text = with_shape(R"({"sphere": {"center": [0, 1, 0],
          "radius": "big"}})");
  const std::string what = expect_error(text, "components[1].shapes[0].sphere.radius", line_of(text, "\"big\""),
                                        "must be a positive number (m), got \"big\"");
  const std::string fixed = with_component(R"(    {"name": "thing", "parent": "hook", "joint": [0, 1, 0],
     "fixed": "no", "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.1}}]})");
  expect_error(fixed, "components[1].fixed", line_of(fixed, "\"no\""), "must be true or false, got \"no\"");
  expect_error("{\"name\": 3, \"components\": []}", "name", 1, "must be a non-empty string, got 3");
  expect_error("[1, 2]", "", 1, "must hold one JSON object");
  const std::string shapes = with_component(R"(    {"name": "thing", "parent": "hook", "joint": [0, 1, 0],
     "shapes": {"sphere": {"center": [0, 1, 0], "radius": 0.1}}})");
  expect_error(shapes, "components[1].shapes", line_of(shapes, "\"shapes\": {"), "must be a non-empty array of shapes");
}

TEST(Parse, NonFiniteNumber) {
  const std::string text = with_shape(R"({"sphere": {"center": [0, 1, 0],
          "radius": 1e999}})");
  expect_error(text, "components[1].shapes[0].sphere.radius", line_of(text, "1e999"),
               "must be a finite number, got 1e999");
  const std::string in_array = with_shape(R"({"sphere": {"center": [0,
    -1e400, 0], "radius": 1}})");
  expect_error(in_array, "components[1].shapes[0].sphere.center[1]", line_of(in_array, "-1e400"), "finite");
}

TEST(Parse, NonPositiveSize) {
  const std::string text = with_shape(R"({"box": {"center": [0, 1, 0],
          "size": [0.1, 0, 0.1]}})");
  expect_error(text, "components[1].shapes[0].box.size[1]", line_of(text, "\"size\""),
               "must be a positive number (m), got 0");
  const std::string radius = with_shape(R"({"sphere": {"center": [0, 1, 0],
          "radius": -0.01}})");
  expect_error(radius, "components[1].shapes[0].sphere.radius", line_of(radius, "-0.01"),
               "must be a positive number (m), got -0.01");
  const std::string dt = "{\"name\": \"x\",\n\"timestep\": 0.1, \"components\": []}";
  expect_error(dt, "timestep", 2, "must be a number of seconds from 1e-06 to 0.01, got 0.1");
  const std::string tiny_dt = "{\"name\": \"x\",\n\"timestep\": 1e-300, \"components\": []}";
  expect_error(tiny_dt, "timestep", 2, "must be a number of seconds from 1e-06 to 0.01, got 1e-300");
  const std::string wire = with_shape(R"({"wire": {"from": [0, 1, 0],
          "to": [0, 1, 0], "radius": 0.001}})");
  expect_error(wire, "components[1].shapes[0].wire.to", line_of(wire, "\"to\""), "must differ from \"from\"");
}

TEST(Parse, BadColour) {
  for (const std::string bad : {"\"#12345\"", "\"red\"", "\"#ggg\"", "[1, 0]", "7"}) {
    const std::string text = with_component(R"(    {"name": "thing", "parent": "hook", "joint": [0, 1, 0],
     "color": )" + bad + R"(,
     "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.1}}]})");
    expect_error(text, "components[1].color", line_of(text, "\"color\""), "must be \"#rrggbb\", \"#rgb\" or [r, g, b]");
  }
  const std::string range = with_component(R"(    {"name": "thing", "parent": "hook", "joint": [0, 1, 0],
     "color": [0.5, 1.5, 0],
     "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.1}}]})");
  expect_error(range, "components[1].color[1]", line_of(range, "1.5"), "must be a number from 0 to 1, got 1.5");
}

TEST(Parse, WrongArrayLength) {
  const std::string text = with_component(R"(    {"name": "thing", "parent": "hook",
     "joint": [0, 1],
     "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.1}}]})");
  expect_error(text, "components[1].joint", line_of(text, "[0, 1]"),
               "must be an array of 3 numbers [x, y, z] (m), got an array of 2 values");
  const std::string point = with_shape(R"({"plate": {"plane": "xy", "thickness": 0.01,
          "points": [[0, 0], [1, 0, 0], [0, 1]]}})");
  expect_error(point, "components[1].shapes[0].plate.points[1]", line_of(point, "\"points\""),
               "must be a point [u, v] of 2 numbers");
}

TEST(Parse, ShapeKinds) {
  const std::string none = with_shape(R"({"density": 100})");
  expect_error(none, "components[1].shapes[0]", line_of(none, "{\"density\""),
               "a shape needs exactly one of sphere, wire, box, plate, mesh; found none");
  const std::string two = with_shape(R"({"sphere": {"center": [0, 1, 0], "radius": 0.1},
                  "box": {"center": [0, 1, 0], "size": [1, 1, 1]}})");
  expect_error(two, "components[1].shapes[0]", line_of(two, "{\"sphere\": {\"center\": [0, 1, 0], \"radius\": 0.1},"), "found sphere and box");
}

TEST(Parse, FixedComponentRules) {
  const std::string joint = R"({"name": "x", "components": [
    {"name": "hook", "fixed": true, "joint": [0, 0, 0],
     "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.01}}]}]})";
  expect_error(joint, "components[0].joint", 2, "a fixed component hangs from nothing");
  const std::string parent = R"({"name": "x", "components": [
    {"name": "hook", "fixed": true,
     "parent": "sky", "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.01}}]}]})";
  expect_error(parent, "components[0].parent", 3, "a fixed component hangs from nothing");
}

TEST(Parse, FormatVersion) {
  expect_error("{\"aloft\": 2, \"name\": \"x\", \"components\": []}", "aloft", 1, "must be 1");
}

TEST(Parse, PlateSelfIntersecting) {
  const std::string text = with_shape(R"({"plate": {"plane": "xy", "thickness": 0.01,
          "points": [[0, 0], [1, 1], [1, 0], [0, 1]]}})");
  expect_error(text, "components[1].shapes[0].plate.points", line_of(text, "\"points\""), "");
  const std::string line = with_shape(R"({"plate": {"plane": "xy", "thickness": 0.01,
          "points": [[0, 0], [1, 1], [2, 2]]}})");
  expect_error(line, "components[1].shapes[0].plate.points", line_of(line, "\"points\""), "zero area");
}

TEST(Parse, PlateParallelAxes) {
  const std::string text = with_shape(R"({"plate": {"thickness": 0.01, "points": [[0, 0], [1, 0], [0, 1]],
          "plane": {"origin": [0, 1, 0], "u": [1, 0, 0],
                    "v": [-2, 0, 0]}}})");
  expect_error(text, "components[1].shapes[0].plate.plane.v", line_of(text, "[-2, 0, 0]"),
               "must not be parallel to \"u\"");
  const std::string zero = with_shape(R"({"plate": {"thickness": 0.01, "points": [[0, 0], [1, 0], [0, 1]],
          "plane": {"origin": [0, 1, 0],
                    "u": [0, 0, 0], "v": [0, 1, 0]}}})");
  expect_error(zero, "components[1].shapes[0].plate.plane.u", line_of(zero, "[0, 0, 0]"), "non-zero");
  const std::string offset = with_shape(R"({"plate": {"thickness": 0.01, "points": [[0, 0], [1, 0], [0, 1]],
          "plane": "xy",
          "x": 3}})");
  expect_error(offset, "components[1].shapes[0].plate", line_of(offset, "\"x\""),
               "unknown key \"x\" (with \"plane\": \"xy\" the plane's offset is \"z\")");
}

TEST(Parse, PlateAxesAreOrthonormalEvenWhenNearlyParallelOrHuge) {
  for (const std::string uv : {R"("u": [1, 0, 0], "v": [1, 1e-7, 0])", R"("u": [1e300, 1e300, 0], "v": [0, 0, 1e-300])"}) {
    SCOPED_TRACE(uv);
    const std::string text = with_shape(R"({"plate": {"thickness": 0.01, "points": [[0, 0], [1, 0], [0, 1]],
          "plane": {"origin": [0, 1, 0], )" + uv + "}}}");
    const auto plate = std::get<Plate>(parse_mobile_text(text).components[1].shapes[0].shape);
    EXPECT_NEAR(plate.u_axis.norm(), 1, 1e-15);
    EXPECT_NEAR(plate.v_axis.norm(), 1, 1e-15);
    EXPECT_NEAR(plate.u_axis.dot(plate.v_axis), 0, 1e-15);
  }
  const std::string huge = with_shape(R"({"box": {"center": [0, 1, 0], "size": [1, 1, 1],
          "rotation": {"axis": [1e300, 1e300, 0], "degrees": 30}}})");
  const Mat3 r = std::get<Box>(parse_mobile_text(huge).components[1].shapes[0].shape).rotation;
  EXPECT_TRUE((r.transpose() * r).isApprox(Mat3::Identity(), 1e-14));
  EXPECT_TRUE((r * Vec3(1, 1, 0)).isApprox(Vec3(1, 1, 0), 1e-14));  // the axis stays put
}

TEST(Parse, MeshFileMissing) {
  TempDir dir;
  const std::string text = with_shape(R"({"mesh": {
          "obj": "nowhere/fish.obj"}})");
  expect_error(text, "components[1].shapes[0].mesh.obj", line_of(text, "nowhere"), "fish.obj: no such file",
               dir.path().string());
}

// A directory or a device is named as not a regular file (common/regular_file.hpp, shared with the WAV and
// speed CSV readers); /dev/zero used to be read until memory ran out.
TEST(Parse, MeshFileThatIsNotARegularFile) {
  TempDir dir;
  fs::create_directory(dir.path() / "fish.obj");
  const std::string text = with_shape(R"({"mesh": {"obj": "fish.obj"}})");
  expect_error(text, "components[1].shapes[0].mesh.obj", line_of(text, "fish.obj"), "fish.obj: not a regular file",
               dir.path().string());
  const std::string zero = with_shape(R"({"mesh": {"obj": "/dev/zero"}})");
  expect_error(zero, "components[1].shapes[0].mesh.obj", line_of(zero, "zero"), "/dev/zero: not a regular file");
}

// The mobile file itself likewise: /dev/zero was read until memory ran out ("out of memory", no file named).
TEST(Parse, MobileFileThatIsNotARegularFile) {
  try {
    parse_mobile_file("/dev/zero");
    ADD_FAILURE() << "/dev/zero was read";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/dev/zero: not a regular file");
  }
}

TEST(Parse, MeshIsPlacedAndScaled) {
  TempDir dir;
  dir.write("tet.obj", std::string(kTetrahedronVertices) + kTetrahedronFaces);
  const std::string text = with_shape(R"({"mesh": {"obj": "tet.obj", "scale": [2, 3, 4], "translate": [1, 1, 1]}})");
  const fs::path mobile = dir.write("m.json", text);
  const MobileSpec spec = parse_mobile_file(mobile.string());
  const auto& mesh = std::get<Mesh>(spec.components[1].shapes[0].shape);
  EXPECT_EQ(mesh.file, "tet.obj");
  ASSERT_EQ(mesh.mesh.vertices.size(), 4u);
  EXPECT_EQ(mesh.mesh.vertices[0], Vec3(1, 1, 1));
  EXPECT_EQ(mesh.mesh.vertices[3], Vec3(1, 1, 5));  // (0, 0, 1) scaled by 4 in z, then moved
  EXPECT_EQ(mesh.mesh.triangles.size(), 4u);

  const std::string uniform = with_shape(R"({"mesh": {"obj": "tet.obj", "scale": 0.5}})");
  const MobileSpec half = parse_mobile_text(uniform, "u.json", dir.path().string());
  EXPECT_EQ(std::get<Mesh>(half.components[1].shapes[0].shape).mesh.vertices[1], Vec3(0.5, 0, 0));
}

TEST(Parse, MeshOpen) {
  TempDir dir;
  dir.write("open.obj", std::string(kTetrahedronVertices) + "f 1 3 2\nf 1 2 4\nf 1 4 3\n");  // a face missing
  const std::string text = with_shape(R"({"mesh": {
          "obj": "open.obj"}})");
  // The mobile file's place, then the OBJ file's path and its face's line (the edge 2-3 of the missing
  // face "f 2 3 4" is first met in "f 1 3 2" on line 5).
  expect_error(text, "components[1].shapes[0].mesh.obj", line_of(text, "open.obj"),
               "open.obj: the edge between vertices 2 and 3 belongs to only one face (line 5): the mesh is not closed",
               dir.path().string());
}

// A degenerate face: both places, the mobile file's and the OBJ's line and column of the face.
TEST(Parse, MeshDegenerateFaceNamesItsLine) {
  TempDir dir;
  dir.write("deg.obj", std::string(kTetrahedronVertices) + kTetrahedronFaces + "f 1 2 -3\n");  // vertex 2 twice
  const std::string text = with_shape(R"({"mesh": {
          "obj": "deg.obj"}})");
  const std::string what = expect_error(text, "components[1].shapes[0].mesh.obj", line_of(text, "deg.obj"),
                                        "deg.obj:9:1: face is degenerate (zero area): vertex 2 appears twice",
                                        dir.path().string());
  EXPECT_NE(what.find(": components[1].shapes[0].mesh.obj: " + (dir.path() / "deg.obj").string() + ":9:1: face"),
            std::string::npos)
      << what;
}

// Sizes no mobile has (aloft/spec.hpp: kLongestLength, the total mass and density ranges) are refused
// where they stand: far beyond them the step and the collision tests break. The first case is what
// fuzz_mobile_simulate found: a hook sphere of radius 5.6e128 m crashed libccd when the pairs were pruned.
TEST(Parse, SizesBeyondAnyMobileAreRefused) {
  const std::string huge_hook = R"({
  "name": "test",
  "components": [
    {"name": "hook", "fixed": true,
     "shapes": [{"sphere": {"center": [0, 2, 0], "radius": 5.6e128}}]},
    {"name": "thing", "parent": "hook", "joint": [0, 2, 0],
     "shapes": [{"sphere": {"center": [0, 1.5, 0], "radius": 0.1}}]}
  ]
})";
  expect_error(huge_hook, "components[0].shapes[0].sphere.radius", line_of(huge_hook, "5.6e128"),
               "must be at most 1000 m (no mobile is larger), got 5.6e+128");
  const std::string far = with_shape(R"({"box": {"center": [0, 1, 0],
          "size": [0.1, 1001, 0.1]}})");
  expect_error(far, "components[1].shapes[0].box.size[1]", line_of(far, "1001"), "must be at most 1000 m");
  const std::string away = with_shape(R"({"wire": {"from": [0, 1, 0],
          "to": [0, -2e3, 0], "radius": 0.001}})");
  expect_error(away, "components[1].shapes[0].wire.to[1]", line_of(away, "-2e3"),
               "must be from -1000 to 1000 m (no mobile is larger), got -2000");
  const std::string dense = with_shape(R"({"sphere": {"center": [0, 1, 0], "radius": 0.1},
          "density": 1e300})");
  expect_error(dense, "components[1].shapes[0].density", line_of(dense, "1e300"),
               "must be a number from 0.001 to 1e+06 (kg/m^3), got 1e+300");
  const std::string heavy = R"({"name": "test", "balance": {"mode": "mass",
  "total_mass": 1e300}, "components": []})";
  expect_error(heavy, "balance.total_mass", 2, "must be a number from 1e-06 to 1e+06 (kg), got 1e+300");
  const std::string crushing = R"({"name": "test", "gravity": [0,
  -1e300, 0], "components": []})";
  expect_error(crushing, "gravity[1]", 2, "must be a number from -100 to 100 (m/s^2), got -1e+300");
  const std::string thick_air = R"({"name": "test", "damping": {"linear": 0.1,
  "angular": 1e300}, "components": []})";
  expect_error(thick_air, "damping.angular", 2, "must be a number from 0 to 100 (1/s), got 1e+300");
  // Lengths at the bounds themselves are taken.
  EXPECT_NO_THROW(parse_mobile_text(with_shape(R"({"box": {"center": [0, -1000, 0], "size": [1000, 1000, 1000]}})"),
                                    "mobiles/test.json"));
}

// An OBJ mesh's vertices, once scaled and moved, keep within kLongestLength of the origin too.
TEST(Parse, MeshScaledBeyondAnyMobileIsRefused) {
  TempDir dir;
  dir.write("tet.obj", std::string(kTetrahedronVertices) + kTetrahedronFaces);
  const std::string text = with_shape(R"({"mesh": {"obj": "tet.obj",
          "scale": 1e6}})");
  expect_error(text, "components[1].shapes[0].mesh.obj", line_of(text, "tet.obj"),
               "once scaled and moved, more than 1000 m from the origin (no mobile is larger)", dir.path().string());
}

TEST(Parse, MeshMalformedLine) {
  TempDir dir;
  dir.write("fish.obj", "v 0 0 0\nv 1 0 0\nv 0 1\n");
  const std::string text = with_shape(R"({"mesh": {
          "obj": "fish.obj"}})");
  const fs::path mobile = dir.write("two.json", text);
  try {
    parse_mobile_file(mobile.string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), mobile.string());
    EXPECT_EQ(e.place().path, "components[1].shapes[0].mesh.obj");
    EXPECT_EQ(e.place().line, line_of(text, "fish.obj"));
    // Both places: the mobile file's and the OBJ file's own line.
    EXPECT_EQ(what.rfind(mobile.string() + ":" + std::to_string(line_of(text, "fish.obj")) + ":", 0), 0u) << what;
    EXPECT_NE(what.find("fish.obj:3"), std::string::npos) << what;
  }
}

TEST(Parse, DepthBomb) {
  expect_error(std::string(100000, '['), "", 1, "nesting deeper than 64");
  std::string deep = "{\"name\": \"x\",\n\"components\": [],\n\"gravity\": ";
  for (int i = 0; i < 70; ++i) deep += "[";
  expect_error(deep, "", 3, "nesting deeper than 64");
  // Brackets inside strings do not count.
  const std::string in_string = "{\"name\": \"" + std::string(1000, '[') + "\", \"components\": []}";
  expect_error(in_string, "components", 1, "must be a non-empty array");
}

TEST(Parse, DuplicateKey) {
  const std::string text = with_component(R"(    {"name": "thing", "parent": "hook", "joint": [0, 1, 0],
     "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.1}}],
     "name": "other"})");
  expect_error(text, "components[1]", line_of(text, "\"other\""),
               "duplicate key \"name\" (first at line " + std::to_string(line_of(text, "\"thing\"")) + ")");
  // Keys spelt differently but equal once decoded are the same key.
  expect_error("{\"name\": \"x\",\n\"na\\u006de\": \"y\", \"components\": []}", "", 2, "duplicate key \"name\"");
}

TEST(Parse, FileErrorsNameTheFile) {
  TempDir dir;
  const fs::path missing = dir.path() / "absent.json";
  try {
    parse_mobile_file(missing.string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), missing.string());
    EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos) << e.what();
  }
  const fs::path bad = dir.write("bad.json", "{\n\"name\": \"x\",\n\"components\": [7]}");
  try {
    parse_mobile_file(bad.string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(bad.string() + ":3:", 0), 0u) << e.what();
    EXPECT_EQ(e.place().path, "components[0]");
  }
}

TEST(ParseLocator, PathsLinesAndColumns) {
  const std::string text =
      "{\n"
      "  \"name\": \"x\",\n"
      "  \"components\": [\n"
      "    {\"name\": \"é\", \"shapes\": [\n"
      "      {\"sphere\": {\"center\": [0, 1,\n"
      "                            2], \"radius\": 0.5}}\n"
      "    ]},\n"
      "    {\"a\\\"b\": [], \"c\": {}, \"t\\u00e9\": null}\n"
      "  ]\n"
      "}\n";
  const internal::JsonLocation loc = internal::locate_json(text);
  EXPECT_FALSE(loc.duplicate);
  const auto at = [&](const std::string& path) {
    auto it = loc.map.places.find(path);
    EXPECT_NE(it, loc.map.places.end()) << path;
    return it == loc.map.places.end() ? std::pair{0, 0} : std::pair{it->second.line, it->second.column};
  };
  EXPECT_EQ(at(""), std::pair(1, 1));
  EXPECT_EQ(at("name"), std::pair(2, 11));
  EXPECT_EQ(at("components"), std::pair(3, 17));
  EXPECT_EQ(at("components[0]"), std::pair(4, 5));
  EXPECT_EQ(at("components[0].name"), std::pair(4, 14));
  EXPECT_EQ(at("components[0].shapes"), std::pair(4, 29));  // "é" is one column
  EXPECT_EQ(at("components[0].shapes[0]"), std::pair(5, 7));
  EXPECT_EQ(at("components[0].shapes[0].sphere"), std::pair(5, 18));
  EXPECT_EQ(at("components[0].shapes[0].sphere.center"), std::pair(5, 29));
  EXPECT_EQ(at("components[0].shapes[0].sphere.center[1]"), std::pair(5, 33));
  EXPECT_EQ(at("components[0].shapes[0].sphere.center[2]"), std::pair(6, 29));
  EXPECT_EQ(at("components[0].shapes[0].sphere.radius"), std::pair(6, 43));
  EXPECT_EQ(at("components[1]"), std::pair(8, 5));
  EXPECT_EQ(at("components[1].a\"b"), std::pair(8, 14));
  EXPECT_EQ(at("components[1].c"), std::pair(8, 23));
  EXPECT_EQ(at("components[1].té"), std::pair(8, 38));
  EXPECT_EQ(loc.map.places.size(), 17u);

  EXPECT_EQ(internal::json_path_at(text, text.find("2]")), "components[0].shapes[0].sphere.center[2]");
  EXPECT_EQ(internal::json_path_at(text, text.find("0.5")), "components[0].shapes[0].sphere.radius");
  const auto lc = internal::line_column_at(text, text.find("0.5"));
  EXPECT_EQ(lc.line, 6);
  EXPECT_EQ(lc.column, 43);
}

TEST(ParseLocator, LocateFallsBackToTheNearestAncestor) {
  SourceMap map;
  map.places["components[2]"] = {"components[2]", 7, 5};
  map.places[""] = {"", 1, 1};
  const SourcePlace p = map.locate("components[2].shapes[0].sphere.radius");
  EXPECT_EQ(p.path, "components[2].shapes[0].sphere.radius");
  EXPECT_EQ(p.line, 7);
  EXPECT_EQ(p.column, 5);
  EXPECT_EQ(map.locate("gravity").line, 1);
  EXPECT_EQ(SourceMap{}.locate("x").line, 0);
}

TEST(ParseLocator, DuplicateKeysInLargeObjects) {
  std::string text = "{";
  for (int i = 0; i < 100; ++i) text += "\"k" + std::to_string(i) + "\": " + std::to_string(i) + ",\n";
  text += "\"k42\": 0}";
  const auto loc = internal::locate_json(text);
  ASSERT_TRUE(loc.duplicate);
  EXPECT_EQ(loc.duplicate->key, "k42");
  EXPECT_EQ(loc.duplicate->first.line, 43);
  EXPECT_EQ(loc.duplicate->second.line, 101);
  // The same key in different objects is no duplicate.
  EXPECT_FALSE(internal::locate_json(R"([{"a": 1}, {"a": 2}, {"b": {"a": 3}}])").duplicate);
}

// Arbitrary bytes never crash the locator or the parser, nor escape as anything but InputError.
TEST(ParseLocator, SurvivesArbitraryBytes) {
  std::mt19937 rng(12345);
  const std::string alphabet = "{}[]\",:\\ \n0123456789.eE-+truefalsnu\x80\xc3\xa9";
  const std::string valid = with_shape(R"({"sphere": {"center": [0, 1, 0], "radius": 0.1}})");
  for (int round = 0; round < 3000; ++round) {
    std::string text;
    if (round % 2) {
      text = valid.substr(0, rng() % valid.size());  // truncated
      for (int k = 0; k < 3 && !text.empty(); ++k) text[rng() % text.size()] = alphabet[rng() % alphabet.size()];
    } else {
      const std::size_t n = rng() % 64;
      for (std::size_t i = 0; i < n; ++i) text += alphabet[rng() % alphabet.size()];
    }
    const auto loc = internal::locate_json(text);
    (void)internal::json_path_at(text, rng() % (text.size() + 2));
    (void)internal::line_column_at(text, rng() % (text.size() + 2));
    (void)internal::find_excess_nesting(text, 64);
    try {
      parse_mobile_text(text);
    } catch (const InputError&) {
    }
  }
}

TEST(Parse, LargeMobileParsesWhole) {
  constexpr int kCount = 65535;
  std::string text = R"({"name": "big", "components": [
{"name": "c0", "fixed": true, "shapes": [{"sphere": {"center": [0, 0, 0], "radius": 0.01}}]})";
  text.reserve(16'000'000);
  for (int i = 1; i < kCount; ++i) {
    const std::string y = std::to_string(-0.01 * i);
    text += ",\n{\"name\": \"c" + std::to_string(i) + "\", \"parent\": \"c" + std::to_string(i - 1) +
            "\", \"joint\": [0, " + y + ", 0], \"color\": \"#336699\", \"density\": 2700,\n \"shapes\": " +
            "[{\"wire\": {\"from\": [0, " + y + ", 0], \"to\": [0.25, " + y + ", 0.125], \"radius\": 0.001}}, " +
            "{\"sphere\": {\"center\": [0.25, " + y + ", 0.125], \"radius\": 0.01}}]}";
  }
  text += "\n]}\n";
  // Speed is measured by the BM_Load benchmark (bench/bench_step.cpp), not here: this checks that a
  // 65535-component file parses whole and that the locator still knows its last lines.
  const MobileSpec spec = parse_mobile_text(text, "big.json");
  ASSERT_EQ(spec.components.size(), static_cast<std::size_t>(kCount));
  EXPECT_EQ(spec.components.back().name, "c" + std::to_string(kCount - 1));
  EXPECT_EQ(spec.source.locate("components[65534].shapes[1].sphere.radius").line, 2 * kCount);
}

// ------------------------------------------------------------------------------------------------
// The documentation agrees with the parser.

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The ```json blocks of docs/mobile-format.md that are whole mobiles (have "components").
std::vector<std::string> doc_examples() {
  const std::string doc = read_text(fs::path(ALOFT_SOURCE_DIR) / "docs" / "mobile-format.md");
  std::vector<std::string> blocks;
  std::size_t at = 0;
  while ((at = doc.find("```json\n", at)) != std::string::npos) {
    const std::size_t start = at + 8, end = doc.find("```", start);
    if (end == std::string::npos) break;
    const std::string block = doc.substr(start, end - start);
    if (block.find("\"components\"") != std::string::npos && block.rfind("{", 0) == 0) blocks.push_back(block);
    at = end + 3;
  }
  return blocks;
}

TEST(ParseFormatDoc, ExamplesParseAndCompile) {
  const auto examples = doc_examples();
  ASSERT_GE(examples.size(), 1u);
  for (const auto& text : examples) {
    SCOPED_TRACE(text);
    const MobileSpec spec = parse_mobile_text(text, "docs/mobile-format.md");
    EXPECT_GE(spec.components.size(), 2u);
    EXPECT_NO_THROW(compile(spec));
  }
}

std::set<std::string> keys_of(const nlohmann::json& object) {
  std::set<std::string> keys;
  for (const auto& [k, v] : object.items()) keys.insert(k);
  return keys;
}
template <std::size_t N>
std::set<std::string> set_of(const std::array<std::string_view, N>& a) {
  return {a.begin(), a.end()};
}

TEST(ParseFormatSchema, ListsExactlyTheKeysTheParserAccepts) {
  const auto schema = nlohmann::json::parse(read_text(fs::path(ALOFT_SOURCE_DIR) / "docs" / "mobile-format.schema.json"));
  EXPECT_EQ(schema.at("$schema"), "https://json-schema.org/draft/2020-12/schema");
  EXPECT_EQ(schema.at("additionalProperties"), false);
  EXPECT_EQ(keys_of(schema.at("properties")), set_of(internal::format_keys::kMobile));
  const auto& defs = schema.at("$defs");
  namespace k = internal::format_keys;
  const std::pair<const char*, std::set<std::string>> objects[] = {
      {"balance", set_of(k::kBalance)}, {"damping", set_of(k::kDamping)},   {"contact", set_of(k::kContact)},
      {"component", set_of(k::kComponent)}, {"shape", set_of(k::kShape)},   {"sphere", set_of(k::kSphere)},
      {"wire", set_of(k::kWire)},       {"box", set_of(k::kBox)},           {"rotation", set_of(k::kRotation)},
      {"plate", set_of(k::kPlate)},     {"plane_frame", set_of(k::kPlaneFrame)}, {"mesh", set_of(k::kMesh)},
      {"wind_source", set_of(k::kWindSource)}, {"wind_profile", set_of(k::kWindProfile)},
      {"camera", set_of(k::kCamera)}};
  for (const auto& [name, keys] : objects) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(defs.contains(name));
    EXPECT_EQ(defs.at(name).at("additionalProperties"), false);
    EXPECT_EQ(keys_of(defs.at(name).at("properties")), keys);
  }
}

// With python3 and its jsonschema module: the documentation's examples and the fuzz seeds are valid
// under the schema, and a file with an unknown key is not.
TEST(ParseFormatSchema, ValidatesTheExamples) {
  if (std::system("python3 -c 'import jsonschema' >/dev/null 2>&1") != 0) GTEST_SKIP() << "no python3 jsonschema";
  TempDir dir;
  const auto examples = doc_examples();
  ASSERT_GE(examples.size(), 1u);
  std::vector<fs::path> good;
  for (std::size_t i = 0; i < examples.size(); ++i) good.push_back(dir.write("doc" + std::to_string(i) + ".json", examples[i]));
  for (const auto& entry : fs::directory_iterator(fs::path(ALOFT_SOURCE_DIR) / "fuzz" / "corpus" / "mobile"))
    good.push_back(entry.path());
  const fs::path bad = dir.write("bad.json", with_component(R"({"name": "t", "parent": "hook", "joint": [0, 1, 0],
     "colour": "#fff", "shapes": [{"sphere": {"center": [0, 1, 0], "radius": 0.1}}]})"));
  const fs::path script = dir.write("check.py", R"(import json, sys, jsonschema
schema = json.load(open(sys.argv[1]))
jsonschema.Draft202012Validator.check_schema(schema)
v = jsonschema.Draft202012Validator(schema)
ok = all(v.is_valid(json.load(open(p))) for p in sys.argv[3:])
for p in sys.argv[3:]:
    for e in v.iter_errors(json.load(open(p))): print(p, e.message)
sys.exit(0 if ok and not v.is_valid(json.load(open(sys.argv[2]))) else 1)
)");
  std::string command = "python3 '" + script.string() + "' '" +
                        (fs::path(ALOFT_SOURCE_DIR) / "docs" / "mobile-format.schema.json").string() + "' '" +
                        bad.string() + "'";
  for (const auto& p : good) command += " '" + p.string() + "'";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
}

// ---------------------------------------------------------------------------------------------------
// Wind sources placed by the file ("wind_sources") and the file's camera ("camera").

// A one-component mobile (just the hook) with `keys` (top-level "key": value pairs) on lines 3 onwards.
std::string with_top_keys(const std::string& keys) {
  return "{\n  \"name\": \"test\",\n" + keys +
         ",\n  \"components\": [\n    {\"name\": \"hook\", \"fixed\": true,"
         " \"shapes\": [{\"sphere\": {\"center\": [0, 1, 0], \"radius\": 0.01}}]}\n  ]\n}\n";
}

TEST(ParseScene, WindSourcesAndCameraHaveTheirValuesAndDefaults) {
  const std::string text = with_top_keys(R"(  "wind_sources": [
    {"name": "fan", "from": [1, 1.5, 0.5], "to": [0, 1.5, 0], "r0": 0.2, "l0": 0.8, "speed": 3.5,
     "alpha": 0.6, "beta": 0, "seed": 42},
    {"from": [0, 0.2, 0], "to": [0, 2, 0], "speed": 1,
     "profile": {"type": "on_off", "period": 10, "on": 6, "ramp": 2, "phase": 1}},
    {"name": "vent", "from": [-1, 1, 0], "to": [0, 1, 0], "speed": 0,
     "profile": {"type": "swell", "period": 4}},
    {"name": "still", "from": [-1, 1, 1], "to": [0, 1, 1], "speed": 2, "profile": {"type": "steady"}}
  ],
  "camera": {"yaw": -30, "pitch": 12.5, "distance": 3, "fov": 40, "target": [0.1, 1.2, -0.1]})");
  const MobileSpec spec = parse_mobile_text(text, "scene.json");
  ASSERT_EQ(spec.wind_sources.size(), 4u);
  const WindSourceSpec& fan = spec.wind_sources[0];
  EXPECT_EQ(fan.name, "fan");
  EXPECT_EQ(fan.path, "wind_sources[0]");
  EXPECT_EQ(fan.from, Vec3(1, 1.5, 0.5));
  EXPECT_EQ(fan.to, Vec3(0, 1.5, 0));
  EXPECT_EQ(fan.r0, 0.2);
  EXPECT_EQ(fan.l0, 0.8);
  EXPECT_EQ(fan.speed, 3.5);
  EXPECT_EQ(fan.profile.kind, WindProfileKind::Steady);
  EXPECT_EQ(fan.alpha, 0.6);
  EXPECT_EQ(fan.beta, 0.0);
  EXPECT_EQ(fan.seed, 42u);
  const WindSourceSpec& fan2 = spec.wind_sources[1];
  EXPECT_EQ(fan2.name, "source 2");  // default: "source N", N counted from 1
  EXPECT_EQ(fan2.r0, 0.25);          // defaults: WindSource's r0 and l0
  EXPECT_EQ(fan2.l0, 1.0);
  EXPECT_FALSE(fan2.alpha);
  EXPECT_FALSE(fan2.beta);
  EXPECT_FALSE(fan2.seed);
  EXPECT_EQ(fan2.profile.kind, WindProfileKind::OnOff);
  EXPECT_EQ(fan2.profile.period, 10);
  EXPECT_EQ(fan2.profile.on, 6);
  EXPECT_EQ(fan2.profile.ramp, 2);
  EXPECT_EQ(fan2.profile.phase, 1);
  EXPECT_EQ(spec.wind_sources[2].profile.kind, WindProfileKind::Swell);
  EXPECT_EQ(spec.wind_sources[2].profile.depth, 0.5);  // default depth
  EXPECT_EQ(spec.wind_sources[2].speed, 0);            // a fan switched off is allowed
  EXPECT_EQ(spec.wind_sources[3].profile.kind, WindProfileKind::Steady);
  ASSERT_TRUE(spec.camera);
  EXPECT_EQ(spec.camera->yaw_deg, -30.0);
  EXPECT_EQ(spec.camera->pitch_deg, 12.5);
  EXPECT_EQ(spec.camera->distance, 3.0);
  EXPECT_EQ(spec.camera->fov_deg, 40.0);
  EXPECT_EQ(spec.camera->target, Vec3(0.1, 1.2, -0.1));

  // Every key of the camera is optional; no "camera" and no "wind_sources" are the defaults.
  const MobileSpec partial = parse_mobile_text(with_top_keys(R"(  "camera": {"pitch": -85})"));
  ASSERT_TRUE(partial.camera);
  EXPECT_EQ(partial.camera->pitch_deg, -85.0);
  EXPECT_FALSE(partial.camera->yaw_deg || partial.camera->distance || partial.camera->fov_deg || partial.camera->target);
  const MobileSpec none = parse_mobile_text(with_top_keys(R"(  "density": 1000)"));
  EXPECT_FALSE(none.camera);
  EXPECT_TRUE(none.wind_sources.empty());
  EXPECT_TRUE(parse_mobile_text(with_top_keys(R"(  "wind_sources": [])")).wind_sources.empty());
}

TEST(ParseScene, WindProfilesGiveTheirSpeedFactor) {
  WindProfileSpec p;
  EXPECT_EQ(p.factor(123.4), 1);  // steady
  p.kind = WindProfileKind::OnOff;
  p.period = 10;
  p.on = 6;
  p.ramp = 2;
  // Rise over [0, 2), full until 6, fall over [6, 8), still until 10; then again. Exact arithmetic on
  // these binary-friendly times up to one rounding of fmod/division: 1e-12.
  const std::pair<double, double> on_off[] = {{0, 0},   {1, 0.5}, {2, 1},  {5.9, 1},  {6, 1},   {7, 0.5},
                                              {8, 0},   {9.5, 0}, {11, 0.5}, {-9, 0.5}, {27, 0.5}};
  for (const auto& [t, f] : on_off) EXPECT_NEAR(p.factor(t), f, 1e-12) << "t = " << t;
  p.phase = 1;  // starts 1 s into its cycle
  EXPECT_NEAR(p.factor(0), 0.5, 1e-12);
  p.phase = 0;
  p.ramp = 0;  // a plain switch
  EXPECT_EQ(p.factor(0), 1);
  EXPECT_EQ(p.factor(5.999), 1);
  EXPECT_EQ(p.factor(6), 0);
  // The mean over a period is on / period (the doc's promise), with or without a ramp: midpoint rule on
  // 10^5 points, exact for the piecewise-linear profile up to the kinks' cells, 1e-4.
  for (double ramp : {0.0, 2.0, 4.0}) {
    p.ramp = ramp;
    double sum = 0;
    constexpr int kN = 100000;
    for (int i = 0; i < kN; ++i) sum += p.factor((i + 0.5) * p.period / kN);
    EXPECT_NEAR(sum / kN, 0.6, 1e-4) << "ramp " << ramp;
  }
  WindProfileSpec swell;
  swell.kind = WindProfileKind::Swell;
  swell.period = 4;
  swell.depth = 0.3;
  EXPECT_NEAR(swell.factor(0), 1, 1e-12);    // full at the start of its cycle
  EXPECT_NEAR(swell.factor(2), 0.7, 1e-12);  // 1 - depth at half the period
  EXPECT_NEAR(swell.factor(1), 0.85, 1e-12); // halfway down (cos 90 deg = 0)
  EXPECT_NEAR(swell.factor(4), 1, 1e-12);
  WindSourceSpec source;
  source.speed = 2;
  source.profile = swell;
  EXPECT_NEAR(source.v0(2), 1.4, 1e-12);
}

TEST(ParseScene, BadWindSourcesAndCamerasNameFilePathAndLine) {
  struct Case {
    std::string keys;        // top-level keys
    std::string path;        // the JSON path in the message
    std::string line_at;     // text on the line the message must name
    std::string problem;     // part of the problem
  };
  const std::string fan = R"("from": [1, 1, 0], "to": [0, 1, 0], "speed": 2)";
  const Case cases[] = {
      {R"(  "wind_sources": {"from": [1, 1, 0]})", "wind_sources", "\"wind_sources\"", "must be an array of wind sources"},
      {R"(  "wind_sources": [3])", "wind_sources[0]", "\"wind_sources\"", "must be an object"},
      {"  \"wind_sources\": [\n    {" + fan + R"(, "sped": 2}])", "wind_sources[0]", "\"sped\"",
       "unknown key \"sped\" (did you mean \"speed\"?)"},
      {R"(  "wind_sources": [{"to": [0, 1, 0], "speed": 2}])", "wind_sources[0]", "\"wind_sources\"", "missing key \"from\""},
      {R"(  "wind_sources": [{"from": [1, 1, 0], "to": [0, 1, 0]}])", "wind_sources[0]", "\"wind_sources\"",
       "missing key \"speed\""},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"r0\": \"wide\"}]", "wind_sources[0].r0", "\"wide\"",
       "must be a positive number (m, the radius of the disc S0), got \"wide\""},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"r0\": 0}]", "wind_sources[0].r0", "\"r0\"", "must be a positive number"},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"l0\": -1}]", "wind_sources[0].l0", "\"l0\"", "must be a positive number"},
      {"  \"wind_sources\": [\n    {\"from\": [1, 1, 0], \"to\": [0, 1, 0],\n     \"speed\": -0.5}]",
       "wind_sources[0].speed", "\"speed\"", "must be from 0 to 100 m/s (the cone model treats the air as "
       "incompressible, which holds below about 0.3 of the speed of sound), got -0.5"},
      // Faster than the cone model's incompressible air (kFastestWind).
      {"  \"wind_sources\": [\n    {\"from\": [1, 1, 0], \"to\": [0, 1, 0],\n     \"speed\": 150}]",
       "wind_sources[0].speed", "\"speed\"", "must be from 0 to 100 m/s (the cone model treats the air as "
       "incompressible, which holds below about 0.3 of the speed of sound), got 150"},
      {"  \"wind_sources\": [\n    {\"from\": [1, 1, 0], \"to\": [0, 1, 0],\n     \"speed\": true}]",
       "wind_sources[0].speed", "\"speed\"", "got true"},
      {"  \"wind_sources\": [\n    {\"from\": [1, 1e999, 0], \"to\": [0, 1, 0], \"speed\": 1}]",
       "wind_sources[0].from[1]", "1e999", "must be a finite number, got 1e999"},
      {"  \"wind_sources\": [\n    {\"from\": [1, 1, 0], \"to\": [1, 1, 0], \"speed\": 1}]",
       "wind_sources[0].to", "\"to\"", "must differ from \"from\""},
      {"  \"wind_sources\": [\n    {\"from\": [1, 1], \"to\": [0, 1, 0], \"speed\": 1}]",
       "wind_sources[0].from", "\"from\"", "must be an array of 3 numbers [x, y, z] (m), got an array of 2 values"},
      {"  \"wind_sources\": [\n    {" + fan + ", \"name\": \"a\"},\n    {" + fan + ", \"name\": \"a\"}]",
       "wind_sources[1].name", "}]", "the name \"a\" is already used by wind_sources[0]"},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"beta\": 11}]", "wind_sources[0].beta", "\"beta\"",
       "must be a number from 0 to 10, got 11"},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"alpha\": 0}]", "wind_sources[0].alpha", "\"alpha\"",
       "must be a positive number of at most 1000 kg m: alpha = rho l0^4, and with l0 = 1 m that is water's density, "
       "1000 kg/m^3 (air's alpha is 1.204 kg m), got 0"},
      // Denser than water (kDensestWind) for the source's own l0: 1000 * 0.5^4 = 62.5 kg m.
      {"  \"wind_sources\": [\n    {" + fan + ", \"l0\": 0.5,\n     \"alpha\": 63}]", "wind_sources[0].alpha",
       "\"alpha\"", "must be a positive number of at most 62.5 kg m: alpha = rho l0^4, and with l0 = 0.5 m"},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"alpha\": 1e300}]", "wind_sources[0].alpha", "\"alpha\"",
       "got 1e+300"},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"seed\": -1}]", "wind_sources[0].seed", "\"seed\"",
       "must be a whole number from 0 to 2^63 - 1, got -1"},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"seed\": 1.5}]", "wind_sources[0].seed", "\"seed\"",
       "must be a whole number"},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"profile\": {\"type\": \"pulse\"}}]",
       "wind_sources[0].profile.type", "\"profile\"", "must be \"steady\", \"on_off\" or \"swell\", got \"pulse\""},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"profile\": {\"period\": 3}}]",
       "wind_sources[0].profile", "\"profile\"", "missing key \"type\""},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"profile\": {\"type\": \"on_off\", \"on\": 2}}]",
       "wind_sources[0].profile", "\"profile\"", "missing key \"period\""},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"profile\": {\"type\": \"on_off\", \"period\": 4, \"on\": 5}}]",
       "wind_sources[0].profile.on", "\"profile\"", "must be at most \"period\" (4 s), got 5"},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"profile\": {\"type\": \"on_off\", \"period\": 4, \"on\": 1, \"ramp\": 2}}]",
       "wind_sources[0].profile.ramp", "\"profile\"", "must be at most \"on\" (1 s)"},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"profile\": {\"type\": \"on_off\", \"period\": 4, \"on\": 3, \"ramp\": 2}}]",
       "wind_sources[0].profile.ramp", "\"profile\"", "\"on\" + \"ramp\" must be at most \"period\" (4 s)"},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"profile\": {\"type\": \"on_off\", \"period\": 4, \"on\": 2, \"depth\": 0.5}}]",
       "wind_sources[0].profile", "\"profile\"", "unknown key \"depth\" (with \"type\": \"on_off\" the keys are: type, period, on, ramp, phase)"},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"profile\": {\"type\": \"swell\", \"period\": 4, \"depth\": 1.5}}]",
       "wind_sources[0].profile.depth", "\"profile\"", "must be a number from 0 to 1, got 1.5"},
      {"  \"wind_sources\": [\n    {" + fan + ",\n     \"profile\": {\"type\": \"steady\", \"period\": 4}}]",
       "wind_sources[0].profile", "\"profile\"", "unknown key \"period\" (with \"type\": \"steady\" there are no other keys)"},
      {R"(  "camera": [0, 1])", "camera", "\"camera\"", "must be an object"},
      {"  \"camera\": {\"yaw\": 10,\n    \"pitch\": 90}", "camera.pitch", "\"pitch\"",
       "must be a number from -85 to 85 (degrees), got 90"},
      {"  \"camera\": {\"yaw\": 10,\n    \"fov\": 2}", "camera.fov", "\"fov\"", "must be a number from 5 to 120 (degrees), got 2"},
      {"  \"camera\": {\"yaw\": 10,\n    \"distance\": 0}", "camera.distance", "\"distance\"",
       "must be a positive number (m), got 0"},
      {"  \"camera\": {\"yaw\": \"left\"}", "camera.yaw", "\"camera\"", "must be a number (degrees), got \"left\""},
      {"  \"camera\": {\"yaw\": 10,\n    \"target\": [0, 1e999, 0]}", "camera.target[1]", "\"target\"",
       "must be a finite number"},
      {"  \"camera\": {\"yaw\": 10,\n    \"zoom\": 2}", "camera", "\"zoom\"", "unknown key \"zoom\" (expected one of: yaw, pitch, distance, fov, target)"},
      {"  \"wind_source\": []", "", "\"wind_source\"", "unknown key \"wind_source\" (did you mean \"wind_sources\"?)"},
  };
  for (const Case& c : cases) {
    const std::string text = with_top_keys(c.keys);
    SCOPED_TRACE(text);
    expect_error(text, c.path, line_of(text, c.line_at), c.problem);
  }
  // Water's alpha itself is taken (1000 * 0.5^4 = 62.5 kg m, exact in binary).
  const MobileSpec water = parse_mobile_text(with_top_keys(
      R"(  "wind_sources": [{"from": [1, 1, 0], "to": [0, 1, 0], "speed": 2, "l0": 0.5, "alpha": 62.5}])"));
  EXPECT_EQ(water.wind_sources.at(0).alpha, 62.5);
}

}  // namespace
}  // namespace aloft
