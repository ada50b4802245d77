#include "units/safety/safety_field_unit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "models/polygon.h"

namespace linesim::safety {

namespace {
constexpr double kNoLimit = std::numeric_limits<double>::infinity();
}

SafetyFieldUnit::SafetyFieldUnit(std::string name, int beam_count, std::vector<FieldSet> field_sets)
    : cosim::Unit(kTypeName, std::move(name)),
      beam_count_(beam_count),
      sets_(std::move(field_sets)) {
  if (beam_count_ < 1) throw cosim::UnitError(Where() + ": needs at least one beam");
  if (sets_.empty()) throw cosim::UnitError(Where() + ": needs at least one field set");
  // A degenerate polygon holds no point: a field that never stops.
  for (std::size_t i = 0; i < sets_.size(); ++i) {
    if (const auto problem = models::PolygonProblem(sets_[i].protective)) {
      throw cosim::UnitError(Where() + ": field set " + std::to_string(i) +
                             ": the protective field " + *problem);
    }
    if (sets_[i].warning.empty()) continue;
    if (const auto problem = models::PolygonProblem(sets_[i].warning)) {
      throw cosim::UnitError(Where() + ": field set " + std::to_string(i) + ": the warning field " +
                             *problem + " (give none or a polygon)");
    }
  }
  ranges_.assign(static_cast<std::size_t>(beam_count_), 0.0);
  velocity_command_.assign(2, 0.0);
  velocity_out_.assign(2, 0.0);
  using cosim::Rule;
  auto& v = variables();
  v.Parameter("first_beam_angle", "rad", &first_beam_angle_,
              "angle of beam 0 in the scanner frame (S300: -135 deg, 8010948)", Rule::Finite());
  v.Parameter("angular_step", "rad", &angular_step_, "angle between beams (S300: 0.5 deg, 8010948)",
              Rule::Positive());
  v.Parameter("no_return_value", "m", &no_return_value_,
              "what a beam without echo reads (never in a field)", Rule::Finite());
  v.Parameter("multiple_sampling", &multiple_sampling_,
              "consecutive infringing scans before a field counts as infringed (S300: 2 to 16, "
              "8010948)",
              Rule::Range(2, 16));
  // models/robots/raw3.yaml: drive_max_acceleration 12.5 rad/s^2 on a 0.08 m
  // wheel, 1 m/s^2 at the rim: the base's braking limit.
  v.Parameter("braking_deceleration", "m/s2", &braking_deceleration_,
              "deceleration of a safe stop (the base's braking limit; Rob@Work 3: 1 m/s^2)",
              Rule::Positive());
  v.Parameter("warning_speed", "m/s", &warning_speed_,
              "speed while the warning field is infringed (ASSUMPTION: 0.3 m/s, an application "
              "choice)",
              Rule::NonNegative());
  v.Parameter("restart_delay", "s", &restart_delay_,
              "time both fields must be clear before the robot resumes (ASSUMPTION: 2 s, an "
              "application choice)",
              Rule::NonNegative());
  v.Parameter("resume_acceleration", "m/s2", &resume_acceleration_,
              "how fast the speed cap rises on resuming (ASSUMPTION: 0.5 m/s^2)", Rule::Positive());
  v.Input("ranges", "m", &ranges_, "the scanner's reported ranges");
  v.Input("scan_count", "1", &scan_count_, "the scanner's completed scans (a new scan: evaluate)");
  v.Input("velocity_command", "m/s", &velocity_command_, "the follower's [vx, vy] (base_link)");
  v.Input("yaw_rate_command", "rad/s", &yaw_rate_command_, "the follower's yaw rate");
  v.Input("task_done", &task_done_, "the task's done (for task_time)");
  v.Output("velocity_command_out", "m/s", &velocity_out_, "[vx, vy] to the wheel controller",
           {"velocity_command", "yaw_rate_command"});
  v.Output("yaw_rate_command_out", "rad/s", &yaw_rate_out_, "yaw rate to the wheel controller",
           {"velocity_command", "yaw_rate_command"});
  v.Output("protective_clear", "1", &protective_clear_,
           "1: protective field clear (OSSDs on), 0: infringed", {});
  v.Output("warning_clear", "1", &warning_clear_, "1: warning field clear, 0: infringed", {});
  v.Output("field_set", "1", &field_set_, "index of the active field set", {});
  v.Output("speed_cap", "m/s", &speed_cap_out_, "the safety function's speed cap (-1: none)", {});
  v.Output("protective_stops", "1", &protective_stops_,
           "safe stops the protective field caused so far (an infringement during a stop, before "
           "its restart delay has run out, extends that stop)",
           {});
  v.Output("time_stopped", "s", &time_stopped_, "time the cap has held the robot at 0", {});
  v.Output("task_time", "s", &task_time_, "when task_done first rose (-1: not yet)", {});
}

std::vector<cosim::ParameterProblem> SafetyFieldUnit::CheckParameters() const {
  return cosim::Unit::CheckParameters();
}

bool SafetyFieldUnit::Inside(const std::vector<std::array<double, 2>>& polygon, double x,
                             double y) {
  // Even-odd crossing rule.
  bool inside = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const auto& a = polygon[i];
    const auto& b = polygon[j];
    if ((a[1] > y) != (b[1] > y) && x < (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]) + a[0]) {
      inside = !inside;
    }
  }
  return inside;
}

std::size_t SafetyFieldUnit::ActiveSet() const {
  for (std::size_t i = 0; i < sets_.size(); ++i) {
    if (last_speed_ <= sets_[i].max_speed_mps) return i;
  }
  return sets_.size() - 1;
}

void SafetyFieldUnit::EvaluateScan() {
  const std::size_t set = ActiveSet();
  field_set_ = static_cast<double>(set);
  const FieldSet& f = sets_[set];
  bool protective = false, warning = false;
  for (int i = 0; i < beam_count_ && !(protective && (warning || f.warning.empty())); ++i) {
    const double r = ranges_[static_cast<std::size_t>(i)];
    if (r == no_return_value_ || !(r > 0.0)) continue;
    const double a = first_beam_angle_ + i * angular_step_;
    const double x = r * std::cos(a), y = r * std::sin(a);
    if (!protective && Inside(f.protective, x, y)) protective = true;
    if (!warning && !f.warning.empty() && Inside(f.warning, x, y)) warning = true;
  }
  protective_scans_ = protective ? protective_scans_ + 1 : 0;
  warning_scans_ = warning ? warning_scans_ + 1 : 0;
  const bool was_clear = protective_clear_ == 1.0;
  protective_clear_ = protective_scans_ >= multiple_sampling_ ? 0.0 : 1.0;
  warning_clear_ = warning_scans_ >= multiple_sampling_ ? 0.0 : 1.0;
  // A new stop, unless the last one still holds (target_ 0 until its
  // restart delay has run out): legs walking out of a field break it again
  // and again while the robot stands.
  if (was_clear && protective_clear_ == 0.0 && target_ != 0.0) protective_stops_ += 1.0;
}

void SafetyFieldUnit::Initialize() {
  ThrowIfBadParameters();
  last_scan_count_ = scan_count_;
  protective_scans_ = warning_scans_ = 0;
  protective_clear_ = warning_clear_ = 1.0;
  protective_stops_ = time_stopped_ = 0.0;
  task_time_ = -1.0;
  cap_ = target_ = kNoLimit;
  clear_for_ = 0;
  last_speed_ = 0.0;
  field_set_ = static_cast<double>(ActiveSet());
  UpdateOutputs();
}

void SafetyFieldUnit::UpdateOutputs() {
  const double vx = velocity_command_[0], vy = velocity_command_[1];
  const double speed = std::hypot(vx, vy);
  double factor = 1.0;
  if (cap_ <= 0.0) {
    factor = 0.0;
  } else if (speed > cap_) {
    factor = cap_ / speed;
  }
  if (factor == 1.0) {
    velocity_out_[0] = vx;
    velocity_out_[1] = vy;
    yaw_rate_out_ = yaw_rate_command_;
  } else {
    velocity_out_[0] = vx * factor;
    velocity_out_[1] = vy * factor;
    yaw_rate_out_ = yaw_rate_command_ * factor;
  }
  speed_cap_out_ = std::isinf(cap_) ? -1.0 : cap_;
}

cosim::StepResult SafetyFieldUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  const double h = cosim::NsToSeconds(dt);
  if (task_done_ && task_time_ < 0.0) task_time_ = cosim::NsToSeconds(t - start_);
  last_speed_ = std::hypot(velocity_out_[0], velocity_out_[1]);
  if (scan_count_ != last_scan_count_) {
    last_scan_count_ = scan_count_;
    EvaluateScan();
  }
  if (protective_clear_ == 0.0) {
    target_ = 0.0;
    clear_for_ = 0;
  } else if (warning_clear_ == 0.0) {
    // A warning does not lift a stop that still waits for its restart delay.
    target_ = std::min(target_, warning_speed_);
    clear_for_ = 0;
  } else {
    // In whole nanoseconds: the delay ends on the step it should, whatever
    // the step's rounding in seconds.
    clear_for_ += dt;
    if (clear_for_ >= cosim::SecondsToNs(restart_delay_)) {
      target_ = kNoLimit;
    }
  }
  if (target_ < cap_) {
    // Brake from the speed last commanded (a cap above it does not act).
    cap_ = std::max(target_, std::min(cap_, last_speed_) - braking_deceleration_ * h);
  } else if (target_ > cap_) {
    cap_ = std::min(target_, cap_ + resume_acceleration_ * h);
    const double commanded = std::hypot(velocity_command_[0], velocity_command_[1]);
    if (std::isinf(target_) && cap_ >= commanded) cap_ = kNoLimit;
  }
  if (cap_ == 0.0) time_stopped_ += h;
  UpdateOutputs();
  return cosim::StepResult::kOk;
}

void SafetyFieldUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals = {last_scan_count_, cap_, target_, last_speed_};
  state.integers = {protective_scans_, warning_scans_, clear_for_};
}

void SafetyFieldUnit::RestoreInternal(const cosim::UnitState& state) {
  last_scan_count_ = state.reals.at(0);
  cap_ = state.reals.at(1);
  target_ = state.reals.at(2);
  last_speed_ = state.reals.at(3);
  clear_for_ = state.integers.at(2);
  protective_scans_ = state.integers.at(0);
  warning_scans_ = state.integers.at(1);
}

}  // namespace linesim::safety
