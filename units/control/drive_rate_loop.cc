#include "units/control/drive_rate_loop.h"

#include <algorithm>
#include <cmath>

namespace linesim::control {

double ClampSymmetric(double x, double limit) { return std::clamp(x, -limit, limit); }

DriveRateLoop::DriveRateLoop(std::size_t channels)
    : ref_(channels, 0.0), next_(channels, 0.0), integral_(channels, 0.0) {}

void DriveRateLoop::Reset() {
  for (auto* v : {&ref_, &next_, &integral_}) std::fill(v->begin(), v->end(), 0.0);
}

double DriveRateLoop::Voltage(std::size_t i, double measured_rate, double period_s) const {
  const double accel_ref = period_s > 0.0 ? (next_[i] - ref_[i]) / period_s : 0.0;
  // The back-EMF grows over the period with the reference: feed the mean.
  return gains.feedforward * 0.5 * (ref_[i] + next_[i]) +
         gains.acceleration_feedforward * accel_ref + gains.kp * (ref_[i] - measured_rate) +
         gains.ki * integral_[i];
}

void DriveRateLoop::Step(std::size_t i, double setpoint, double measured_rate, double period_s,
                         double dt_s, double max_voltage) {
  // Integral on the error of this sample, unless the output saturates in
  // the error's direction (anti-windup); never more than the full voltage.
  // Computed again, not taken from the unit's UpdateOutputs: Gauss-Seidel
  // transfers new inputs right before DoStep.
  const double u = Voltage(i, measured_rate, period_s);
  const double error = ref_[i] - measured_rate;
  if (!(std::abs(u) > max_voltage && error * u > 0.0)) integral_[i] += error * dt_s;
  if (gains.ki > 0.0) integral_[i] = ClampSymmetric(integral_[i], max_voltage / gains.ki);

  // Reference: rate-limited ramp towards the set point.
  ref_[i] = next_[i];
  const double goal = ClampSymmetric(setpoint, gains.max_rate);
  next_[i] = ref_[i] + ClampSymmetric(goal - ref_[i], gains.max_acceleration * dt_s);
}

void DriveRateLoop::AppendState(std::vector<double>& reals) const {
  for (const auto* v : {&ref_, &next_, &integral_}) reals.insert(reals.end(), v->begin(), v->end());
}

std::vector<double>::const_iterator DriveRateLoop::RestoreState(
    std::vector<double>::const_iterator it) {
  const auto n = static_cast<std::ptrdiff_t>(ref_.size());
  for (auto* v : {&ref_, &next_, &integral_}) {
    std::copy(it, it + n, v->begin());
    it += n;
  }
  return it;
}

}  // namespace linesim::control
