#pragma once
// The mobile file's "camera" (CameraSpec) applied to a camera: every key it gives replaces the camera's
// own, in the same units and meanings as the --yaw, --pitch, --distance, --fov, --target flags
// (camera_flags.hpp), which are applied after it and so override it key by key.

#include <numbers>
#include <optional>

#include "aloft/render/camera.hpp"
#include "aloft/spec.hpp"

namespace aloft::view {

inline render::OrbitCamera apply_file_camera(const std::optional<CameraSpec>& file, render::OrbitCamera camera) {
  if (!file) return camera;
  constexpr double deg = std::numbers::pi / 180;
  if (file->yaw_deg) camera.yaw = *file->yaw_deg * deg;
  if (file->pitch_deg) camera.pitch = *file->pitch_deg * deg;
  if (file->distance) camera.distance = *file->distance;
  if (file->fov_deg) camera.fov_y = *file->fov_deg * deg;
  if (file->target) camera.target = *file->target;
  return camera;
}

}  // namespace aloft::view
