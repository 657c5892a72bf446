// Occlusion by the item buffer: hidden, half hidden, outside the cone, before S0; convergence of the
// visible area with the resolution; the item buffer's contents.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "wind/wind_scenes.hpp"

namespace aloft::test {
namespace {

WindSettings at_resolution(int pixels) {
  WindSettings s;
  s.resolution = pixels;
  s.beta = 0;
  return s;
}

TEST(WindOcclusion, PlateFullyBehindAnotherGetsNothing) {
  // Same size, 0.5 m further along the same axis: its image is smaller, entirely inside the front one's.
  const Model model = plates_model({PlacedPlate{Vec3(0, 0, 2), 0.1}, PlacedPlate{Vec3(0, 0, 2.5), 0.1}});
  const std::vector<Vec3> f = wind_forces(model, axis_source(), at_resolution(512), 2, rest_state(model));
  EXPECT_GT(f[1].z(), 0);
  EXPECT_EQ(f[2], Vec3::Zero());  // not one pixel: exactly nothing
}

TEST(WindOcclusion, HalfHiddenPlateGetsHalfTheForce) {
  // The rear plate is centred on the axis at 2.5 m; the front one at 2 m covers every ray with x < 0
  // (its right edge on the axis, its image 1.25 times the rear one's). By symmetry about the axis, half
  // the rear plate's force remains.
  const PlacedPlate rear{Vec3(0, 0, 2.5), 0.1};
  const PlacedPlate front{Vec3(-0.05, 0, 2), 0.1};
  const Model alone = plates_model({rear});
  const Model both = plates_model({rear, front});
  const WindSettings settings = at_resolution(512);
  const double full = wind_forces(alone, axis_source(), settings, 2, rest_state(alone))[1].z();
  const double half = wind_forces(both, axis_source(), settings, 2, rest_state(both))[1].z();
  // Raster error: the hidden edge falls on a column of pixel centres or between two; the rear image is
  // 0.04 m = 205 pixels wide, so one column is 1/205 = 0.5 % of its force, i.e. 1 % of the half. The
  // tolerance is that one column.
  EXPECT_NEAR(half / full, 0.5, 0.5 / 205);
}

TEST(WindOcclusion, OutsideTheConeOrBeforeS0GetsNothing) {
  // The cone is 0.1 m in radius at z = 2 m: a plate at x = 0.3 m is outside. A plate at z = 0.5 m sits
  // between the vertex and S0 (l0 = 1 m), where the wind does not exist yet.
  const Model model = plates_model({PlacedPlate{Vec3(0.3, 0, 2), 0.1}, PlacedPlate{Vec3(0, 0, 0.5), 0.01}});
  const std::vector<Vec3> f = wind_forces(model, axis_source(), at_resolution(256), 2, rest_state(model));
  EXPECT_EQ(f[1], Vec3::Zero());
  EXPECT_EQ(f[2], Vec3::Zero());
  // Partly inside: a plate straddling the cone's edge feels only its part inside the S0 circle.
  const Model straddling = plates_model({PlacedPlate{Vec3(0.1, 0, 2), 0.1}});
  const Model centred = plates_model({PlacedPlate{Vec3(0, 0, 2), 0.1}});
  const double part = wind_forces(straddling, axis_source(), at_resolution(256), 2, rest_state(straddling))[1].z();
  const double whole = wind_forces(centred, axis_source(), at_resolution(256), 2, rest_state(centred))[1].z();
  EXPECT_GT(part, 0);
  EXPECT_LT(part, 0.5 * whole);  // less than half the plate is inside the circle of radius 0.1 m
}

TEST(WindOcclusion, PlateThroughS0IsClippedAtIt) {
  // A 1 m plate turned 80 deg about y, centred on S0 (z = 1 m): it reaches from z = 0.5 m, between the
  // vertex and S0, to z = 1.5 m, and its image runs far outside the buffer. Only its part beyond S0 and
  // inside the cone feels the wind: a finite force, less than the whole plate would get face-on at 1 m.
  const double theta = 80 * std::numbers::pi / 180;
  const PlacedPlate plate{Vec3(0, 0, 1.0), 1.0, Vec3(std::cos(theta), 0, -std::sin(theta)), Vec3::UnitY()};
  const Model model = plates_model({plate});
  const Vec3 f = wind_forces(model, axis_source(), at_resolution(256), 2, rest_state(model))[1];
  EXPECT_TRUE(f.allFinite());
  EXPECT_GT(f.z(), 0);
  // The cone's cross-section is at most 0.1 m in radius over z in [1, 1.5]: the pushed area is below
  // pi 0.075^2 / cos(80 deg) = 0.1 m^2, and eq. 4 at l1 >= 1 m with cos(80 deg) caps the force at
  // alpha v0^2 * 0.1 * cos(80 deg) = 0.08 N; the face-on plate's 1.2 * 4 * 1 N is far above.
  EXPECT_LT(f.norm(), 0.1);
}

TEST(WindOcclusion, VisibleAreaConvergesWithResolution) {
  // A pentagon-like tilted square (edges not aligned with the pixels): the visible area must approach
  // the plate's area, 0.01 m^2, as the item buffer gets finer.
  const double tilt = 0.6, twist = 0.35;
  const Mat3 rotation = (Eigen::AngleAxisd(twist, Vec3::UnitZ()) * Eigen::AngleAxisd(tilt, Vec3::UnitX())).toRotationMatrix();
  const PlacedPlate plate{Vec3(0.01, -0.02, 2), 0.1, rotation * Vec3::UnitX(), rotation * Vec3::UnitY()};
  const Model model = plates_model({plate});
  double error = 1;
  for (int pixels : {64, 128, 256, 512, 1024}) {
    Wind wind(model, axis_source(), at_resolution(pixels));
    wind.refresh_occlusion(rest_state(model));
    error = std::abs(wind.visible_area()[1] - 0.01) / 0.01;
    // The plate's image is w = pixels / 2 pixels across (0.05 m of the 0.1 m wide S0 square), foreshortened
    // by cos(tilt) in one direction. Pixel-centre sampling misplaces at most half a pixel along each edge:
    // relative error <= 0.5 * 4 w / (w^2 cos(tilt)) = 4 / (pixels cos(tilt)), a bound that goes to zero as the
    // resolution grows (the actual error wanders below it as edges meet pixel centres differently).
    EXPECT_LT(error, 4.0 / (pixels * std::cos(tilt))) << pixels;
  }
  // At 1024 pixels: 0.3 % (the bound is 0.47 %; the edges' errors partly cancel).
  EXPECT_LT(error, 0.003);
}

TEST(WindOcclusion, ItemBufferNamesTheComponents) {
  const Model model = plates_model({PlacedPlate{Vec3(0, 0, 2), 0.1}});
  Wind wind(model, axis_source(), at_resolution(64));
  wind.refresh_occlusion(rest_state(model));
  const ItemBuffer& b = wind.item_buffer();
  ASSERT_EQ(b.width, 64);
  // The plate's image spans half the S0 square: the centre pixel shows it, a corner pixel (outside the
  // circle) shows nothing.
  EXPECT_EQ(b.component_at(32, 32), 1);
  EXPECT_EQ(b.component_at(0, 0), -1);
  EXPECT_EQ(b.component_at(2, 32), -1);
  // Elements carry body and world positions that agree at the refresh's pose.
  for (const WindElement& e : wind.elements()) EXPECT_LT((e.point_world - (Vec3(0, 0, 2) + e.point_body)).norm(), 1e-12);
}

TEST(WindOcclusion, DeterministicAcrossRuns) {
  const Model model = plates_model({PlacedPlate{Vec3(0, 0, 2), 0.1}, PlacedPlate{Vec3(-0.05, 0.02, 1.8), 0.07}});
  Wind a(model, axis_source(), at_resolution(256));
  Wind b(model, axis_source(), at_resolution(256));
  a.refresh_occlusion(rest_state(model));
  b.refresh_occlusion(rest_state(model));
  EXPECT_EQ(a.item_buffer().ids, b.item_buffer().ids);
  ASSERT_EQ(a.elements().size(), b.elements().size());
  for (std::size_t i = 0; i < a.elements().size(); ++i) {
    EXPECT_EQ(a.elements()[i].area, b.elements()[i].area);
    EXPECT_EQ(a.elements()[i].point_body, b.elements()[i].point_body);
  }
}

}  // namespace
}  // namespace aloft::test
