#include "units/evaluation/pose_error.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "models/angle.h"

namespace linesim::evaluation {

PoseErrorUnit::PoseErrorUnit(std::string name) : cosim::Unit(kTypeName, std::move(name)) {
  auto& v = variables();
  v.Parameter("region_x", "m", &region_x_, "centre x of the region the statistics count in",
              cosim::Rule::Finite());
  v.Parameter("region_y", "m", &region_y_, "centre y of the region", cosim::Rule::Finite());
  v.Parameter("region_yaw", "rad", &region_yaw_, "heading of the region's length",
              cosim::Rule::Finite());
  v.Parameter("region_length", "m", &region_length_,
              "the region's length (0: no region, every point counts)", cosim::Rule::NonNegative());
  v.Parameter("region_width", "m", &region_width_, "the region's width",
              cosim::Rule::NonNegative());
  v.Input("true_position", "m", &true_position_, "true x, y of base_link in map");
  v.Input("true_yaw", "rad", &true_yaw_, "true yaw of base_link");
  v.Input("estimated_position", "m", &estimated_position_, "estimated x, y of base_link in map");
  v.Input("estimated_yaw", "rad", &estimated_yaw_, "estimated yaw of base_link");
  v.Output("position_error", "m", &position_error_,
           "distance between the estimated and the true position",
           {"true_position", "estimated_position"});
  v.Output("yaw_error", "rad", &yaw_error_, "estimated - true yaw, wrapped to (-pi, pi]",
           {"true_yaw", "estimated_yaw"});
  v.Output("max_position_error", "m", &max_position_error_,
           "largest position_error over the communication points so far", {});
  v.Output("rms_position_error", "m", &rms_position_error_,
           "root mean square of position_error over the communication points so far", {});
  v.Output("max_yaw_error", "rad", &max_yaw_error_, "largest |yaw_error| so far", {});
  v.Output("rms_yaw_error", "rad", &rms_yaw_error_, "root mean square of yaw_error so far", {});
  v.Output("samples", "1", &samples_out_,
           "communication points counted so far (with a region: those with the true position "
           "in it)",
           {});
}

void PoseErrorUnit::Evaluate() {
  position_error_ = std::hypot(estimated_position_[0] - true_position_[0],
                               estimated_position_[1] - true_position_[1]);
  yaw_error_ = models::WrapAngle(estimated_yaw_ - true_yaw_);
}

void PoseErrorUnit::Initialize() {
  ThrowIfBadParameters();
  sum_squared_position_ = sum_squared_yaw_ = 0.0;
  samples_ = 0;
  max_position_error_ = rms_position_error_ = max_yaw_error_ = rms_yaw_error_ = 0.0;
  samples_out_ = 0.0;
  Evaluate();
}

cosim::StepResult PoseErrorUnit::DoStep(cosim::TimeNs t, cosim::TimeNs) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  // The inputs are those at the step's start: count them.
  Evaluate();
  if (region_length_ > 0.0) {
    const double dx = true_position_[0] - region_x_, dy = true_position_[1] - region_y_;
    const double c = std::cos(region_yaw_), s = std::sin(region_yaw_);
    if (std::abs(c * dx + s * dy) > 0.5 * region_length_ ||
        std::abs(-s * dx + c * dy) > 0.5 * region_width_) {
      return cosim::StepResult::kOk;
    }
  }
  sum_squared_position_ += position_error_ * position_error_;
  sum_squared_yaw_ += yaw_error_ * yaw_error_;
  ++samples_;
  samples_out_ = static_cast<double>(samples_);
  const double n = static_cast<double>(samples_);
  max_position_error_ = std::max(max_position_error_, position_error_);
  max_yaw_error_ = std::max(max_yaw_error_, std::abs(yaw_error_));
  rms_position_error_ = std::sqrt(sum_squared_position_ / n);
  rms_yaw_error_ = std::sqrt(sum_squared_yaw_ / n);
  return cosim::StepResult::kOk;
}

void PoseErrorUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals = {sum_squared_position_, sum_squared_yaw_};
  state.integers = {samples_};
}

void PoseErrorUnit::RestoreInternal(const cosim::UnitState& state) {
  if (state.reals.size() != 2 || state.integers.size() != 1) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected 2 and 1");
  }
  sum_squared_position_ = state.reals[0];
  sum_squared_yaw_ = state.reals[1];
  samples_ = state.integers[0];
  samples_out_ = static_cast<double>(samples_);
}

}  // namespace linesim::evaluation
