#include "units/control/wheel_controller_unit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "units/control/wheel_kinematics.h"

namespace linesim::control {

WheelControllerUnit::WheelControllerUnit(std::string name, int wheel_count)
    : cosim::Unit(kTypeName, std::move(name)),
      wheel_count_(wheel_count),
      drive_(static_cast<std::size_t>(std::max(wheel_count, 0))) {
  if (wheel_count < 1) {
    throw cosim::UnitError(Where() + ": wheel_count must be at least 1, got " +
                           std::to_string(wheel_count));
  }
  const auto n = static_cast<std::size_t>(wheel_count);
  wheel_x_.assign(n, kUnset);
  wheel_y_.assign(n, kUnset);
  velocity_command_.assign(2, 0.0);
  surface_velocity_.assign(2 * n, 0.0);
  steer_angle_.assign(n, 0.0);
  steer_rate_.assign(n, 0.0);
  drive_rate_.assign(n, 0.0);
  steer_voltage_.assign(n, 0.0);
  drive_voltage_.assign(n, 0.0);
  steer_target_.assign(n, 0.0);
  drive_rate_target_.assign(n, 0.0);
  for (auto* v : {&steer_ref_, &steer_next_, &steer_prev_rate_, &flip_angle_, &drive_setpoint_}) {
    v->assign(n, 0.0);
  }

  // The gains have no default (robot-specific); the Rob@Work 3's, in
  // models/robots/raw3.yaml, are designed for the 20 ms period (sampled
  // plant with zero-order hold, checked by simulation over the inertia
  // ranges below, with its maxon RE 40 stand-in motors; retune them for
  // another plant):
  //  - drive: back-EMF damping at the wheel eta N^2 k_t k_e / R = 1.01
  //    N.m.s, so the loaded wheel (0.197 kg.m^2) has a 0.195 s time
  //    constant, but a wheel off the ground (about 0.01 kg.m^2) has 10 ms,
  //    shorter than the period. There the rate loop's sampled pole is about
  //    -kp / (k_e N), so kp must stay well under 0.63 V.s/rad: kp 0.5 keeps
  //    it at -0.5 airborne and 0.83 loaded; ki 5 V/rad adds an integrator
  //    pole near 0.9 per sample (loaded) for load torques.
  //  - steering: PD with kp 10 V/rad, kd 0.5 V.s/rad is well damped for a
  //    joint inertia from 0.002 to 0.01 kg.m^2 (back-EMF damping 0.044
  //    N.m.s at the joint); kd above about 0.7 goes unstable at 0.002.
  auto& v = variables();
  v.Parameter("wheel_x", "m", &wheel_x_, "steering axis x in base_link, per wheel",
              cosim::Rule::Required());
  v.Parameter("wheel_y", "m", &wheel_y_, "steering axis y in base_link, per wheel",
              cosim::Rule::Required());
  v.Parameter("wheel_radius", "m", &wheel_radius_, "wheel radius",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("compensation", &compensation_,
              "subtract the surface velocity under each wheel from its command (paper 1 "
              "Algorithm 1); false = the nominal controller");
  v.Parameter("steer_speed_threshold", "m/s", &steer_speed_threshold_,
              "below this contact speed a wheel keeps its heading and rolls the command's "
              "component along it",
              cosim::Rule::NonNegative());
  v.Parameter("steer_kp", "V/rad", &steer_kp_, "steering angle gain",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("steer_kd", "V.s/rad", &steer_kd_, "steering rate error gain",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("steer_feedforward", "V.s/rad", &steer_feedforward_,
              "voltage per reference steering rate (back-EMF constant at the joint, k_e N)",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("steer_acceleration_feedforward", "V.s2/rad", &steer_acceleration_feedforward_,
              "voltage per reference steering acceleration (joint inertia R / (eta N k_t))",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("steer_max_rate", "rad/s", &steer_max_rate_, "steering reference rate limit",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("steer_max_acceleration", "rad/s2", &steer_max_acceleration_,
              "steering reference acceleration limit", cosim::Rule::Positive().NoDefault());
  v.Parameter("drive_feedforward", "V.s/rad", &drive_.gains.feedforward,
              "voltage per reference wheel rate (back-EMF constant at the wheel, k_e N)",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("drive_acceleration_feedforward", "V.s2/rad", &drive_.gains.acceleration_feedforward,
              "voltage per reference wheel acceleration (load inertia R / (eta N k_t))",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("drive_kp", "V.s/rad", &drive_.gains.kp, "wheel rate error gain",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("drive_ki", "V/rad", &drive_.gains.ki, "wheel rate error integral gain",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("drive_max_rate", "rad/s", &drive_.gains.max_rate,
              "wheel rate limit; all wheels are scaled together to respect it",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("drive_max_acceleration", "rad/s2", &drive_.gains.max_acceleration,
              "wheel rate reference acceleration limit", cosim::Rule::Positive().NoDefault());
  v.Parameter("max_voltage", "V", &max_voltage_, "supply voltage: outputs saturate at +-this",
              cosim::Rule::Positive().NoDefault());

  v.Input("velocity_command", "m/s", &velocity_command_,
          "body velocity command of base_link in base_link: vx, vy");
  v.Input("yaw_rate_command", "rad/s", &yaw_rate_command_, "body yaw rate command");
  v.Input("surface_velocity", "m/s", &surface_velocity_,
          "absolute velocity of the floor under each wheel in base_link, interleaved "
          "(vx0, vy0, vx1, vy1, ...)");
  v.Input("steer_angle", "rad", &steer_angle_,
          "measured steering angle per wheel (0 = rolling along +x, + counter-clockwise)");
  v.Input("steer_rate", "rad/s", &steer_rate_, "measured steering rate per wheel");
  v.Input("drive_rate", "rad/s", &drive_rate_,
          "measured wheel rate per wheel (+ rolls forward along the heading)");

  v.Output("steer_voltage", "V", &steer_voltage_,
           "steering motor voltage per wheel (+ turns counter-clockwise seen from above)",
           {"steer_angle", "steer_rate"});
  v.Output("drive_voltage", "V", &drive_voltage_,
           "drive motor voltage per wheel (+ drives forward)", {"drive_rate"});
  v.Output("steer_target", "rad", &steer_target_,
           "slew-limited steering reference at this sample, in (-pi, pi]", {});
  v.Output("drive_rate_target", "rad/s", &drive_rate_target_,
           "slew-limited wheel rate reference at this sample", {});
}

std::vector<cosim::ParameterProblem> WheelControllerUnit::CheckParameters() const {
  // The rules of single parameters are declared with them; here only what
  // relates several: wheel_x and wheel_y put no two wheels at one point.
  auto problems = cosim::Unit::CheckParameters();
  // Two steering axes at one point are no robot: wheels all at the centre
  // would quietly turn a yaw command into no wheel motion.
  const std::size_t n = wheel_x_.size();
  std::vector<bool> reported(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<std::size_t> same = {i};
    for (std::size_t j = i + 1; j < n; ++j) {
      if (!reported[j] && wheel_x_[j] == wheel_x_[i] && wheel_y_[j] == wheel_y_[i]) {
        same.push_back(j);
        reported[j] = true;
      }
    }
    if (same.size() < 2) continue;
    std::string wheels = std::to_string(same[0]);
    for (std::size_t k = 1; k < same.size(); ++k) {
      wheels += (k + 1 == same.size() ? " and " : ", ") + std::to_string(same[k]);
    }
    problems.push_back({"wheel_x", std::nullopt,
                        "with wheel_y puts wheels " + wheels +
                            " at the same point (set the positions of all " + std::to_string(n) +
                            " wheels)"});
  }
  return problems;
}

void WheelControllerUnit::Initialize() {
  ThrowIfBadParameters();
  // Start from where the wheels point, at rest, so nothing jumps at t = 0.
  for (std::size_t i = 0; i < steer_ref_.size(); ++i) {
    const double a = WrapAngle(steer_angle_[i]);
    steer_ref_[i] = steer_next_[i] = flip_angle_[i] = a;
    steer_prev_rate_[i] = 0.0;
  }
  drive_.Reset();
  period_s_ = 0.0;
  ComputeOutputs();
}

double WheelControllerUnit::SteerRateReference(std::size_t i) const {
  return period_s_ > 0.0 ? WrapAngle(steer_next_[i] - steer_ref_[i]) / period_s_ : 0.0;
}

double WheelControllerUnit::SteerVoltage(std::size_t i) const {
  const double steer_rate_ref = SteerRateReference(i);
  const double steer_accel_ref =
      period_s_ > 0.0 ? (steer_rate_ref - steer_prev_rate_[i]) / period_s_ : 0.0;
  return steer_kp_ * WrapAngle(steer_ref_[i] - steer_angle_[i]) +
         steer_kd_ * (steer_rate_ref - steer_rate_[i]) + steer_feedforward_ * steer_rate_ref +
         steer_acceleration_feedforward_ * steer_accel_ref;
}

void WheelControllerUnit::ComputeOutputs() {
  for (std::size_t i = 0; i < steer_voltage_.size(); ++i) {
    steer_voltage_[i] = ClampSymmetric(SteerVoltage(i), max_voltage_);
    drive_voltage_[i] = ClampSymmetric(drive_.Voltage(i, drive_rate_[i], period_s_), max_voltage_);
    steer_target_[i] = steer_ref_[i];
    drive_rate_target_[i] = drive_.reference(i);
  }
}

cosim::StepResult WheelControllerUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  const double dt_s = cosim::NsToSeconds(dt);
  const std::size_t n = steer_ref_.size();

  // Set points of this sample: Eq. 1, Algorithm 1, flip rule (from the
  // last flip-rule heading, which the set point then replaces).
  const Eigen::Vector3d twist(velocity_command_[0], velocity_command_[1], yaw_rate_command_);
  double fastest_rad_s = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector2d v = WheelVelocity(twist, {wheel_x_[i], wheel_y_[i]});
    if (compensation_) {
      v = CompensateSurface(v, {surface_velocity_[2 * i], surface_velocity_[2 * i + 1]});
    }
    const WheelSetpoint setpoint =
        ToWheelSetpoint(v, wheel_radius_, steer_angle_[i], flip_angle_[i], steer_speed_threshold_);
    flip_angle_[i] = setpoint.steer_angle_rad;
    drive_setpoint_[i] = setpoint.drive_rate_rad_s;
    fastest_rad_s = std::max(fastest_rad_s, std::abs(setpoint.drive_rate_rad_s));
  }
  // Scale all wheels alike, so that a too fast command keeps its direction
  // and curvature instead of being distorted wheel by wheel.
  const double max_rate = drive_.gains.max_rate;
  const double scale = fastest_rad_s > max_rate ? max_rate / fastest_rad_s : 1.0;

  for (std::size_t i = 0; i < n; ++i) {
    // Steering reference: second-order slew towards the flip-rule heading,
    // at the largest rate from which the acceleration limit still stops the
    // discrete profile exactly at the target: rates (m + f) dv, (m - 1 + f)
    // dv, ..., f dv cover dv dt ((m + 1) f + m (m + 1) / 2).
    const double rate_now = SteerRateReference(i);
    steer_prev_rate_[i] = rate_now;
    steer_ref_[i] = steer_next_[i];
    const double gap = WrapAngle(flip_angle_[i] - steer_ref_[i]);
    const double dv = steer_max_acceleration_ * dt_s;
    const double steps = std::abs(gap) / (dv * dt_s);
    const double m = std::floor(0.5 * (std::sqrt(1.0 + 8.0 * steps) - 1.0));
    const double f = std::clamp((steps - 0.5 * m * (m + 1.0)) / (m + 1.0), 0.0, 1.0);
    const double stoppable = (m + f) * dv;
    const double wanted =
        std::copysign(std::min({steer_max_rate_, stoppable, std::abs(gap) / dt_s}), gap);
    const double rate_next = rate_now + ClampSymmetric(wanted - rate_now, dv);
    steer_next_[i] = WrapAngle(steer_ref_[i] + rate_next * dt_s);

    // Drive: integrator on the error of this sample, reference ramped
    // towards the scaled set point.
    drive_.Step(i, scale * drive_setpoint_[i], drive_rate_[i], period_s_, dt_s, max_voltage_);
  }
  period_s_ = dt_s;
  ComputeOutputs();
  return cosim::StepResult::kOk;
}

void WheelControllerUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals.clear();
  for (const auto* v : {&steer_ref_, &steer_next_, &steer_prev_rate_, &flip_angle_}) {
    state.reals.insert(state.reals.end(), v->begin(), v->end());
  }
  drive_.AppendState(state.reals);
  state.reals.push_back(period_s_);
  state.integers.clear();
}

void WheelControllerUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t n = steer_ref_.size();
  const std::size_t expected = (4 + DriveRateLoop::kStatePerChannel) * n + 1;
  if (state.reals.size() != expected || !state.integers.empty()) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected " + std::to_string(expected) + " and 0");
  }
  auto it = state.reals.begin();
  for (auto* v : {&steer_ref_, &steer_next_, &steer_prev_rate_, &flip_angle_}) {
    std::copy(it, it + static_cast<std::ptrdiff_t>(n), v->begin());
    it += static_cast<std::ptrdiff_t>(n);
  }
  period_s_ = *drive_.RestoreState(it);
}

}  // namespace linesim::control
