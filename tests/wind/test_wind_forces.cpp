// Eq. 4 on single plates: continuity (v1 = v0 (l0/l1)^2, so F ~ 1/l1^4), the cos^2 law, alpha from the
// density of air, the torque of an off-centre force.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "aloft/geometry.hpp"
#include "support/presets.hpp"
#include "wind/wind_scenes.hpp"

namespace aloft::test {
namespace {

// Raster error: a 0.1 m plate at 2 m covers 256 x 256 pixels at resolution 512; pixel-centre sampling
// misplaces at most half a pixel along each edge, 4 * 256 * 0.5 / 256^2 = 0.8 % of the area in the worst
// case. 1 % covers that (and the 1e-5 m plate edges, 0.01 % of the area).
constexpr double kRasterTolerance = 0.01;

WindSettings fine() {
  WindSettings s;
  s.resolution = 512;
  s.beta = 0;
  return s;
}

TEST(WindForces, FaceOnPlateMatchesDensityOfAirAndContinuity) {
  const PlacedPlate plate{Vec3(0, 0, 2), 0.1};
  const Model model = plates_model({plate});
  const WindSource source = axis_source();
  const double v0 = 3;
  const Vec3 f = wind_forces(model, source, fine(), v0, rest_state(model))[1];
  // Eq. 3 with the speed of eq. 2: rho A v1^2, v1 = v0 (l0 / l1)^2 = 0.75 m/s at l1 = 2 m.
  const double v1 = v0 * std::pow(source.l0 / 2.0, 2);
  const double expected = kAirDensity * 0.01 * v1 * v1;
  EXPECT_NEAR(f.z(), expected, kRasterTolerance * expected);
  // The plate's face is perpendicular to z and centred on the axis: the force has no sideways part (by
  // symmetry, up to the raster's asymmetry: 1e-3 of the force).
  EXPECT_LT(std::hypot(f.x(), f.y()), 1e-3 * f.z());
  // Quadrature of eq. 4 over the face (finite size: l1 varies by 0.1 % across it).
  const Vec3 exact = exact_plate_force(plate, source, kAirDensity * std::pow(source.l0, 4), v0);
  EXPECT_NEAR(f.z(), exact.z(), kRasterTolerance * exact.z());
}

TEST(WindForces, ForceFallsAsTheFourthPowerOfDistance) {
  // The same plate at l1 = 2 m and l1 = 3 m, scaled with distance so it fills the same pixels: the
  // area grows as l1^2, the force per area falls as l1^-4, the total as l1^-2.
  const WindSource source = axis_source();
  const PlacedPlate near{Vec3(0, 0, 2), 0.1};
  const PlacedPlate far{Vec3(0, 0, 3), 0.15};
  const Model m_near = plates_model({near});
  const Model m_far = plates_model({far});
  const double f_near = wind_forces(m_near, source, fine(), 2, rest_state(m_near))[1].z();
  const double f_far = wind_forces(m_far, source, fine(), 2, rest_state(m_far))[1].z();
  const double area_ratio = std::pow(0.15 / 0.1, 2);
  // Same pixels, so the raster error cancels in the ratio but for the 1/l1^4 weighting across the plate
  // (identical in angle): 1e-3.
  EXPECT_NEAR(f_far / f_near, area_ratio * std::pow(2.0 / 3.0, 4), 1e-3 * area_ratio * std::pow(2.0 / 3.0, 4));
  // And F ~ v0^2.
  const double f_double = wind_forces(m_near, source, fine(), 4, rest_state(m_near))[1].z();
  EXPECT_NEAR(f_double / f_near, 4.0, 1e-12);  // the same elements: only the factor v0^2 changes
}

TEST(WindForces, TiltedPlateFollowsTheCosineSquaredLaw) {
  const WindSource source = axis_source();
  const double alpha = kAirDensity * std::pow(source.l0, 4);
  double face_on = 0;
  for (double degrees : {0.0, 30.0, 45.0, 60.0, 75.0}) {
    const double theta = degrees * std::numbers::pi / 180;
    // Turned about y: the normal is (sin, 0, cos), at angle theta to the wind.
    const PlacedPlate plate{Vec3(0, 0, 2), 0.1, Vec3(std::cos(theta), 0, -std::sin(theta)), Vec3::UnitY()};
    const Model model = plates_model({plate});
    const Vec3 f = wind_forces(model, source, fine(), 2, rest_state(model))[1];
    const Vec3 normal = plate.u.cross(plate.v);
    // The force is along the normal (eq. 4), pushing with the wind.
    EXPECT_LT((f - f.dot(normal) * normal).norm(), 1e-9 * f.norm()) << degrees;
    EXPECT_GT(f.z(), 0) << degrees;
    // Against the quadrature of eq. 4 (the plate's image is 256 cos(theta) pixels wide: the half-pixel
    // edge error grows as 1/cos, 2 % at 75 deg).
    const Vec3 exact = exact_plate_force(plate, source, alpha, 2);
    EXPECT_NEAR(f.norm(), exact.norm(), kRasterTolerance / std::cos(theta) * 0.5 * exact.norm() + 1e-12) << degrees;
    // The component along the wind follows cos^2 (the quadrature's finite-size effects are 0.3 %).
    if (degrees == 0) face_on = f.z();
    const double law = std::pow(std::cos(theta), 2);
    EXPECT_NEAR(f.z() / face_on, law, (kRasterTolerance / std::cos(theta) * 0.5 + 0.003) * law) << degrees;
  }
}

TEST(WindForces, OffCentreForceTurnsTheComponent) {
  // A plate whose centre of mass is 0.2 m to the right of the face (an arm): the wind's force acts at the
  // face, so the torque about the centre of mass is r x F with r = (-0.2, 0, 0).
  Model model = plates_model({PlacedPlate{Vec3(0.2, 0, 2), 0.1}});
  std::get<Plate>(model.shapes[1][0].shape).origin = Vec3(-0.2, 0, 0);
  const WindSource source = axis_source();
  WindSettings settings = fine();
  settings.beta = 0;
  Wind wind(model, source, settings);
  const State state = rest_state(model);
  wind.refresh_occlusion(state);
  ExternalLoads loads;
  loads.resize(model.count);
  wind.apply(state, 2, 0.001, loads);
  const Vec3 f = loads.force[1];
  const Vec3 expected_torque = Vec3(-0.2, 0, 0).cross(f);
  // The centre of pressure is the plate's centre up to the raster's asymmetry (1e-3 of the arm).
  EXPECT_NEAR(loads.torque[1].y(), expected_torque.y(), 1e-3 * std::abs(expected_torque.y()));
  EXPECT_GT(loads.torque[1].y(), 0);  // pushed along +z at x = -0.2 from the centre: turns about +y
  EXPECT_EQ(loads.force[0], Vec3::Zero());  // the fixed component gets nothing
}

TEST(WindForces, ElementsFollowTheirComponentBetweenRefreshes) {
  // Move the plate 0.5 m further after the refresh: apply() uses the new distance (l1 = 2.5 m).
  const Model model = plates_model({PlacedPlate{Vec3(0, 0, 2), 0.1}});
  WindSettings settings = fine();
  Wind wind(model, axis_source(), settings);
  State state = rest_state(model);
  wind.refresh_occlusion(state);
  ExternalLoads loads;
  loads.resize(model.count);
  wind.apply(state, 2, 0.001, loads);
  const double at_two = loads.force[1].z();
  state.position[1].z() = 2.5;
  loads.clear();
  wind.apply(state, 2, 0.001, loads);
  // Same elements and areas, l1 from 2 to 2.5 m: about (2/2.5)^4, exactly the ratio of eq. 4 integrated
  // over the plate at both places (the spread of l1 over the plate changes with distance: 4e-4). The tiles'
  // centroids stand for their pixels: 1e-4.
  const WindSource source = axis_source();
  const double alpha = kAirDensity;
  const double expected = exact_plate_force(PlacedPlate{Vec3(0, 0, 2.5), 0.1}, source, alpha, 2).z() /
                          exact_plate_force(PlacedPlate{Vec3(0, 0, 2), 0.1}, source, alpha, 2).z();
  EXPECT_NEAR(loads.force[1].z() / at_two, expected, 1e-4);
}

// A round surface turns nothing about its axis: the pressure on a wire's side acts along its normals,
// which all meet the wire's axis, and on a sphere along radii, which meet at its centre. The item buffer
// samples the faceted mesh (12 sides) at points spread over each facet, and a pixel's force acting off
// the facet's midline would turn the wire about its axis, where its moment of inertia is smallest
// (docs/wind.md, "Round shapes"). Before the fix: 5.1e-8 N m about the wire's axis and 1.7e-6 N m on the
// ball at 64 pixels.
TEST(WindForces, RoundShapesAreNotTurnedAboutTheirAxisOrCentre) {
  Model model = empty_model(3);
  model.rest_position[0] = Vec3(0, 100, 0);
  // A wire 0.2 m long and 1 mm in radius across the wind, turned 7 degrees about its axis so that no facet
  // faces the wind square; and a ball 2 cm in radius beside it.
  const Vec3 axis = Vec3(1, 0.3, 0).normalized();
  for (int c = 1; c <= 2; ++c) {
    model.parent[c] = 0;
    model.rest_position[c] = c == 1 ? Vec3(0, 0, 2) : Vec3(0.15, 0.05, 2.1);
    model.joint_world[c] = model.rest_position[c];
  }
  model.shapes[1].push_back(BodyShape{Wire{-0.1 * axis, 0.1 * axis, 0.001}, Color{}});
  model.shapes[2].push_back(BodyShape{Sphere{Vec3::Zero(), 0.02}, Color{}});
  model.rest_orientation[1] = Quat(Eigen::AngleAxisd(7 * std::numbers::pi / 180, axis));
  finish_model(model);
  for (int resolution : {64, 256, 1024}) {  // pixels coarser than the wire (3 mm), and finer (0.2 mm)
    WindSettings settings;
    settings.resolution = resolution;
    settings.beta = 0;
    Wind wind(model, axis_source(0.3), settings);
    const State state = rest_state(model);
    wind.refresh_occlusion(state);
    ExternalLoads loads;
    loads.resize(model.count);
    wind.apply(state, 3, 0.001, loads);
    ASSERT_GT(loads.force[1].z(), 0) << resolution;  // the wind does reach both
    ASSERT_GT(loads.force[2].z(), 0) << resolution;
    const Vec3 world_axis = state.orientation[1] * axis;  // the wire is along `axis` in its body frame
    // Round-off only: each element's force meets the axis (centre) exactly, so what is left is the
    // rounding of r x F, 1e-12 of the force times the wire's radius (ball: its radius).
    EXPECT_LE(std::abs(loads.torque[1].dot(world_axis)), 1e-12 * loads.force[1].norm() * 0.001) << resolution;
    EXPECT_LE(loads.torque[2].norm(), 1e-12 * loads.force[2].norm() * 0.02) << resolution;
  }
}

TEST(WindSource, AimedPutsS0AtFromAndValidates) {
  const WindSource s = WindSource::aimed(Vec3(0, 1, 3), Vec3(0, 1, 0), 0.2, 0.5);
  EXPECT_NEAR((s.disc_center() - Vec3(0, 1, 3)).norm(), 0, 1e-15);  // exact up to rounding
  EXPECT_NEAR((s.direction - Vec3(0, 0, -1)).norm(), 0, 1e-15);
  EXPECT_THROW(WindSource::aimed(Vec3::Zero(), Vec3::Zero(), 0.2, 0.5), std::invalid_argument);
  EXPECT_THROW(WindSource::aimed(Vec3::Zero(), Vec3::UnitZ(), -1, 0.5), std::invalid_argument);
  WindSettings bad;
  bad.resolution = 2;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

// The sources sized to the mobile: the Steel Fish's every shape corner lies in mobile_sphere, and the
// cone of source_in_front (source_facing_mobile's, from the front) and of source_covering (off to one
// side) holds that whole sphere.
TEST(WindSource, SourcesFacingTheMobileCoverItsWholeSphere) {
  const Model model = load_mobile(preset_path("steel-fish"));
  const State state = rest_state(model);
  const MobileSphere cover = mobile_sphere(model, state);
  for (int c = 0; c < model.count; ++c)
    for (const BodyShape& shape : model.shapes[c]) {
      const Bounds b = shape_bounds(shape.shape);
      for (const Vec3& corner : {b.min, b.max})  // two opposite corners of each box
        EXPECT_LE((state.position[c] + state.orientation[c] * corner - cover.center).norm(),
                  cover.radius * (1 + 1e-12));  // relative round-off of a metre-sized sum
    }
  const auto holds_sphere = [&](const WindSource& s) {
    // The sphere's angular radius seen from the vertex, plus its centre's angle off the axis, within the
    // cone's half angle (1e-12 rad: the round-off of the trigonometry).
    const Vec3 to_center = cover.center - s.vertex;
    const double off_axis = std::acos(std::clamp(to_center.normalized().dot(s.direction), -1.0, 1.0));
    return off_axis + std::asin(cover.radius / to_center.norm()) <= s.half_angle() + 1e-12;
  };
  const WindSource facing = source_in_front(model, state);
  EXPECT_TRUE(holds_sphere(facing));
  EXPECT_NEAR((facing.disc_center() - (cover.center + Vec3(0, 0, kFrontSourceDistance))).norm(), 0, 1e-12);
  // Aimed at the centre from elsewhere: S0 where asked, the cone still holding the sphere, and no wider
  // than it needs (the sphere touches the cone: 1e-9 of its half angle).
  const Vec3 from = cover.center + Vec3(1, 0.5, 2);
  const WindSource aimed = source_covering(from, cover.center, 0.8, cover);
  EXPECT_NEAR((aimed.disc_center() - from).norm(), 0, 1e-12);
  EXPECT_TRUE(holds_sphere(aimed));
  EXPECT_NEAR(std::asin(cover.radius / (cover.center - aimed.vertex).norm()), aimed.half_angle(), 1e-9);
}

// Steps between occlusion refreshes: 1 / (rate h) rounded, at least one step, and at most INT_MAX for a
// rate too low to refresh again in any run (1e-300 Hz: the cast of 1e303 to int gave 1, every step).
TEST(WindSource, OcclusionRefreshStepsRoundAndSaturate) {
  EXPECT_EQ(occlusion_refresh_steps(kOcclusionRefreshRate, 0.001), 17);  // 16.67 rounded
  EXPECT_EQ(occlusion_refresh_steps(100, 0.001), 10);
  EXPECT_EQ(occlusion_refresh_steps(1e6, 0.001), 1);  // faster than the steps: every step
  EXPECT_EQ(occlusion_refresh_steps(1e-300, 0.001), std::numeric_limits<int>::max());
  EXPECT_EQ(occlusion_refresh_steps(1e-6, 0.001), 1000000000);
}

}  // namespace
}  // namespace aloft::test
