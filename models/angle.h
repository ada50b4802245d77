#pragma once

#include <cmath>
#include <numbers>

namespace linesim::models {

/// Degrees (as files write angles) to radians.
inline constexpr double kDegToRad = std::numbers::pi / 180.0;

/// An angle wrapped to (-pi, pi]: remainder() gives [-pi, pi], and -pi is
/// moved to +pi so that every heading has one value.
inline double WrapAngle(double angle_rad) {
  constexpr double kPi = std::numbers::pi;
  const double a = std::remainder(angle_rad, 2.0 * kPi);
  return a <= -kPi ? a + 2.0 * kPi : a;
}

}  // namespace linesim::models
