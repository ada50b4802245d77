#include "units/control/diff_drive_controller_unit.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace linesim::control {

DiffDriveControllerUnit::DiffDriveControllerUnit(std::string name)
    : cosim::Unit(kTypeName, std::move(name)),
      velocity_command_(2, 0.0),
      drive_rate_(kSides, 0.0),
      drive_voltage_(kSides, 0.0),
      drive_rate_target_(kSides, 0.0),
      drive_(kSides) {
  auto& v = variables();
  v.Parameter("wheel_radius", "m", &wheel_radius_, "wheel radius",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("effective_track", "m", &effective_track_,
              "track of the yaw kinematics w = (v -+ omega T / 2) / r; for a skid-steer base "
              "larger than the geometric track (wheel scrub)",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("drive_feedforward", "V.s/rad", &drive_.gains.feedforward,
              "voltage per reference wheel rate (back-EMF constant at the wheel, k_e N)",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("drive_acceleration_feedforward", "V.s2/rad", &drive_.gains.acceleration_feedforward,
              "voltage per reference wheel acceleration (joint inertia R / (eta N k_t))",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("drive_kp", "V.s/rad", &drive_.gains.kp, "wheel rate error gain",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("drive_ki", "V/rad", &drive_.gains.ki, "wheel rate error integral gain",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("max_rate", "rad/s", &drive_.gains.max_rate,
              "wheel rate limit; both sides are scaled together to respect it",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("max_acceleration", "rad/s2", &drive_.gains.max_acceleration,
              "wheel rate reference acceleration limit", cosim::Rule::Positive().NoDefault());
  v.Parameter("max_voltage", "V", &max_voltage_, "supply voltage: outputs saturate at +-this",
              cosim::Rule::Positive().NoDefault());

  v.Input("velocity_command", "m/s", &velocity_command_,
          "body velocity command in base_link: vx, vy (vy ignored: the base cannot follow it)");
  v.Input("yaw_rate_command", "rad/s", &yaw_rate_command_, "body yaw rate command");
  v.Input("drive_rate", "rad/s", &drive_rate_,
          "measured drive motor joint rate: left, right (+ rolls forward)");

  v.Output("drive_voltage", "V", &drive_voltage_,
           "drive motor voltage: left, right (+ drives forward)", {"drive_rate"});
  v.Output("drive_rate_target", "rad/s", &drive_rate_target_,
           "slew-limited wheel rate reference at this sample: left, right", {});
}

void DiffDriveControllerUnit::Initialize() {
  ThrowIfBadParameters();
  drive_.Reset();
  period_s_ = 0.0;
  ComputeOutputs();
}

void DiffDriveControllerUnit::ComputeOutputs() {
  for (std::size_t i = 0; i < kSides; ++i) {
    drive_voltage_[i] = ClampSymmetric(drive_.Voltage(i, drive_rate_[i], period_s_), max_voltage_);
    drive_rate_target_[i] = drive_.reference(i);
  }
}

cosim::StepResult DiffDriveControllerUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  const double dt_s = cosim::NsToSeconds(dt);

  // Set points of this sample, both scaled by one factor when too fast.
  const double v = velocity_command_[0];
  const double turn = 0.5 * yaw_rate_command_ * effective_track_;
  double setpoint[kSides] = {(v - turn) / wheel_radius_, (v + turn) / wheel_radius_};
  const double fastest = std::max(std::abs(setpoint[0]), std::abs(setpoint[1]));
  const double max_rate = drive_.gains.max_rate;
  const double scale = fastest > max_rate ? max_rate / fastest : 1.0;
  for (std::size_t i = 0; i < kSides; ++i) {
    drive_.Step(i, scale * setpoint[i], drive_rate_[i], period_s_, dt_s, max_voltage_);
  }
  period_s_ = dt_s;
  ComputeOutputs();
  return cosim::StepResult::kOk;
}

void DiffDriveControllerUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals.clear();
  drive_.AppendState(state.reals);
  state.reals.push_back(period_s_);
  state.integers.clear();
}

void DiffDriveControllerUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t expected = DriveRateLoop::kStatePerChannel * kSides + 1;
  if (state.reals.size() != expected || !state.integers.empty()) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected " + std::to_string(expected) + " and 0");
  }
  period_s_ = *drive_.RestoreState(state.reals.begin());
}

}  // namespace linesim::control
