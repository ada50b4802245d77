#pragma once

#include <string>
#include <vector>

#include "cosim/unit.h"

namespace linesim::sources {

/// A piecewise-constant signal of `count` channels: the exogenous commands
/// and disturbances of a scenario (voltage steps, load torque steps).
/// Before the first switching time the output is `initial`; from each
/// switching time on it is that step's value.
class StepSignalUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "step_signal";

  struct Step {
    cosim::TimeNs time;
    std::vector<double> value;  // one per channel
  };

  /// `unit` is the unit of measure of the output (e.g. "V"); steps must be
  /// in increasing time order with `count` values each.
  StepSignalUnit(std::string name, int count, std::string unit, std::vector<Step> steps);

  /// The rule of `initial` (finite), and the schedule: finite values, times
  /// that increase.
  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

 private:
  void Evaluate(cosim::TimeNs t);

  std::vector<Step> steps_;
  std::vector<double> initial_;
  std::vector<double> value_;
  cosim::TimeNs start_ = 0;
};

}  // namespace linesim::sources
