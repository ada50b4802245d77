#include "units/sources/step_signal.h"

#include <cmath>
#include <string>

namespace linesim::sources {

StepSignalUnit::StepSignalUnit(std::string name, int count, std::string unit,
                               std::vector<Step> steps)
    : cosim::Unit(kTypeName, std::move(name)), steps_(std::move(steps)) {
  if (count < 1) {
    throw cosim::UnitError(Where() + ": needs at least one channel, got " + std::to_string(count));
  }
  initial_.assign(static_cast<std::size_t>(count), 0.0);
  value_.assign(static_cast<std::size_t>(count), 0.0);
  for (std::size_t i = 0; i < steps_.size(); ++i) {
    if (steps_[i].value.size() != value_.size()) {
      throw cosim::UnitError(Where() + ": step " + std::to_string(i) + " has " +
                             std::to_string(steps_[i].value.size()) + " values, expected " +
                             std::to_string(value_.size()));
    }
  }
  auto& v = variables();
  // A non-finite value is named here, not later as a NaN output.
  v.Parameter("initial", unit, &initial_, "value before the first step", cosim::Rule::Finite());
  v.Output("value", unit, &value_, "the signal, one element per channel", {});
}

std::vector<cosim::ParameterProblem> StepSignalUnit::CheckParameters() const {
  // The declared rules (initial), then the schedule, which is no variable.
  auto problems = cosim::Unit::CheckParameters();
  for (std::size_t i = 0; i < steps_.size(); ++i) {
    for (double v : steps_[i].value) {
      if (!std::isfinite(v)) {
        problems.push_back({"steps", i, "values must be finite, got " + cosim::FormatValue(v)});
        break;
      }
    }
    if (i > 0 && steps_[i].time <= steps_[i - 1].time) {
      problems.push_back({"steps", i,
                          "step times must increase, got " + cosim::FormatSeconds(steps_[i].time) +
                              " s after " + cosim::FormatSeconds(steps_[i - 1].time) + " s"});
    }
  }
  return problems;
}

void StepSignalUnit::Evaluate(cosim::TimeNs t) {
  const std::vector<double>* current = &initial_;
  for (const Step& s : steps_) {
    if (s.time > t) break;
    current = &s.value;
  }
  value_ = *current;
}

void StepSignalUnit::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void StepSignalUnit::Initialize() {
  ThrowIfBadParameters();
  Evaluate(start_);
}

cosim::StepResult StepSignalUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  Evaluate(t + dt);
  return cosim::StepResult::kOk;
}

}  // namespace linesim::sources
