#pragma once

#include <limits>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "units/control/drive_rate_loop.h"

namespace linesim::control {

/// The wheel controller of a robot with W independently steered and driven
/// wheels (Rob@Work 3: W = 4), run as a sampled-data controller (20 ms in
/// paper 1's robot). Per sample at time t:
///  - feedback (UpdateOutputs, direct feedthrough): the motor voltages from
///    the reference of this sample and the measured joint angles and rates;
///  - reference (DoStep(t, dt)): the body velocity and yaw rate commands
///    become a contact velocity per wheel (paper 1 Eq. 1), less the surface
///    velocity under the wheel when compensation is on (Algorithm 1), then
///    a steering angle and drive rate by the flip rule; both are
///    slew-limited into the reference that the next samples track.
/// So a new command reaches the voltages one sample later, while the
/// measured joint states act at once. Outputs are meant to be held by the
/// master over the period.
///
/// Steering voltage (PD plus feedforward, saturated at max_voltage):
///   kp wrap(a_ref - a) + kd (r_ref - r) + k_ff r_ref + k_acc alpha_ref,
/// with a_ref, r_ref, alpha_ref the slewed reference angle at the sample,
/// its rate over the coming period and the change of that rate.
/// Drive voltage (DriveRateLoop: PI plus feedforward, saturated, conditional
/// integration):
///   k_ff mean(w_ref over the period) + k_acc dw_ref/dt + kp (w_ref - w) + ki I.
/// The feedforward gains are the back-EMF constant and the load inertia
/// seen through the gearbox, so a well-modelled wheel follows its reference
/// without error and the feedback only corrects what the model misses.
///
/// Robot-specific parameters have no default (NaN until set; Initialize
/// refuses them): wheel_x, wheel_y, wheel_radius, the four feedforwards,
/// drive_max_rate and drive_max_acceleration.
class WheelControllerUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "wheel_controller";

  /// Throws cosim::UnitError if wheel_count < 1. The robot-specific
  /// parameters start unset (NaN) and must be set before Initialize.
  explicit WheelControllerUnit(std::string name, int wheel_count = 4);

  /// The declared rules, and: no two wheels at one point (wheel_x, wheel_y).
  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  /// Validates the parameters (throws cosim::UnitError listing every
  /// problem), takes the measured steering angles as the reference, zero
  /// drive reference and integrators, and computes the outputs. Idempotent.
  void Initialize() override;
  /// The voltages from the current joint measurements and the reference of
  /// this sample; the state is not changed.
  void UpdateOutputs() override { ComputeOutputs(); }
  /// Commits the sample taken at t: drive integrators with the error at t,
  /// the reference advanced to t + dt and the next one from the inputs at t.
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  int wheel_count() const { return wheel_count_; }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  /// Start value of a robot-specific parameter (declared with
  /// Rule::NoDefault): not set.
  static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
  /// The steering voltage of wheel i before saturation.
  double SteerVoltage(std::size_t i) const;
  /// Reference steering rate of wheel i over the coming period (0 before
  /// the first step).
  double SteerRateReference(std::size_t i) const;
  void ComputeOutputs();

  int wheel_count_;

  // Parameters (the drive gains and limits are in drive_.gains).
  std::vector<double> wheel_x_, wheel_y_;
  double wheel_radius_ = kUnset;
  bool compensation_ = true;
  // 3 x the contact-velocity command's noise at rest on own sensors (fused
  // localization + fused_flow, hold_on_belt with the line off: 1.9-2.9 mm/s
  // rms over 8 seeds): a command below it is noise, above it intent.
  double steer_speed_threshold_ = 1e-2;
  double steer_kp_ = kUnset;
  double steer_kd_ = kUnset;
  double steer_feedforward_ = kUnset;
  double steer_acceleration_feedforward_ = kUnset;
  double steer_max_rate_ = kUnset;
  double steer_max_acceleration_ = kUnset;
  double max_voltage_ = kUnset;

  // Inputs.
  std::vector<double> velocity_command_;
  double yaw_rate_command_ = 0.0;
  std::vector<double> surface_velocity_;
  std::vector<double> steer_angle_, steer_rate_, drive_rate_;

  // Outputs.
  std::vector<double> steer_voltage_, drive_voltage_, steer_target_, drive_rate_target_;

  // State, per wheel. The steering reference at this sample and at the next
  // one (wrapped angles), the reference steering rate over the previous
  // period (for its acceleration), the last flip-rule heading, and the drive
  // rate loop (references and integrator). period_s_ is the step that
  // produced the next reference (0 before the first step: no motion in the
  // reference yet).
  std::vector<double> steer_ref_, steer_next_, steer_prev_rate_, flip_angle_;
  DriveRateLoop drive_;
  double period_s_ = 0.0;
  // DoStep's scratch (not state): the flip-rule drive rate of this sample.
  std::vector<double> drive_setpoint_;
};

}  // namespace linesim::control
