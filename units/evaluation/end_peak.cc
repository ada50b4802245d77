#include "units/evaluation/end_peak.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace linesim::evaluation {

EndPeakUnit::EndPeakUnit(std::string name, int count)
    : cosim::Unit(kTypeName, std::move(name)), values_(static_cast<std::size_t>(count), 0.0) {
  auto& v = variables();
  v.Parameter("window", "m", &window_,
              "length of the path's end over which the peak is taken (default 2 m: a final "
              "approach)",
              cosim::Rule::Positive());
  v.Input("values", "A", &values_, "the currents whose peak absolute value is taken");
  v.Input("remaining", "m", &remaining_, "the path's length left ahead of the robot");
  v.Output("peak", "A", &peak_,
           "largest |value| of any signal so far while remaining <= window (0 before)", {});
  v.Output("entered", &entered_, "the robot has been within the window", {});
}

void EndPeakUnit::Initialize() {
  ThrowIfBadParameters();
  peak_ = 0.0;
  entered_ = false;
  Sample();
}

void EndPeakUnit::Sample() {
  if (!(remaining_ <= window_)) return;
  entered_ = true;
  for (const double value : values_) peak_ = std::max(peak_, std::abs(value));
}

cosim::StepResult EndPeakUnit::DoStep(cosim::TimeNs t, cosim::TimeNs) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  Sample();
  return cosim::StepResult::kOk;
}

}  // namespace linesim::evaluation
