#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::sensors {

/// The count an incremental quadrature counter holds when the shaft is at
/// `position` (in counts: angle * counts_per_revolution / 2 pi) and it held
/// `previous`. The counter steps up when the position reaches the next edge
/// (previous + 1) and steps down only when it falls `hysteresis` counts
/// below the edge it crossed on the way up (previous - hysteresis), as a
/// decoder with a hysteresis band on its edges does. With hysteresis 0 it
/// is floor(position) whatever `previous` is. A jump of several counts
/// within one sample is counted in full (the decoder runs far faster than
/// the sample rate).
inline std::int64_t IncrementalCount(std::int64_t previous, double position, double hysteresis) {
  if (position >= static_cast<double>(previous) + 1.0) {
    return static_cast<std::int64_t>(std::floor(position));
  }
  if (position < static_cast<double>(previous) - hysteresis) {
    return static_cast<std::int64_t>(std::floor(position + hysteresis));
  }
  return previous;
}

/// Incremental quadrature encoders on N joints (structural key `channels`),
/// read by the controller once per unit step (the scenario sets the step:
/// 20 ms for the robots' control cycle).
///
/// Per channel, at each communication point (direct feedthrough from
/// `angle`, computed by UpdateOutputs from the angle of that instant):
///   position = angle * counts_per_revolution / (2 pi)   [counts]
///   counts   = IncrementalCount(counts of the previous sample, position,
///              hysteresis)  = floor(position) for hysteresis 0
///   rate     = (counts - counts of the previous sample) * 2 pi
///              / counts_per_revolution / sample interval
/// i.e. the counter is zero where the angle is zero (the driver's reset),
/// counts down for negative angles, and the rate is what a driver computes
/// from two successive readings (quantized to 2 pi / cpr / dt; 0 at the
/// first sample, which has no predecessor). DoStep(t, dt) commits the
/// sample taken at t by UpdateOutputs (or Initialize), whatever inputs it
/// is given since (a Gauss-Seidel master hands it its sources' values at
/// t + dt).
///
/// counts_per_revolution is counts per JOINT revolution: encoder counts per
/// motor revolution (x4 for quadrature decoding where the device does it)
/// times the gear ratio. Robot-specific: no default.
class WheelEncoderUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "wheel_encoder";

  /// Throws cosim::UnitError if channels < 1.
  WheelEncoderUnit(std::string name, int channels);

  void Initialize() override;
  void UpdateOutputs() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  // Parameters.
  std::vector<double> counts_per_revolution_;
  double hysteresis_ = 0.0;
  // Input.
  std::vector<double> angle_;
  // Outputs.
  std::vector<double> counts_, rate_;
  // State: the counter at the last committed sample and the interval that
  // ended there (0 before the first step).
  std::vector<std::int64_t> committed_;
  cosim::TimeNs interval_ = 0;
};

}  // namespace linesim::sensors
