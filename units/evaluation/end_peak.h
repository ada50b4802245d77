#pragma once

#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::evaluation {

/// The largest absolute value of a set of currents (a robot's drive
/// motors') while the robot is within `window` metres of its path's end:
/// what the final approach asks of the drives. Sampled at every step of the
/// unit from the inputs at its start; the path's remaining length is an
/// input (path_deviation's `remaining`), so the window is measured along
/// the path, never as a straight-line distance to its end.
///
/// 0 until the robot first enters the window (a run that never gets there
/// reads 0, and `entered` 0).
class EndPeakUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "end_peak";

  /// `count`: the number of signals in `values`.
  EndPeakUnit(std::string name, int count);

  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;
  // No state beyond its variables (the peak is an output).

 private:
  void Sample();

  double window_ = 2.0;
  std::vector<double> values_;
  double remaining_ = 0.0;
  double peak_ = 0.0;
  bool entered_ = false;
};

}  // namespace linesim::evaluation
