#include "units/sensors/belt_encoder_unit.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "units/sensors/wheel_encoder_unit.h"

namespace linesim::sensors {

namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
}  // namespace

BeltEncoderUnit::BeltEncoderUnit(std::string name)
    : cosim::Unit(kTypeName, std::move(name)),
      wheel_radius_(std::numeric_limits<double>::quiet_NaN()),
      counts_per_revolution_(std::numeric_limits<double>::quiet_NaN()) {
  auto& v = variables();
  v.Parameter("wheel_radius", "m", &wheel_radius_, "radius of the wheel rolling on the belt",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("counts_per_revolution", "1", &counts_per_revolution_,
              "encoder counts per wheel revolution (x4 with quadrature decoding)",
              cosim::Rule::Positive().NoDefault().Count());
  v.Parameter("hysteresis", "1", &hysteresis_,
              "hysteresis of the decoder's edges, in counts (0: ideal decoder)",
              cosim::Rule::Range(0.0, true, 1.0, false));
  v.Parameter("average_window", &average_window_,
              "samples in the moving average of the speed (1: the count difference over one "
              "sample interval)",
              cosim::Rule::Range(1, 1000));
  v.Input("travel", "m", &travel_,
          "distance the belt's surface has moved (connect the belt unit's travel[k])");
  v.Output("counts", "1", &counts_, "counter value (an integer)", {"travel"});
  v.Output("speed", "m/s", &speed_,
           "belt speed from the count difference over the sample interval(s), as the "
           "microcontroller computes it (0 at the first sample)",
           {"travel"});
}

double BeltEncoderUnit::Position() const {
  return CheckCount(travel_ / wheel_radius_ * counts_per_revolution_ / kTwoPi, "counts");
}

void BeltEncoderUnit::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void BeltEncoderUnit::Initialize() {
  ThrowIfBadParameters();
  const auto window = static_cast<std::size_t>(average_window_);
  ring_counts_.assign(window, 0);
  ring_times_.assign(window, 0);
  ring_head_ = 0;
  ring_size_ = 0;
  count_ = static_cast<std::int64_t>(std::floor(Position()));
  sample_time_ = start_;
  counts_ = static_cast<double>(count_);
  speed_ = 0.0;
}

void BeltEncoderUnit::UpdateOutputs() {
  const std::int64_t c = IncrementalCount(count_, Position(), hysteresis_);
  counts_ = static_cast<double>(c);
  if (ring_size_ == 0) {
    speed_ = 0.0;
    return;
  }
  // The oldest sample of the window: m = ring_size_ samples back.
  const std::int64_t old_count = ring_counts_[ring_head_];
  const cosim::TimeNs old_time = ring_times_[ring_head_];
  speed_ = static_cast<double>(c - old_count) * kTwoPi * wheel_radius_ / counts_per_revolution_ /
           cosim::NsToSeconds(sample_time_ - old_time);
}

cosim::StepResult BeltEncoderUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  // Commit the sample taken at t by UpdateOutputs (or Initialize), not one
  // from the inputs now (Gauss-Seidel hands over the belt's travel at
  // t + dt before this step).
  count_ = static_cast<std::int64_t>(counts_);
  // Push the sample at t, dropping the oldest once the window is full.
  const std::size_t window = ring_counts_.size();
  const std::size_t slot = (ring_head_ + ring_size_) % window;
  ring_counts_[slot] = count_;
  ring_times_[slot] = t;
  if (ring_size_ < window) {
    ++ring_size_;
  } else {
    ring_head_ = (ring_head_ + 1) % window;
  }
  sample_time_ = t + dt;
  return cosim::StepResult::kOk;
}

void BeltEncoderUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals.clear();
  state.integers = {count_, start_, sample_time_, static_cast<std::int64_t>(ring_head_),
                    static_cast<std::int64_t>(ring_size_)};
  state.integers.insert(state.integers.end(), ring_counts_.begin(), ring_counts_.end());
  state.integers.insert(state.integers.end(), ring_times_.begin(), ring_times_.end());
}

void BeltEncoderUnit::RestoreInternal(const cosim::UnitState& state) {
  // The window (a parameter) came back with the variables.
  const auto window = static_cast<std::size_t>(average_window_);
  if (state.integers.size() != 5 + 2 * window || !state.reals.empty()) {
    throw cosim::UnitError(Where() + ": saved state has " +
                           std::to_string(state.integers.size()) + " integers and " +
                           std::to_string(state.reals.size()) + " reals, expected " +
                           std::to_string(5 + 2 * window) + " and 0");
  }
  const auto& s = state.integers;
  if (s[3] < 0 || s[4] < 0 || static_cast<std::size_t>(s[3]) >= window ||
      static_cast<std::size_t>(s[4]) > window) {
    throw cosim::UnitError(Where() + ": saved ring position " + std::to_string(s[3]) +
                           " and size " + std::to_string(s[4]) + " do not fit the window of " +
                           std::to_string(window));
  }
  count_ = s[0];
  start_ = s[1];
  sample_time_ = s[2];
  ring_head_ = static_cast<std::size_t>(s[3]);
  ring_size_ = static_cast<std::size_t>(s[4]);
  const auto counts_begin = s.begin() + 5;
  const auto times_begin = counts_begin + static_cast<std::ptrdiff_t>(window);
  ring_counts_.assign(counts_begin, times_begin);
  ring_times_.assign(times_begin, s.end());
}

}  // namespace linesim::sensors
