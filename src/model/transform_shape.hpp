#pragma once
#include "aloft/shapes.hpp"

namespace aloft::internal {

// The shape moved rigidly: every point p becomes rotation * p + translation.
Shape transform_shape(const Shape& shape, const Mat3& rotation, const Vec3& translation);

}  // namespace aloft::internal
