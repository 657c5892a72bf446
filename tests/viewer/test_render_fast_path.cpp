// The renderer's fast path (a FrameTarget: the room shaded once and reused, the shadow blended from the
// cached lit and unlit room, anti-aliasing only over the mobile's rectangles) against the reference
// (everything shaded anew through the whole multisampled buffer), and what anti-aliasing does to a
// thin wire. Drawn in-process on Mesa's llvmpipe through EGL (no display needed).

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <utility>
#include <vector>

#include "aloft/model.hpp"
#include "aloft/render/frame_target.hpp"
#include "aloft/render/headless_context.hpp"
#include "aloft/render/renderer.hpp"
#include "aloft/simulation.hpp"
#include "support/model_builder.hpp"
#include "support/presets.hpp"

namespace aloft::render {
namespace {

constexpr int kWidth = 640, kHeight = 360;  // small: the tests stay fast on a software rasteriser

using Pixels = std::vector<std::uint8_t>;

Pixels draw(Renderer& renderer, FrameTarget& target, const State& state, const OrbitCamera& camera,
            const DrawOptions& options) {
  target.bind();
  renderer.draw(state, camera, kWidth, kHeight, options);
  target.resolve();
  Pixels pixels;
  target.read_rgba(pixels);
  return pixels;
}

struct Difference {
  int largest = 0;        // over every channel of every pixel, 8-bit levels
  double beyond = 0;      // fraction of pixels with some channel more than `tolerance` apart
};

Difference compare(const Pixels& a, const Pixels& b, int tolerance) {
  Difference d;
  long long count = 0;
  for (std::size_t p = 0; p + 3 < a.size(); p += 4) {
    int worst = 0;
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(a[p + c]) - int(b[p + c])));
    d.largest = std::max(d.largest, worst);
    if (worst > tolerance) ++count;
  }
  d.beyond = static_cast<double>(count) / (static_cast<double>(a.size()) / 4);
  return d;
}

// The Steel Fish a moment after being pushed, so pieces are turned and their shadows spread over floor
// and wall.
State pushed_fish(const Model& model) {
  State start = rest_state(model);
  for (std::size_t i = 1; i < start.angular.size(); ++i) start.angular[i] = Vec3(0.3, 1.5 * (i % 3), 0.2);  // rad/s
  Simulation sim(model, start);
  for (int k = 0; k < 400 && sim.step(); ++k) {
  }
  return sim.state();
}

// The Steel Fish pushed (above), a renderer with its meshes, the framing camera and a 4x multisampled
// target: the scene of the tests below. Needs a current GL context (the fixture's).
struct PushedFishScene {
  Model model = load_mobile(test::preset_path("steel-fish"));
  Renderer renderer;
  State state;
  OrbitCamera camera;
  FrameTarget target;
  PushedFishScene() {
    renderer.set_model(model);
    state = pushed_fish(model);
    camera = framing_camera(renderer.scene(), double(kWidth) / kHeight);
    target.resize(kWidth, kHeight, 4);
  }
  Pixels draw(const DrawOptions& options) { return render::draw(renderer, target, state, camera, options); }
};

// See SamePictureAsShadingEverythingAnew for the tolerances.
void expect_same_picture(const Pixels& fast, const Pixels& reference) {
  const Difference d = compare(fast, reference, 3);
  EXPECT_LT(d.beyond, 5e-5);
  EXPECT_LT(d.largest, 24);
}

class RenderFastPath : public ::testing::Test {
 protected:
  // Mesa's driver is loaded by libEGL and unloaded at exit with its allocations still held in its own
  // globals; LeakSanitizer then sees them as leaks of an unknown module. Loaded here first and never
  // unloaded (RTLD_NODELETE), those globals stay mapped and the memory stays reachable.
  static void SetUpTestSuite() {
    for (const char* library : {"libEGL_mesa.so.0", "libglapi.so.0", "/usr/lib/x86_64-linux-gnu/dri/swrast_dri.so"})
      dlopen(library, RTLD_NOW | RTLD_NODELETE);
  }
  HeadlessContext context;
};

TEST_F(RenderFastPath, SamePictureAsShadingEverythingAnew) {
  PushedFishScene scene;
  DrawOptions fast, reference;
  reference.reuse_background = false;

  const Pixels first = scene.draw(fast);
  const Pixels again = scene.draw(fast);   // from the cached background
  const Pixels full = scene.draw(reference);
  // The picture must show something besides the room: the mobile and its shadow differ from the room.
  DrawOptions empty_room = reference;
  empty_room.mobile = false;
  const Pixels room = scene.draw(empty_room);
  EXPECT_GT(compare(full, room, 24).beyond, 0.01);

  // The cache changes nothing: the second frame is the first, bit for bit.
  EXPECT_EQ(compare(first, again, 0).largest, 0);

  // Against the reference: the shadow is the cached lit and unlit room blended in linear colour, so a
  // room pixel differs by the 8-bit rounding of the two cached pictures carried through the blend (at
  // most 2 levels; 3 allows for the final rounding). Beyond that only a handful of pixels where a
  // multisampled edge meets a shadow's edge (the fast path blends the resolved pixel where the
  // reference shades each sample): under 5e-5 of the picture (11 pixels; 2 seen). A missed patch of
  // shadow is off by the shadow's full contrast (~65 levels) over tens of pixels (one rectangle
  // dropped: 46 pixels, 2e-4), so the largest difference must also stay under that: 24 levels, a bit
  // over a third of the contrast, the most an edge pixel shared with a shadow's edge shows.
  expect_same_picture(again, full);
}

TEST_F(RenderFastPath, CacheFollowsTheCamera) {
  PushedFishScene scene;
  DrawOptions fast, reference;
  reference.reuse_background = false;

  const Pixels before = scene.draw(fast);
  scene.camera.orbit(0.3, 0.1);
  // While the camera moves the background is redrawn without anti-aliasing; the first frame with the
  // camera at rest draws it again with anti-aliasing, and then it matches the reference (as above).
  const Pixels moving = scene.draw(fast);
  const Pixels rested = scene.draw(fast);
  const Pixels full = scene.draw(reference);
  EXPECT_GT(compare(before, rested, 24).beyond, 0.05);   // the view did change (the room moved)
  // Moving: the floor-wall line aliased (a pixel or two per column, under 1 % of the picture; 0.2 %
  // seen), no stale room (that would be most of the picture, as `before` against `rested` shows).
  EXPECT_LT(compare(moving, full, 3).beyond, 0.01);
  expect_same_picture(rested, full);
}

// DrawOptions::glowing (pieces touching another): the glowing piece is tinted, more strongly than the
// grabbed one's glow, and nothing else changes (its shadow neither).
TEST_F(RenderFastPath, AGlowingPieceIsTintedAndNothingElse) {
  PushedFishScene scene;
  const int count = scene.model.count;
  DrawOptions plain;
  plain.reuse_background = false;
  const int leaf = 3;  // "O3 white leaf": a large plate, well in view
  DrawOptions glowing = plain, grabbed = plain;
  glowing.glowing.assign(static_cast<std::size_t>(count), 0);
  glowing.glowing[leaf] = 1;
  grabbed.highlighted = leaf;

  const Pixels none = scene.draw(plain);
  const Pixels glow = scene.draw(glowing);
  const Pixels grab = scene.draw(grabbed);
  // All zero is no glow at all, bit for bit.
  DrawOptions zeros = plain;
  zeros.glowing.assign(static_cast<std::size_t>(count), 0);
  EXPECT_EQ(compare(none, scene.draw(zeros), 0).largest, 0);
  // The leaf's pixels change: over 100 of them (192 seen, 8e-4 of the picture; the leaf is turned
  // nearly edge-on in this pose).
  EXPECT_GT(compare(none, glow, 3).beyond, 100.0 / (kWidth * kHeight));
  // Only where the grabbed leaf's glow also changes the picture (the same piece, not its shadow nor any
  // other piece), and by more.
  long long changed = 0, outside = 0, stronger = 0;
  for (std::size_t i = 0; i + 3 < none.size(); i += 4) {
    int by_glow = 0, by_grab = 0;
    for (int c = 0; c < 3; ++c) {
      by_glow = std::max(by_glow, std::abs(int(glow[i + c]) - int(none[i + c])));
      by_grab = std::max(by_grab, std::abs(int(grab[i + c]) - int(none[i + c])));
    }
    if (by_glow <= 3) continue;
    ++changed;
    outside += by_grab == 0;
    stronger += by_glow > by_grab;
  }
  EXPECT_EQ(outside, 0);
  EXPECT_GT(stronger, 0.9 * changed);
}

// A thin dark wire, slanted, in front of the wall: with anti-aliasing its edge pixels take colours
// between the wire's and the wall's (partial coverage), which the aliased picture lacks; the wire's
// total darkening (its coverage summed over the picture) stays about the same.
TEST_F(RenderFastPath, AntiAliasingGivesAWireIntermediateColours) {
  Model model = test::empty_model(2);
  model.rest_position[0] = Vec3(0, 2.0, 0);
  model.shapes[0].assign(1, BodyShape{Shape(std::in_place_type<Sphere>, Sphere{Vec3::Zero(), 0.01}), Color{}});
  model.parent[1] = 0;
  model.rest_position[1] = Vec3(0, 1.7, 0);
  model.joint_world[1] = Vec3(0, 2.0, 0);
  // 0.6 mm radius: drawn at the minimum of 1.2 mm, under a pixel wide at this distance.
  model.shapes[1].assign(
      1, BodyShape{Shape(std::in_place_type<Wire>, Wire{Vec3(-0.5, -0.15, 0), Vec3(0.5, 0.15, 0), 0.0006}), Color{}});
  model.color = {Color{0.1f, 0.1f, 0.1f}, Color{0.05f, 0.05f, 0.05f}};
  test::finish_model(model);
  const State state = rest_state(model);

  Renderer renderer;
  renderer.set_model(model);
  const OrbitCamera camera = framing_camera(renderer.scene(), double(kWidth) / kHeight);
  DrawOptions options;
  options.shadows = false;  // only the wire against the room
  DrawOptions empty = options;
  empty.mobile = false;

  const auto luminance = [](const Pixels& p, std::size_t i) { return (p[i] + p[i + 1] + p[i + 2]) / 3.0; };
  struct Coverage {
    int intermediate = 0;   // pixels between 20 % and 80 % darkened towards the wire
    double total = 0;       // the darkening summed, pixels' worth
  };
  const auto coverage = [&](int samples) {
    FrameTarget target;
    target.resize(kWidth, kHeight, samples);
    const Pixels room = draw(renderer, target, state, camera, empty);
    const Pixels wire = draw(renderer, target, state, camera, options);
    Coverage c;
    for (std::size_t i = 0; i + 3 < wire.size(); i += 4) {
      const double background = luminance(room, i);
      const double darkening = background - luminance(wire, i);
      if (darkening < 2) continue;  // untouched (2 levels: rounding)
      // The wire's own colour is ~20 levels (0.05 lit and encoded); the fraction of the way there.
      const double f = std::clamp(darkening / (background - 20.0), 0.0, 1.0);
      c.total += f;
      if (f > 0.2 && f < 0.8) ++c.intermediate;
    }
    return c;
  };
  const Coverage aliased = coverage(0);
  const Coverage smooth = coverage(4);
  ASSERT_GT(aliased.total, 100) << "the wire must be on the picture";
  // The wire darkens ~400 pixels' worth. Anti-aliased, a sub-pixel line has an edge pixel or two of
  // partial coverage in every column it crosses (over 200 columns here), so hundreds of intermediate
  // pixels (600 seen); aliased, a pixel is hit or missed, and intermediate values come only from the
  // wire's own shading (90 seen): at least 3 times more with anti-aliasing.
  EXPECT_GT(smooth.intermediate, 200);
  EXPECT_GT(smooth.intermediate, 3 * std::max(aliased.intermediate, 1));
  // Coverage is conserved up to sampling: 4 samples against 1 per pixel over ~400 pixels' worth of wire
  // differ by a few per cent (4 % seen); 15 % bounds it.
  EXPECT_NEAR(smooth.total, aliased.total, 0.15 * aliased.total);
}

}  // namespace
}  // namespace aloft::render
