#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

/// Moving solids as units exchange them through connections, one array of
/// numbers per solid (a unit that takes N of them has an input of N times
/// the count, one solid after another). The values hold at the
/// communication point; a user moves the solid on with its velocity within
/// its own step (a laser at each beam's time, a chassis at each substep).
namespace linesim::models {

/// A robot's body (ChassisUnit's `body_box`): a box yawed about the
/// vertical, [x, y, yaw, vx, vy, yaw_rate, length, width, z_bottom, z_top]
/// in map (m, rad, m/s, rad/s); length 0: no box (absent).
struct MovingBox {
  enum Index : std::size_t { kX, kY, kYaw, kVx, kVy, kYawRate, kLength, kWidth, kZBottom, kZTop };
  static constexpr std::size_t kValues = 10;
};

/// A vertical cylinder (a worker's leg or torso, people::WorkerUnit's
/// `cylinders`): [x, y, vx, vy, radius, z_bottom, z_top] in map.
struct MovingCylinder {
  enum Index : std::size_t { kX, kY, kVx, kVy, kRadius, kZBottom, kZTop };
  static constexpr std::size_t kValues = 7;
};

/// Distance of map point (x, y) from the footprint of a MovingBox (0
/// inside it).
inline double FootprintDistance(const double* box, double x, double y) {
  const double c = std::cos(box[MovingBox::kYaw]), s = std::sin(box[MovingBox::kYaw]);
  const double dx = x - box[MovingBox::kX], dy = y - box[MovingBox::kY];
  const double ex = std::abs(c * dx + s * dy) - 0.5 * box[MovingBox::kLength];
  const double ey = std::abs(-s * dx + c * dy) - 0.5 * box[MovingBox::kWidth];
  return std::hypot(std::max(ex, 0.0), std::max(ey, 0.0));
}

}  // namespace linesim::models
