#pragma once

#include <array>
#include <cmath>

namespace linesim::models {

/// A 3x3 rotation, row-major: element (i, j) at [3 i + j].
using Matrix3 = std::array<double, 9>;

/// The rotation of the quaternion w + x i + y j + z k, for any non-zero
/// norm (the terms are scaled by 2 / |q|^2, so a quaternion off unit
/// length by rounding still gives a rotation); the identity for a zero one.
inline Matrix3 QuaternionMatrix(double w, double x, double y, double z) {
  const double n2 = w * w + x * x + y * y + z * z;
  const double s = n2 > 0.0 ? 2.0 / n2 : 0.0;
  return {1.0 - s * (y * y + z * z), s * (x * y - w * z),       s * (x * z + w * y),
          s * (x * y + w * z),       1.0 - s * (x * x + z * z), s * (y * z - w * x),
          s * (x * z - w * y),       s * (y * z + w * x),       1.0 - s * (x * x + y * y)};
}

/// Rz(yaw) Ry(pitch) Rx(roll): roll about x first, then pitch about y, then
/// yaw about z (the mounts of the robot descriptions).
inline Matrix3 RollPitchYawMatrix(double roll, double pitch, double yaw) {
  const double cr = std::cos(roll), sr = std::sin(roll);
  const double cp = std::cos(pitch), sp = std::sin(pitch);
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  return {cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,
          sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,
          -sp,     cp * sr,                cp * cr};
}

}  // namespace linesim::models
