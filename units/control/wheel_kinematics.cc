#include "units/control/wheel_kinematics.h"

#include <cmath>
#include <numbers>

namespace linesim::control {

Eigen::Vector2d WheelVelocity(const Eigen::Vector3d& twist, const Eigen::Vector2d& position_m) {
  return {twist[0] - twist[2] * position_m[1], twist[1] + twist[2] * position_m[0]};
}

WheelSetpoint ToWheelSetpoint(const Eigen::Vector2d& velocity_mps, double radius_m,
                              double angle_now_rad, double last_target_rad,
                              double steer_speed_mps) {
  const double speed_mps = velocity_mps.norm();
  if (!(speed_mps >= steer_speed_mps) || speed_mps == 0.0) {
    const double heading = WrapAngle(last_target_rad);
    const double along_mps =
        velocity_mps[0] * std::cos(heading) + velocity_mps[1] * std::sin(heading);
    return {heading, along_mps / radius_m};
  }
  const double forward = std::atan2(velocity_mps[1], velocity_mps[0]);
  const double backward = WrapAngle(forward + std::numbers::pi);
  const auto cost = [&](double a) {
    return 0.6 * std::abs(WrapAngle(a - angle_now_rad)) +
           0.4 * std::abs(WrapAngle(a - last_target_rad));
  };
  const double rate = speed_mps / radius_m;
  if (cost(backward) < cost(forward)) return {backward, -rate};
  return {WrapAngle(forward), rate};
}

}  // namespace linesim::control
