#pragma once

#include <Eigen/Dense>

#include "models/angle.h"

namespace linesim::control {

/// An angle wrapped to (-pi, pi] (the one definition the units share).
using models::WrapAngle;

/// Paper 1, Eq. 1: the velocity of the contact of a wheel whose steering axis
/// is at `position_m` (base_link) when the body moves with `twist`
/// (vx m/s, vy m/s, yaw rate rad/s, base_link):
///   v_x = xdot - phidot * y,  v_y = ydot + phidot * x.
Eigen::Vector2d WheelVelocity(const Eigen::Vector3d& twist, const Eigen::Vector2d& position_m);

/// Paper 1, Algorithm 1: the wheel must move relative to the floor it stands
/// on, so the absolute surface velocity under it (base_link, m/s) is
/// subtracted from the commanded wheel velocity.
inline Eigen::Vector2d CompensateSurface(const Eigen::Vector2d& wheel_velocity_mps,
                                         const Eigen::Vector2d& surface_velocity_mps) {
  return wheel_velocity_mps - surface_velocity_mps;
}

/// A steered wheel's set point: heading of the wheel in base_link and the
/// rolling rate (+ rolls forward along the heading).
struct WheelSetpoint {
  double steer_angle_rad = 0.0;
  double drive_rate_rad_s = 0.0;
};

/// The wheel set point for a contact velocity (the flip rule of IPA's
/// cob_control, docs/references.md). Two candidates reach the same
/// velocity: heading atan2(v_y, v_x) rolling forward at |v| / R, or that
/// heading + pi rolling backward. The one minimising
///   0.6 |wrap(a - angle_now)| + 0.4 |wrap(a - last_target)|
/// wins (ties go to rolling forward), so a wheel at its last target never
/// turns more than 90 deg: it reverses instead; the second term keeps a
/// lagging wheel from flip-flopping near 90 deg. Below `steer_speed_mps` the
/// command's direction is noise, not intent: the wheel keeps `last_target`
/// and rolls the command's component along it (IPA keeps the heading for an
/// exactly zero command only; then the component is zero too). Re-aiming on
/// noise would swing a wheel by up to 90 deg at full steering rate, and a
/// wheel left across the line when it starts pushes the robot sideways.
/// The price: a position loop of gain k (velocity k e) leaves an error
/// across the wheels' heading until k e reaches the threshold (1 cm at the
/// path follower's k_position 1/s and the controller's 1 cm/s).
WheelSetpoint ToWheelSetpoint(const Eigen::Vector2d& velocity_mps, double radius_m,
                              double angle_now_rad, double last_target_rad, double steer_speed_mps);

}  // namespace linesim::control
