#pragma once

#include <limits>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "units/control/drive_rate_loop.h"

namespace linesim::control {

/// The wheel controller of a differential or skid-steer base with one drive
/// motor per side (index 0 left, 1 right; Husky A200: the two wheels of a
/// side share their motor through a belt), run as a sampled-data controller
/// like wheel_controller. Per sample at time t:
///  - feedback (UpdateOutputs, direct feedthrough): the motor voltages from
///    the reference of this sample and the measured rates;
///  - reference (DoStep(t, dt)): the commands become wheel rates
///      w_left  = (v - omega T / 2) / r,   w_right = (v + omega T / 2) / r,
///    with v = velocity_command[0] (the sideways part is ignored: the base
///    cannot follow it), omega the yaw rate command, r the wheel radius and
///    T the EFFECTIVE track: a skid-steer base scrubs its wheels sideways
///    when it turns and needs a larger speed difference than its geometric
///    track gives (the Husky's ROS configuration multiplies its 0.571 m
///    wheel separation by 1.875). If a rate exceeds max_rate both are
///    scaled by one factor (the curvature is kept); then each reference
///    ramps towards its set point at most at max_acceleration.
/// So a new command reaches the voltages one sample later, while the
/// measured rates act at once. Outputs are meant to be held by the master
/// over the period.
///
/// Voltage per side (DriveRateLoop: PI plus feedforward, saturated at
/// +-max_voltage, conditional integration):
///   k_ff mean(w_ref over the period) + k_acc dw_ref/dt + kp (w_ref - w) + ki I,
/// with k_ff the back-EMF constant at the wheel (k_e N) and k_acc the joint
/// inertia over the torque per volt, J R / (eta N k_t), so a well-modelled
/// drive follows its reference without error. The integral stops while
/// the output saturates in the direction of the error and never holds more
/// than max_voltage.
///
/// Every parameter depends on the robot and its motors: none has a default
/// (NaN until set, declared with Rule::NoDefault; Initialize refuses them,
/// naming each).
class DiffDriveControllerUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "diff_drive_controller";

  explicit DiffDriveControllerUnit(std::string name);

  /// Validates the parameters (throws cosim::UnitError listing every
  /// problem), sets the references and integrals to zero and computes the
  /// outputs. Idempotent.
  void Initialize() override;
  /// The voltages from the current measured rates and the reference of
  /// this sample; the state is not changed.
  void UpdateOutputs() override { ComputeOutputs(); }
  /// Commits the sample taken at t: integrals with the error at t, the
  /// reference advanced to t + dt and the next one from the commands at t.
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  /// Start value of a robot-specific parameter (declared with
  /// Rule::NoDefault): not set.
  static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
  static constexpr std::size_t kSides = 2;
  void ComputeOutputs();

  // Parameters (all robot-specific; the drive gains and limits are in
  // drive_.gains).
  double wheel_radius_ = kUnset;
  double effective_track_ = kUnset;
  double max_voltage_ = kUnset;

  // Inputs.
  std::vector<double> velocity_command_;
  double yaw_rate_command_ = 0.0;
  std::vector<double> drive_rate_;

  // Outputs.
  std::vector<double> drive_voltage_, drive_rate_target_;

  // State: per side the drive rate loop (references and integral).
  // period_s_ is the step that produced the next reference (0 before the
  // first step: no motion in the reference).
  DriveRateLoop drive_;
  double period_s_ = 0.0;
};

}  // namespace linesim::control
