#include "units/control/diff_drive_controller_unit.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace linesim::control {

namespace {

double SignedMin(double x, double limit) { return std::clamp(x, -limit, limit); }

}  // namespace

DiffDriveControllerUnit::DiffDriveControllerUnit(std::string name)
    : cosim::Unit(kTypeName, std::move(name)),
      velocity_command_(2, 0.0),
      drive_rate_(kSides, 0.0),
      drive_voltage_(kSides, 0.0),
      drive_rate_target_(kSides, 0.0),
      ref_(kSides, 0.0),
      next_(kSides, 0.0),
      integral_(kSides, 0.0) {
  auto& v = variables();
  v.Parameter("wheel_radius", "m", &wheel_radius_, "wheel radius",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("effective_track", "m", &effective_track_,
              "track of the yaw kinematics w = (v -+ omega T / 2) / r; for a skid-steer base "
              "larger than the geometric track (wheel scrub)",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("drive_feedforward", "V.s/rad", &drive_feedforward_,
              "voltage per reference wheel rate (back-EMF constant at the wheel, k_e N)",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("drive_acceleration_feedforward", "V.s2/rad", &drive_acceleration_feedforward_,
              "voltage per reference wheel acceleration (joint inertia R / (eta N k_t))",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("drive_kp", "V.s/rad", &drive_kp_, "wheel rate error gain",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("drive_ki", "V/rad", &drive_ki_, "wheel rate error integral gain",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("max_rate", "rad/s", &max_rate_,
              "wheel rate limit; both sides are scaled together to respect it",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("max_acceleration", "rad/s2", &max_acceleration_,
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
  std::fill(ref_.begin(), ref_.end(), 0.0);
  std::fill(next_.begin(), next_.end(), 0.0);
  std::fill(integral_.begin(), integral_.end(), 0.0);
  period_s_ = 0.0;
  ComputeOutputs();
}

double DiffDriveControllerUnit::Voltage(std::size_t i) const {
  const double accel_ref = period_s_ > 0.0 ? (next_[i] - ref_[i]) / period_s_ : 0.0;
  // The back-EMF grows over the period with the reference: feed the mean.
  return drive_feedforward_ * 0.5 * (ref_[i] + next_[i]) +
         drive_acceleration_feedforward_ * accel_ref + drive_kp_ * (ref_[i] - drive_rate_[i]) +
         drive_ki_ * integral_[i];
}

void DiffDriveControllerUnit::ComputeOutputs() {
  for (std::size_t i = 0; i < kSides; ++i) {
    drive_voltage_[i] = SignedMin(Voltage(i), max_voltage_);
    drive_rate_target_[i] = ref_[i];
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
  const double scale = fastest > max_rate_ ? max_rate_ / fastest : 1.0;

  for (std::size_t i = 0; i < kSides; ++i) {
    // Integral on the error of this sample, unless the output saturates in
    // the error's direction (anti-windup); never more than the full
    // voltage. Computed again, not taken from UpdateOutputs: Gauss-Seidel
    // transfers new inputs right before DoStep.
    const double u = Voltage(i);
    const double error = ref_[i] - drive_rate_[i];
    if (!(std::abs(u) > max_voltage_ && error * u > 0.0)) integral_[i] += error * dt_s;
    if (drive_ki_ > 0.0) integral_[i] = SignedMin(integral_[i], max_voltage_ / drive_ki_);

    // Reference: rate-limited ramp towards the scaled set point.
    ref_[i] = next_[i];
    const double goal = SignedMin(scale * setpoint[i], max_rate_);
    next_[i] = ref_[i] + SignedMin(goal - ref_[i], max_acceleration_ * dt_s);
  }
  period_s_ = dt_s;
  ComputeOutputs();
  return cosim::StepResult::kOk;
}

void DiffDriveControllerUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals.clear();
  for (const auto* v : {&ref_, &next_, &integral_}) {
    state.reals.insert(state.reals.end(), v->begin(), v->end());
  }
  state.reals.push_back(period_s_);
  state.integers.clear();
}

void DiffDriveControllerUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t expected = 3 * kSides + 1;
  if (state.reals.size() != expected || !state.integers.empty()) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected " + std::to_string(expected) + " and 0");
  }
  auto it = state.reals.begin();
  for (auto* v : {&ref_, &next_, &integral_}) {
    std::copy(it, it + static_cast<std::ptrdiff_t>(kSides), v->begin());
    it += static_cast<std::ptrdiff_t>(kSides);
  }
  period_s_ = *it;
}

}  // namespace linesim::control
