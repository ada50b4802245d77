#pragma once

#include <cstddef>
#include <limits>
#include <vector>

namespace linesim::control {

/// x limited to [-limit, limit] (limit >= 0).
double ClampSymmetric(double x, double limit);

/// The drive rate loop of wheel_controller and diff_drive_controller: per
/// channel (wheel or side) a sampled-data PI with feedforward from the
/// wheel rate reference to the motor voltage, and the slew-limited ramp
/// that makes that reference. Per channel the voltage before saturation is
///   k_ff mean(w_ref over the period) + k_acc dw_ref/dt + kp (w_ref - w) + ki I,
/// with w_ref the reference at this sample, the mean and dw_ref/dt taken
/// over the coming period (towards the next reference), w the measured rate
/// and I the integral of the rate error. The integral stops while the
/// output saturates in the direction of the error (conditional
/// integration, anti-windup) and never holds more than the full voltage.
///
/// The units own the sample period (wheel_controller shares it with its
/// steering) and the supply voltage; they pass them in.
class DriveRateLoop {
 public:
  /// Robot-specific: NaN until the unit's parameters set them.
  struct Gains {
    static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
    double feedforward = kUnset;               // V.s/rad, k_ff
    double acceleration_feedforward = kUnset;  // V.s2/rad, k_acc
    double kp = kUnset;                        // V.s/rad
    double ki = kUnset;                        // V/rad
    double max_rate = kUnset;                  // rad/s, reference limit
    double max_acceleration = kUnset;          // rad/s2, reference slew limit
  };

  /// Values saved per channel by AppendState: reference, next reference,
  /// integral.
  static constexpr std::size_t kStatePerChannel = 3;

  explicit DriveRateLoop(std::size_t channels);

  /// References and integrals to zero.
  void Reset();

  /// The voltage of channel i before saturation, from the measured rate;
  /// period_s is the step that produced the next reference (0: none yet,
  /// no acceleration in the reference).
  double Voltage(std::size_t i, double measured_rate, double period_s) const;

  /// Commits the sample of channel i: the integral with the error at this
  /// sample (period_s and max_voltage as for Voltage and its saturation),
  /// then the reference advanced to the next one and a new next reference
  /// ramped over dt_s towards setpoint (limited to max_rate).
  void Step(std::size_t i, double setpoint, double measured_rate, double period_s, double dt_s,
            double max_voltage);

  /// The reference of channel i at this sample.
  double reference(std::size_t i) const { return ref_[i]; }

  Gains gains;

  /// Appends the references, then the next references, then the integrals.
  void AppendState(std::vector<double>& reals) const;
  /// Reads what AppendState wrote from it on (the caller checked the size);
  /// returns the position after it.
  std::vector<double>::const_iterator RestoreState(std::vector<double>::const_iterator it);

 private:
  // Per channel: the reference at this sample and at the next one, and the
  // integral of the rate error.
  std::vector<double> ref_, next_, integral_;
};

}  // namespace linesim::control
