#include "units/control/route_follower_unit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "cosim/parameter_checks.h"
#include "models/angle.h"

namespace linesim::control {

namespace {
// A gap between the end of a segment and the start of the next that is
// still one path (rounding of hand-written coefficients): 1 mm.
constexpr double kJointTolerance = 1e-3;
}  // namespace

RouteFollowerUnit::RouteFollowerUnit(std::string name,
                                     std::vector<models::PolynomialSegment> segments)
    : cosim::Unit(kTypeName, std::move(name)),
      segments_(std::move(segments)),
      position_(2, 0.0),
      velocity_command_(2, 0.0) {
  auto& v = variables();
  using cosim::Rule;
  v.Parameter("speed", "m/s", &speed_,
              "the constant linear velocity V (paper 2 Eq. 5: \"the linear velocity is "
              "constant\"), but for the stop at the route's end",
              Rule::Positive());
  // Defaults: the linearised error dynamics on a straight path (e lateral
  // offset, psi heading error: e' = V psi, psi' = w) under Eqs. 12-13 are
  //   e''' + K_P,theta e'' + (V K_P,D + K_I,theta) e' + V K_I,D e = 0
  // (signed distance integral); without integral action a double pole at
  // 1.5 rad/s (critically damped: the offset decays without crossing the
  // path; a tenth of the Husky's wheel-rate loop, ~16 rad/s) gives
  // K_P,theta = 2 * 1.5 = 3 /s and K_P,D = 1.5^2 / V = 7.5 rad/(s m) at 0.3 m/s.
  v.Parameter("k_p_distance", "rad/(s.m)", &k_p_distance_,
              "K_P,D: yaw rate per metre of distance error (Eqs. 12-13)", Rule::NonNegative());
  v.Parameter("k_i_distance", "rad/(s2.m)", &k_i_distance_,
              "K_I,D: yaw rate per metre-second of integrated distance error (Eqs. 12-13)",
              Rule::NonNegative());
  v.Parameter("k_p_orientation", "1/s", &k_p_orientation_,
              "K_P,theta: yaw rate per radian of orientation error (Eqs. 12-13)",
              Rule::NonNegative());
  v.Parameter("k_i_orientation", "1/s2", &k_i_orientation_,
              "K_I,theta: yaw rate per radian-second of integrated orientation error",
              Rule::NonNegative());
  v.Parameter("distance_integral", &distance_integral_,
              "unsigned: integral of Err_D (>= 0), its term switched with T_theta as Eqs. 12-13 "
              "write it; signed: integral of the switched distance (+ path on the left)",
              Rule::OneOf({"unsigned", "signed"}));
  v.Parameter("max_distance_integral_rate", "rad/s", &max_distance_integral_rate_,
              "anti-windup: the distance integral is clamped so that |K_I,D I_D| <= this",
              Rule::NonNegative());
  v.Parameter("max_orientation_integral_rate", "rad/s", &max_orientation_integral_rate_,
              "anti-windup: the orientation integral is clamped so that |K_I,theta I_theta| <= "
              "this",
              Rule::NonNegative());
  v.Parameter("max_yaw_rate", "rad/s", &max_yaw_rate_, "limit on the commanded yaw rate",
              Rule::Positive());
  v.Parameter("deceleration", "m/s2", &deceleration_,
              "constant deceleration of the stop on the route's final point", Rule::Positive());
  v.Parameter("stop_tolerance", "m", &stop_tolerance_,
              "arc length left on the route counted as arrived (done)", Rule::Positive());
  v.Input("position", "m", &position_, "x, y of base_link in map");
  v.Input("yaw", "rad", &yaw_measured_, "heading of base_link in map");
  v.Output("velocity_command", "m/s", &velocity_command_,
           "body velocity command in base_link: V, 0", {"position", "yaw"});
  v.Output("yaw_rate_command", "rad/s", &yaw_rate_command_, "W (Eqs. 12-13 with Eq. 17)",
           {"position", "yaw"});
  v.Output("done", &done_, "the route's final point was reached (latched)", {"position"});
  v.Output("segment", &segment_out_, "index of the current segment (from 0)", {"position"});
  v.Output("map_index", &map_index_, "localization map of the current segment", {"position"});
  v.Output("distance_error", "m", &distance_error_, "Err_D (Eq. 6): distance to F(t_n), >= 0",
           {"position"});
  v.Output("cross_track_error", "m", &cross_track_error_,
           "Err_D signed by the side: + when the robot is left of the path", {"position"});
  v.Output("orientation_error", "rad", &orientation_error_,
           "Err_theta (Eq. 10): wrap(F_theta(t_n) - yaw)", {"position", "yaw"});
  v.Output("t", "1", &t_out_, "t_n: the closest parameter on the current segment", {"position"});
  MeasureSegments();
}

void RouteFollowerUnit::MeasureSegments() {
  length_after_m_.assign(segments_.size(), 0.0);
  double after = 0.0;
  for (std::size_t k = segments_.size(); k-- > 0;) {
    length_after_m_[k] = after;
    after += models::SegmentArcLength(segments_[k], 0.0, 1.0);
  }
}

std::vector<cosim::ParameterProblem> RouteFollowerUnit::CheckParameters() const {
  cosim::ParameterChecks c;
  if (segments_.empty()) c.Add({"segments", std::nullopt, "a route needs at least one segment"});
  for (std::size_t k = 0; k < segments_.size(); ++k) {
    const auto& s = segments_[k];
    bool good = true;
    for (const auto* coefficients : {&s.x, &s.y}) {
      const char* axis = coefficients == &s.x ? "x" : "y";
      if (coefficients->empty() || coefficients->size() > models::kMaxPolynomialCoefficients) {
        c.Add({"segments", k,
               std::string(axis) + " has " + std::to_string(coefficients->size()) +
                   " coefficients: expected 1 to " +
                   std::to_string(models::kMaxPolynomialCoefficients)});
        good = false;
      } else if (!std::all_of(coefficients->begin(), coefficients->end(),
                              [](double a) { return std::isfinite(a); })) {
        c.Add({"segments", k, std::string(axis) + " has a coefficient that is not finite"});
        good = false;
      }
    }
    if (s.map < 0) c.Add({"segments", k, "map must be >= 0, got " + std::to_string(s.map)});
    if (!good) continue;
    if (!(models::SegmentArcLength(s, 0.0, 1.0) > 0.0)) {
      c.Add({"segments", k, "has no length (F'(t) = 0): no tangent to follow"});
    }
    if (k > 0 && segments_[k - 1].x.size() <= models::kMaxPolynomialCoefficients &&
        segments_[k - 1].y.size() <= models::kMaxPolynomialCoefficients) {
      const auto end = models::SegmentPosition(segments_[k - 1], 1.0);
      const auto start = models::SegmentPosition(s, 0.0);
      const double gap = std::hypot(start[0] - end[0], start[1] - end[1]);
      if (gap > kJointTolerance) {
        c.Add({"segments", k,
               "starts " + cosim::FormatValue(std::round(gap * 1e6) / 1e6) +
                   " m from the end of the previous segment: a route is one path (at most 1 mm)"});
      }
    }
  }
  auto problems = c.Take();
  for (auto& p : Unit::CheckParameters()) problems.push_back(std::move(p));
  return problems;
}

void RouteFollowerUnit::Initialize() {
  ThrowIfBadParameters();
  MeasureSegments();
  segment_ = 0;
  distance_integral_value_ = 0.0;
  orientation_integral_value_ = 0.0;
  done_latched_ = false;
  ComputeOutputs(Evaluate());
}

RouteFollowerUnit::Sample RouteFollowerUnit::Evaluate() const {
  Sample s;
  if (segments_.empty()) return s;
  const double x = position_[0], y = position_[1];
  std::size_t k = std::min(segment_, segments_.size() - 1);
  double t = models::ClosestParameter(segments_[k], x, y);
  // Segment advance: the end of the current segment is its nearest point.
  while (t >= 1.0 && k + 1 < segments_.size()) {
    ++k;
    t = models::ClosestParameter(segments_[k], x, y);
  }
  s.segment = k;
  s.t = t;
  const models::SegmentPoint p = models::EvaluateSegment(segments_[k], t);
  const double ex = p.x - x, ey = p.y - y;
  s.distance = std::hypot(ex, ey);                                               // Eq. 6
  s.orientation = models::WrapAngle(models::SegmentHeading(p) - yaw_measured_);  // Eq. 10
  const double t_theta = models::WrapAngle(std::atan2(ey, ex) - yaw_measured_);  // Eq. 11
  s.side = t_theta > 0.0 ? 1.0 : -1.0;
  // Left of the path: the tangent turns counter-clockwise onto the robot.
  s.cross_track = std::copysign(s.distance, p.dx * (-ey) - p.dy * (-ex));
  if (s.distance == 0.0) s.cross_track = 0.0;

  // The stop: only near the end is the arc length left worth computing.
  const bool last = k + 1 == segments_.size();
  const double stopping_m = speed_ * speed_ / (2.0 * deceleration_);
  double remaining = std::numeric_limits<double>::infinity();
  if (length_after_m_.size() == segments_.size() && length_after_m_[k] <= stopping_m) {
    remaining = length_after_m_[k] + models::SegmentArcLength(segments_[k], t, 1.0);
  }
  s.at_goal = done_latched_ || (last && (t >= 1.0 || remaining <= stop_tolerance_));
  if (s.at_goal) return s;
  s.speed = std::min(speed_, std::sqrt(2.0 * deceleration_ * remaining));

  const double distance_term =
      SignedDistanceIntegral()
          ? s.side * k_p_distance_ * s.distance + k_i_distance_ * distance_integral_value_
          : s.side * (k_p_distance_ * s.distance + k_i_distance_ * distance_integral_value_);
  const double w = distance_term + k_p_orientation_ * s.orientation +
                   k_i_orientation_ * orientation_integral_value_ +
                   models::FeedForward(s.speed, p);  // Eqs. 12-13, 17
  s.saturated = !(std::abs(w) <= max_yaw_rate_);
  s.yaw_rate = std::clamp(w, -max_yaw_rate_, max_yaw_rate_);
  return s;
}

void RouteFollowerUnit::ComputeOutputs(const Sample& s) {
  velocity_command_[0] = s.at_goal ? 0.0 : s.speed;
  velocity_command_[1] = 0.0;
  yaw_rate_command_ = s.at_goal ? 0.0 : s.yaw_rate;
  done_ = s.at_goal;
  segment_out_ = static_cast<std::int64_t>(s.segment);
  map_index_ = segments_.empty() ? 0 : segments_[s.segment].map;
  distance_error_ = s.distance;
  cross_track_error_ = s.cross_track;
  orientation_error_ = s.orientation;
  t_out_ = s.t;
}

cosim::StepResult RouteFollowerUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  const Sample s = Evaluate();
  segment_ = s.segment;  // never back
  if (s.at_goal) {
    done_latched_ = true;
  } else if (!s.saturated) {
    const double dt_s = cosim::NsToSeconds(dt);
    // Clamped so that each integral term stays within its rate (a gain of
    // 0 keeps its integral at 0).
    if (k_i_distance_ > 0.0) {
      const double limit = max_distance_integral_rate_ / k_i_distance_;
      const bool is_signed = SignedDistanceIntegral();
      distance_integral_value_ =
          std::clamp(distance_integral_value_ + (is_signed ? s.side : 1.0) * s.distance * dt_s,
                     is_signed ? -limit : 0.0, limit);
    }
    if (k_i_orientation_ > 0.0) {
      const double limit = max_orientation_integral_rate_ / k_i_orientation_;
      orientation_integral_value_ =
          std::clamp(orientation_integral_value_ + s.orientation * dt_s, -limit, limit);
    }
  }
  ComputeOutputs(Evaluate());
  return cosim::StepResult::kOk;
}

void RouteFollowerUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals = {distance_integral_value_, orientation_integral_value_};
  state.integers = {static_cast<std::int64_t>(segment_), done_latched_ ? 1 : 0};
}

void RouteFollowerUnit::RestoreInternal(const cosim::UnitState& state) {
  if (state.reals.size() != 2 || state.integers.size() != 2) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected 2 and 2");
  }
  const std::int64_t segment = state.integers[0];
  if (segment < 0 || static_cast<std::size_t>(segment) >= segments_.size()) {
    throw cosim::UnitError(Where() + ": saved segment " + std::to_string(segment) +
                           " is not a segment of the route");
  }
  MeasureSegments();
  distance_integral_value_ = state.reals[0];
  orientation_integral_value_ = state.reals[1];
  segment_ = static_cast<std::size_t>(segment);
  done_latched_ = state.integers[1] != 0;
}

}  // namespace linesim::control
