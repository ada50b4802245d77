#include "units/control/path_follower_unit.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <utility>

#include "cosim/parameter_checks.h"
#include "models/angle.h"

namespace linesim::control {

PathFollowerUnit::PathFollowerUnit(std::string name, Mode mode,
                                   std::vector<std::array<double, 2>> waypoints_m, Base base)
    : cosim::Unit(kTypeName, std::move(name)),
      mode_(mode),
      base_(base),
      waypoints_m_(std::move(waypoints_m)),
      position_(2, 0.0),
      velocity_command_(2, 0.0) {
  if (mode_ == Mode::kPath) cumulative_m_ = models::CumulativeLengths(waypoints_m_);
  auto& v = variables();
  using cosim::Rule;
  v.Parameter("speed", "m/s", &speed_, "cruise speed along the path", Rule::Positive());
  v.Parameter("acceleration", "m/s2", &acceleration_,
              "along-path ramp up from the start and down before the goal (and, differential "
              "base, before a sharp corner)",
              Rule::Positive());
  // Named heading, not yaw: `yaw` is the measured heading input.
  v.Parameter("heading", "rad", &yaw_,
              "heading to hold in map while translating (omnidirectional base only)",
              Rule::Finite());
  // Gains of 0 switch a feedback off; they only have to be finite and >= 0.
  v.Parameter("k_cross", "1/s", &k_cross_, "cross-track gain", Rule::NonNegative());
  v.Parameter("k_position", "1/s", &k_position_,
              "position gain: along-track near the goal, and in hold mode", Rule::Positive());
  // The differential base steers only by the yaw rate: a heading gain or a
  // yaw-rate limit of 0 would leave it unable to turn (frozen at the start
  // or at the first corner). The omnidirectional base may switch it off.
  const bool differential = base_ == Base::kDifferential;
  v.Parameter("k_yaw", "1/s", &k_yaw_, "heading gain",
              differential ? Rule::Positive() : Rule::NonNegative());
  v.Parameter("max_speed", "m/s", &max_speed_, "limit on the commanded translation speed",
              Rule::Positive());
  v.Parameter("max_yaw_rate", "rad/s", &max_yaw_rate_, "limit on the commanded yaw rate",
              differential ? Rule::Positive() : Rule::NonNegative());
  v.Parameter("goal_tolerance", "m", &goal_tolerance_,
              "distance from the goal (hold: the point) counted as arrived", Rule::Positive());
  if (differential) {
    // Below pi/2: at pi/2 the robot would drive across its path. Above 0:
    // at 0 any heading error stops the robot, which then never drives.
    v.Parameter("turn_in_place_angle", "rad", &turn_in_place_angle_,
                "heading error beyond which the robot stops and turns in place; a path corner "
                "turning more than this is sharp (the robot stops at it)",
                Rule::Range(0.0, false, 0.5 * std::numbers::pi, false));
  }
  v.Input("position", "m", &position_, "x, y of base_link in map");
  v.Input("yaw", "rad", &yaw_measured_, "heading of base_link in map");
  // The velocity is rotated by the measured heading, and both commands
  // stop once the goal (a position) is reached: both depend on both.
  v.Output("velocity_command", "m/s", &velocity_command_,
           base_ == Base::kDifferential
               ? "body velocity command in base_link: vx, vy (always 0: differential base)"
               : "body velocity command in base_link: vx, vy",
           {"position", "yaw"});
  v.Output("yaw_rate_command", "rad/s", &yaw_rate_command_, "body yaw rate command",
           {"position", "yaw"});
  v.Output("cross_track_error", "m", &cross_track_error_,
           "signed distance from the path, + left of it; hold: distance from the point",
           {"position"});
  v.Output("progress", "m", &progress_, "arc length of the nearest path point (hold: 0)",
           {"position"});
  v.Output("done", &done_, "path: the goal was reached (latched); hold: within tolerance",
           {"position"});
  FindSharpCorners();
}

void PathFollowerUnit::FindSharpCorners() {
  sharp_corner_after_m_.clear();
  if (!SavesSegment() || waypoints_m_.size() < 2) return;
  // Backwards: the next sharp corner at or after the end of each segment.
  // The distance is only used on a valid path (CheckParameters).
  const std::size_t segments = waypoints_m_.size() - 1;
  sharp_corner_after_m_.assign(segments, std::numeric_limits<double>::infinity());
  std::size_t next = 0;  // 0: none ahead
  for (std::size_t i = segments; i-- > 0;) {
    const std::size_t k = i + 1;  // the waypoint at the end of segment i
    if (k + 1 < waypoints_m_.size() && SharpCorner(k)) next = k;
    if (next != 0) sharp_corner_after_m_[i] = cumulative_m_[next] - cumulative_m_[k];
  }
}

bool PathFollowerUnit::ZeroSegment(std::size_t k) const {
  // The search takes a segment's direction from the growth of cumulative_m_
  // (none: no tangent to follow), so a segment too short to grow the sum is
  // as bad as a zero one. After a non-finite waypoint the sum is NaN, and
  // only the segment itself can be judged.
  if (std::isfinite(cumulative_m_[k - 1])) return !(cumulative_m_[k] > cumulative_m_[k - 1]);
  return !(std::hypot(waypoints_m_[k][0] - waypoints_m_[k - 1][0],
                      waypoints_m_[k][1] - waypoints_m_[k - 1][1]) > 0.0);
}

std::vector<cosim::ParameterProblem> PathFollowerUnit::CheckParameters() const {
  cosim::ParameterChecks c;
  const std::size_t needed = mode_ == Mode::kPath ? 2 : 1;
  if (waypoints_m_.size() < needed) {
    c.Add({"waypoints", std::nullopt,
           std::string(mode_ == Mode::kPath ? "a path" : "hold") + " needs at least " +
               std::to_string(needed) + " waypoint(s), got " +
               std::to_string(waypoints_m_.size())});
  }
  const auto finite = [&](std::size_t k) {
    return std::isfinite(waypoints_m_[k][0]) && std::isfinite(waypoints_m_[k][1]);
  };
  for (std::size_t k = 0; k < waypoints_m_.size(); ++k) {
    if (!finite(k)) {
      c.Add({"waypoints", k,
             "must be finite, got (" + cosim::FormatValue(waypoints_m_[k][0]) + ", " +
                 cosim::FormatValue(waypoints_m_[k][1]) + ")"});
    } else if (mode_ == Mode::kPath && k > 0 && finite(k - 1) && ZeroSegment(k)) {
      c.Add({"waypoints", k, "repeats the previous waypoint (zero-length segment)"});
    }
  }
  // The waypoints are no table parameter: checked here. Every single-value
  // rule is declared with its parameter (Unit::CheckParameters walks them).
  auto problems = c.Take();
  for (auto& p : Unit::CheckParameters()) problems.push_back(std::move(p));
  return problems;
}

void PathFollowerUnit::Initialize() {
  ThrowIfBadParameters();
  FindSharpCorners();  // turn_in_place_angle is locked from here on
  ramp_mps_ = 0.0;
  done_latched_ = false;
  active_segment_ = 0;
  const models::PolylinePoint n = FindNearest();
  if (SavesSegment() && n.found) active_segment_ = n.segment;
  ComputeOutputs(n);
}

bool PathFollowerUnit::SharpCorner(std::size_t k) const {
  const auto& w = waypoints_m_;
  const double in = std::atan2(w[k][1] - w[k - 1][1], w[k][0] - w[k - 1][0]);
  const double out = std::atan2(w[k + 1][1] - w[k][1], w[k + 1][0] - w[k][0]);
  return std::abs(models::WrapAngle(out - in)) > turn_in_place_angle_;
}

PathFollowerUnit::OnSegment PathFollowerUnit::ProjectOnSegment(std::size_t i) const {
  const auto& a = waypoints_m_[i];
  const double length = cumulative_m_[i + 1] - cumulative_m_[i];
  const double tx = (waypoints_m_[i + 1][0] - a[0]) / length;
  const double ty = (waypoints_m_[i + 1][1] - a[1]) / length;
  const double dx = position_[0] - a[0], dy = position_[1] - a[1];
  return {length - (tx * dx + ty * dy), tx * dy - ty * dx};
}

double PathFollowerUnit::ToSharpCorner(const OnSegment& on) const {
  return sharp_corner_after_m_[active_segment_] + on.to_end_m;
}

PathFollowerUnit::Sample PathFollowerUnit::EvaluateDifferentialPath(
    const models::PolylinePoint& n) const {
  Sample s;
  const auto& goal = waypoints_m_.back();
  const double to_goal_m = std::hypot(position_[0] - goal[0], position_[1] - goal[1]);
  s.at_goal = done_latched_ || to_goal_m <= goal_tolerance_;
  if (!n.found) return s;
  s.progress_m = n.progress_m;
  s.cross_track_m = n.cross_track_m;
  if (s.at_goal) return s;
  const std::size_t i = active_segment_;
  const bool last = i + 2 == waypoints_m_.size();
  const OnSegment on = ProjectOnSegment(i);
  // The distance left: along the path, and on the last segment straight to
  // the goal (>= the distance along it: never 0 while the robot is beside
  // the goal, outside goal_tolerance).
  const double remaining = last ? on.to_end_m : length_m() - s.progress_m;
  const double left = last ? to_goal_m : std::abs(remaining);
  const double corner = ToSharpCorner(on);
  const double magnitude =
      std::min({ramp_mps_, speed_, std::sqrt(2.0 * acceleration_ * left), k_position_ * left,
                std::sqrt(2.0 * acceleration_ * std::max(corner, 0.0))});
  const double length = cumulative_m_[i + 1] - cumulative_m_[i];
  const double tx = (waypoints_m_[i + 1][0] - waypoints_m_[i][0]) / length;
  const double ty = (waypoints_m_[i + 1][1] - waypoints_m_[i][1]) / length;
  // a = t along - n k_cross e, n = (-ty, tx): along = sgn(r) speed, and on
  // the last segment within speed / k_cross of the goal along it, k_cross r,
  // so that a = k_cross (goal - p) points at the goal.
  double along = std::copysign(speed_, remaining);
  if (last && k_cross_ > 0.0 && k_cross_ * std::abs(remaining) < speed_) {
    along = k_cross_ * remaining;
  }
  const double aim_x = tx * along + ty * k_cross_ * on.cross_track_m;
  const double aim_y = ty * along - tx * k_cross_ * on.cross_track_m;
  const double h = models::WrapAngle(std::atan2(aim_y, aim_x) - yaw_measured_);
  s.yaw_rate_rad_s = std::clamp(k_yaw_ * h, -max_yaw_rate_, max_yaw_rate_);
  if (std::abs(h) > turn_in_place_angle_) return s;  // turn in place: the ramp starts again
  // The aim already points towards the goal (backwards along the path past
  // it): the robot drives forwards along it.
  const double cos_h = std::cos(h);
  s.along_mps = magnitude * cos_h;
  s.forward_mps = std::min(magnitude * cos_h, max_speed_);
  return s;
}

models::PolylinePoint PathFollowerUnit::FindNearest() const {
  if (mode_ != Mode::kPath) return {};
  // The end segments extend beyond the ends, so that progress runs below 0
  // before the start and past the length after the goal.
  return models::NearestOnPolyline(waypoints_m_, cumulative_m_, position_[0], position_[1],
                                   models::PolylineEnds::kExtend);
}

PathFollowerUnit::Sample PathFollowerUnit::Evaluate(const models::PolylinePoint& n) const {
  if (base_ == Base::kDifferential && mode_ == Mode::kPath) return EvaluateDifferentialPath(n);
  Sample s;
  const double x = position_[0], y = position_[1];
  if (mode_ == Mode::kHold) {
    const double ex = x - waypoints_m_[0][0], ey = y - waypoints_m_[0][1];
    s.vx_map_mps = -k_position_ * ex;
    s.vy_map_mps = -k_position_ * ey;
    s.cross_track_m = std::hypot(ex, ey);
    s.at_goal = s.cross_track_m <= goal_tolerance_;
  } else {
    if (n.found) {
      s.progress_m = n.progress_m;
      s.cross_track_m = n.cross_track_m;
      const double remaining = length_m() - s.progress_m;
      const double magnitude =
          std::min({ramp_mps_, speed_, std::sqrt(2.0 * acceleration_ * std::abs(remaining)),
                    k_position_ * std::abs(remaining)});
      s.along_mps = std::copysign(magnitude, remaining);
      s.vx_map_mps = n.tangent_x * s.along_mps + n.tangent_y * k_cross_ * n.cross_track_m;
      s.vy_map_mps = n.tangent_y * s.along_mps - n.tangent_x * k_cross_ * n.cross_track_m;
    }
    const auto& goal = waypoints_m_.back();
    s.at_goal = done_latched_ || std::hypot(x - goal[0], y - goal[1]) <= goal_tolerance_;
    if (s.at_goal) {
      s.vx_map_mps = s.vy_map_mps = s.along_mps = 0.0;
    }
  }
  if (base_ == Base::kDifferential) {  // hold mode: the path mode returned above
    SteerHold(s);
    return s;
  }
  const double speed = std::hypot(s.vx_map_mps, s.vy_map_mps);
  if (speed > max_speed_) {
    s.vx_map_mps *= max_speed_ / speed;
    s.vy_map_mps *= max_speed_ / speed;
  }
  if (!(mode_ == Mode::kPath && s.at_goal)) {
    s.yaw_rate_rad_s =
        std::clamp(k_yaw_ * models::WrapAngle(yaw_ - yaw_measured_), -max_yaw_rate_, max_yaw_rate_);
  }
  return s;
}

void PathFollowerUnit::SteerHold(Sample& s) const {
  // The hold law leaves the along-track speed at 0 (no ramp in hold).
  s.forward_mps = 0.0;
  s.yaw_rate_rad_s = 0.0;
  // Outside goal_tolerance (> 0) the velocity -k_position (p - p_ref) is
  // not zero (k_position > 0): it has a direction.
  if (s.at_goal) return;
  const double speed = std::hypot(s.vx_map_mps, s.vy_map_mps);
  double h = models::WrapAngle(std::atan2(s.vy_map_mps, s.vx_map_mps) - yaw_measured_);
  double direction = 1.0;
  // Backing up is as good as driving forward, and needs less turning when
  // the point is behind.
  if (std::abs(h) > 0.5 * std::numbers::pi) {
    h = models::WrapAngle(h - std::numbers::pi);
    direction = -1.0;
  }
  s.yaw_rate_rad_s = std::clamp(k_yaw_ * h, -max_yaw_rate_, max_yaw_rate_);
  if (std::abs(h) > turn_in_place_angle_) return;  // turn in place
  s.forward_mps = direction * std::min(speed * std::cos(h), max_speed_);
}

void PathFollowerUnit::ComputeOutputs(const models::PolylinePoint& n) {
  const Sample s = Evaluate(n);
  if (base_ == Base::kDifferential) {
    velocity_command_[0] = s.forward_mps;
    velocity_command_[1] = 0.0;
  } else {
    const double c = std::cos(yaw_measured_), sn = std::sin(yaw_measured_);
    velocity_command_[0] = c * s.vx_map_mps + sn * s.vy_map_mps;
    velocity_command_[1] = -sn * s.vx_map_mps + c * s.vy_map_mps;
  }
  yaw_rate_command_ = s.yaw_rate_rad_s;
  cross_track_error_ = s.cross_track_m;
  progress_ = s.progress_m;
  done_ = s.at_goal;
}

cosim::StepResult PathFollowerUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  // The position is the same before and after the commit: one search.
  const models::PolylinePoint n = FindNearest();
  const Sample s = Evaluate(n);
  // The ramp continues from the speed actually commanded, so that it also
  // restarts gently after a slow-down.
  ramp_mps_ = std::min(speed_, std::abs(s.along_mps) + acceleration_ * cosim::NsToSeconds(dt));
  if (mode_ == Mode::kPath && s.at_goal) done_latched_ = true;
  if (base_ == Base::kDifferential && mode_ == Mode::kPath) {
    // The rule on progress: the robot has reached the end of the active
    // segment (where the sqrt profile before a sharp corner ends; sampled,
    // it gets within acceleration T^2 in finite time), or the nearest path
    // point lies beyond it. Never back: no flipping between segments.
    const double reached = acceleration_ * cosim::NsToSeconds(dt) * cosim::NsToSeconds(dt);
    while (active_segment_ + 2 < waypoints_m_.size() &&
           (ProjectOnSegment(active_segment_).to_end_m <= reached ||
            (n.found && n.segment > active_segment_ &&
             n.progress_m > cumulative_m_[active_segment_ + 1]))) {
      ++active_segment_;
    }
  }
  ComputeOutputs(n);
  return cosim::StepResult::kOk;
}

bool PathFollowerUnit::SavesSegment() const {
  return base_ == Base::kDifferential && mode_ == Mode::kPath;
}

void PathFollowerUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals = {ramp_mps_};
  state.integers = {done_latched_ ? 1 : 0};
  if (SavesSegment()) state.integers.push_back(static_cast<std::int64_t>(active_segment_));
}

void PathFollowerUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t integers = SavesSegment() ? 2 : 1;
  if (state.reals.size() != 1 || state.integers.size() != integers) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected 1 and " + std::to_string(integers));
  }
  FindSharpCorners();  // restored into a unit not initialized since a parameter change
  ramp_mps_ = state.reals[0];
  done_latched_ = state.integers[0] != 0;
  if (SavesSegment()) {
    const std::int64_t segment = state.integers[1];
    if (segment < 0 || static_cast<std::size_t>(segment) + 1 >= waypoints_m_.size()) {
      throw cosim::UnitError(Where() + ": saved active segment " + std::to_string(segment) +
                             " is not a segment of the path");
    }
    active_segment_ = static_cast<std::size_t>(segment);
  }
}

}  // namespace linesim::control
