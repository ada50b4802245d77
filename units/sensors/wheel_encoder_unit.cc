#include "units/sensors/wheel_encoder_unit.h"

#include <algorithm>
#include <limits>
#include <numbers>
#include <utility>

namespace linesim::sensors {

namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
}  // namespace

WheelEncoderUnit::WheelEncoderUnit(std::string name, int channels)
    : cosim::Unit(kTypeName, std::move(name)) {
  if (channels < 1) {
    throw cosim::UnitError(Where() + ": channels must be at least 1, got " +
                           std::to_string(channels));
  }
  const auto n = static_cast<std::size_t>(channels);
  counts_per_revolution_.assign(n, std::numeric_limits<double>::quiet_NaN());
  angle_.assign(n, 0.0);
  counts_.assign(n, 0.0);
  rate_.assign(n, 0.0);
  committed_.assign(n, 0);

  auto& v = variables();
  v.Parameter("counts_per_revolution", "1", &counts_per_revolution_,
              "counts per joint revolution: encoder counts per motor revolution (x4 with "
              "quadrature decoding) times the gear ratio; one per channel (robot-specific)",
              cosim::Rule::Positive().NoDefault().Count());
  v.Parameter("hysteresis", "1", &hysteresis_,
              "hysteresis of the decoder's edges, in counts: after counting up, the count "
              "steps down only once the shaft is this far below the edge (0: ideal decoder)",
              cosim::Rule::Range(0.0, true, 1.0, false));
  v.Input("angle", "rad", &angle_, "joint angle of each channel (connect the chassis' "
                                   "drive_angle / steer_angle)");
  v.Output("counts", "1", &counts_,
           "counter value of each channel (an integer): floor(angle * cpr / 2 pi) for an "
           "ideal decoder",
           {"angle"});
  v.Output("rate", "rad/s", &rate_,
           "joint rate from the count difference over the sample interval, as a driver "
           "computes it (0 at the first sample)",
           {"angle"});
}

void WheelEncoderUnit::Initialize() {
  ThrowIfBadParameters();
  for (std::size_t i = 0; i < angle_.size(); ++i) {
    const double position = CheckCount(angle_[i] * counts_per_revolution_[i] / kTwoPi,
                                       "counts[" + std::to_string(i) + "]");
    committed_[i] = static_cast<std::int64_t>(std::floor(position));
    counts_[i] = static_cast<double>(committed_[i]);
    rate_[i] = 0.0;
  }
  interval_ = 0;
}

void WheelEncoderUnit::UpdateOutputs() {
  const double interval_s = cosim::NsToSeconds(interval_);
  for (std::size_t i = 0; i < angle_.size(); ++i) {
    const double cpr = counts_per_revolution_[i];
    const double position = angle_[i] * cpr / kTwoPi;
    if (!(std::abs(position) <= cosim::kMaxExactCount)) {
      CheckCount(position, "counts[" + std::to_string(i) + "]");  // throws
    }
    const std::int64_t c = IncrementalCount(committed_[i], position, hysteresis_);
    counts_[i] = static_cast<double>(c);
    rate_[i] =
        interval_ > 0 ? static_cast<double>(c - committed_[i]) * kTwoPi / cpr / interval_s : 0.0;
  }
}

cosim::StepResult WheelEncoderUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  // Commit the sample taken at t (by UpdateOutputs or Initialize), not one
  // from the inputs now: a Gauss-Seidel master transfers its predecessors'
  // end-of-step values right before DoStep. The outputs keep showing it
  // until the inputs of t + dt arrive.
  for (std::size_t i = 0; i < angle_.size(); ++i) {
    committed_[i] = static_cast<std::int64_t>(counts_[i]);
  }
  interval_ = dt;
  return cosim::StepResult::kOk;
}

void WheelEncoderUnit::SaveInternal(cosim::UnitState& state) const {
  state.integers.assign(committed_.begin(), committed_.end());
  state.integers.push_back(interval_);
  state.reals.clear();
}

void WheelEncoderUnit::RestoreInternal(const cosim::UnitState& state) {
  if (state.integers.size() != committed_.size() + 1 || !state.reals.empty()) {
    throw cosim::UnitError(Where() + ": saved state has " +
                           std::to_string(state.integers.size()) + " integers and " +
                           std::to_string(state.reals.size()) + " reals, expected " +
                           std::to_string(committed_.size() + 1) + " and 0");
  }
  std::copy(state.integers.begin(), state.integers.end() - 1, committed_.begin());
  interval_ = state.integers.back();
}

}  // namespace linesim::sensors
