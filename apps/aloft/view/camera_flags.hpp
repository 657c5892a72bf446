#pragma once
// Camera flags shared by `aloft render` and `aloft view`: every one optional; what is not given comes
// from the mobile file's "camera" (file_camera.hpp), and what that does not give from the framing camera
// (the whole mobile in view, a little from the right and above).

#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include <CLI/CLI.hpp>

#include "aloft/render/camera.hpp"
#include "../common.hpp"
#include "file_camera.hpp"

namespace aloft::cli {

struct CameraFlags {
  std::optional<double> yaw_deg;       // about +y; 0 faces the wall
  std::optional<double> pitch_deg;     // above the horizontal
  std::optional<double> distance;      // m from the target
  std::optional<double> fov_deg;       // vertical field of view
  std::vector<double> target;          // x y z (m), empty: the middle of the mobile

  void add_to(CLI::App* sub) {
    sub->add_option("--yaw", yaw_deg, "Camera turn about the vertical (degrees; 0 faces the wall)")
        ->type_name("DEG")
        ->check(cli::finite_number())
        ->group("Camera");
    sub->add_option("--pitch", pitch_deg, "Camera height angle above the horizontal (degrees, -85..85)")
        ->type_name("DEG")
        ->check(cli::number_in(-85.0, 85.0))
        ->group("Camera");
    sub->add_option("--distance", distance,
                    cli::format("Camera distance from its target (m, > 0, up to %g)", kLongestLength))
        ->type_name("M")
        ->check(cli::length_in_metres())
        ->group("Camera");
    sub->add_option("--fov", fov_deg, "Vertical field of view (degrees, 5..120)")
        ->type_name("DEG")
        ->check(cli::number_in(5.0, 120.0))
        ->group("Camera");
    sub->add_option("--target", target,
                    cli::format("Point the camera looks at: X Y Z or X,Y,Z (m, world, each -%g to %g)", kLongestLength,
                                kLongestLength))
        ->type_name("X Y Z")
        ->expected(3)
        ->delimiter(',')
        ->check(cli::number_in(-kLongestLength, kLongestLength))
        ->group("Camera");
  }

  // `framed` with the file's camera, then the given flags, applied.
  render::OrbitCamera apply(const std::optional<CameraSpec>& file, render::OrbitCamera framed) const {
    return apply(view::apply_file_camera(file, framed));
  }

  // `framed` with the given flags applied.
  render::OrbitCamera apply(render::OrbitCamera framed) const {
    constexpr double deg = std::numbers::pi / 180;
    if (yaw_deg) framed.yaw = *yaw_deg * deg;
    if (pitch_deg) framed.pitch = *pitch_deg * deg;
    if (distance) framed.distance = *distance;
    if (fov_deg) framed.fov_y = *fov_deg * deg;
    if (target.size() == 3) framed.target = Vec3(target[0], target[1], target[2]);
    return framed;
  }
};

}  // namespace aloft::cli
