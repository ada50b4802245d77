#include "units/people/worker_unit.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "models/moving_solids.h"

namespace linesim::people {

WorkerUnit::WorkerUnit(std::string name, std::vector<std::array<double, 2>> waypoints_m,
                       int robots)
    : cosim::Unit(kTypeName, std::move(name)), waypoints_(std::move(waypoints_m)) {
  if (robots < 0) throw cosim::UnitError(Where() + ": robots must be >= 0");
  if (waypoints_.empty()) throw cosim::UnitError(Where() + ": needs at least one waypoint");
  pause_s_.assign(waypoints_.size(), 0.0);
  pose_.assign(3, 0.0);
  velocity_.assign(2, 0.0);
  legs_.assign(4, 0.0);
  leg_velocities_.assign(4, 0.0);
  cylinders_.assign(kCylinders * kCylinderValues, 0.0);
  using cosim::Rule;
  auto& v = variables();
  v.Parameter("pause", "s", &pause_s_,
              "how long the worker stands at each waypoint after arriving (the first: "
              "ignored, see start_time)",
              Rule::NonNegative());
  v.Parameter("start_time", "s", &start_time_s_, "when the worker leaves waypoint 0",
              Rule::NonNegative());
  // Perry & Burnfield, Gait Analysis (2nd ed., 2010), ch. 1: free walking of
  // adults, 82 m/min (1.37 m/s), stride length 1.41 m, cadence 113
  // steps/min; stance 60 % of the gait cycle, swing 40 %.
  v.Parameter("walking_speed", "m/s", &speed_,
              "walking speed (1.37 m/s: adults' free walking, Perry & Burnfield 2010)",
              Rule::Positive());
  // Brenière & Do (1986), J. Biomech. 19(12): steady walking speed is reached
  // by the end of the first step (about 1 s from quiet standing): ~1 m/s^2.
  v.Parameter("acceleration", "m/s2", &acceleration_,
              "acceleration and deceleration of the speed profile (steady speed within the "
              "first step, about 1 s: Breniere & Do 1986)",
              Rule::Positive());
  v.Parameter("stride_length", "m", &stride_length_,
              "two steps (1.41 m: Perry & Burnfield 2010)", Rule::Positive());
  v.Parameter("stance_fraction", "1", &stance_fraction_,
              "fraction of a stride a foot is on the floor (0.6: Perry & Burnfield 2010)",
              Rule::Range(0.0, false, 1.0, false));
  v.Parameter("initial_phase", "1", &initial_phase_,
              "the left leg's gait phase at the start (strides; 0: start of its stance)",
              Rule::Finite());
  // The body's defaults and their sources: models/person.h.
  v.Parameter("leg_radius", "m", &leg_radius_,
              "radius of a leg's section at a scanner's height (lower shank: ANSUR 1988)",
              Rule::Positive());
  v.Parameter("leg_spacing", "m", &leg_spacing_,
              "distance between the legs' axes across the heading (DIN 33402-2 hip breadth)",
              Rule::Positive());
  v.Parameter("crotch_height", "m", &crotch_height_,
              "top of the legs, bottom of the torso (0.84 m: DIN 33402-2)", Rule::Positive());
  v.Parameter("torso_radius", "m", &torso_radius_,
              "radius of the torso's cylinder (shoulder breadth / 2: DIN 33402-2)",
              Rule::Positive());
  v.Parameter("stature", "m", &stature_, "body height (1.75 m: DIN 33402-2)", Rule::Positive());
  v.Parameter("initial_yaw", "deg", &initial_yaw_deg_,
              "heading of a worker with one waypoint (more: the first segment's)",
              Rule::Finite());
  if (robots > 0) {
    robots_.assign(models::MovingBox::kValues * static_cast<std::size_t>(robots), 0.0);
    // Hall (1966), The Hidden Dimension: personal distance begins at 0.45 m;
    // 0 by default (see the class comment).
    v.Parameter("stop_distance", "m", &stop_distance_,
                "the worker waits while walking on would bring the torso closer than this to a "
                "moving robot's body (e.g. 0.5 m: Hall 1966's personal distance); 0: never",
                Rule::NonNegative());
    v.Input("robots", "m, rad, m/s, rad/s", &robots_,
            "the robots' bodies (chassis body_box: [x, y, yaw, vx, vy, yaw_rate, length, width, "
            "z_bottom, z_top] in map), one after another");
  }
  v.Output("pose", "m, m, rad", &pose_, "[x, y, yaw] of the body centre (map)", {});
  v.Output("velocity", "m/s", &velocity_, "[vx, vy] (map)", {});
  v.Output("speed", "m/s", &speed_out_, "walking speed", {});
  v.Output("distance", "m", &distance_out_, "distance walked since the start", {});
  v.Output("phase", "1", &phase_out_, "the left leg's gait phase (strides)", {});
  v.Output("legs", "m", &legs_, "[x_left, y_left, x_right, y_right] (map)", {});
  v.Output("leg_velocities", "m/s", &leg_velocities_,
           "[vx_left, vy_left, vx_right, vy_right] (map)", {});
  v.Output("cylinders", "m, m/s", &cylinders_,
           "per cylinder (left leg, right leg, torso) [x, y, vx, vy, radius, z_bottom, z_top]",
           {});
  if (robots > 0) {
    v.Output("waiting", &waiting_, "true while the worker waits for a robot", {});
    v.Output("time_waited", "s", &waited_s_, "time spent waiting for robots so far", {});
  }
}

std::vector<cosim::ParameterProblem> WorkerUnit::CheckParameters() const {
  auto problems = cosim::Unit::CheckParameters();
  if (crotch_height_ >= stature_) {
    problems.push_back({"crotch_height", std::nullopt, "must be below stature"});
  }
  for (std::size_t k = 1; k < waypoints_.size(); ++k) {
    if (waypoints_[k][0] == waypoints_[k - 1][0] && waypoints_[k][1] == waypoints_[k - 1][1]) {
      problems.push_back({"waypoints", k, "repeats the waypoint before it"});
    }
  }
  return problems;
}

void WorkerUnit::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void WorkerUnit::Plan() {
  plan_.clear();
  double t = start_time_s_, cum = 0.0;
  for (std::size_t k = 0; k + 1 < waypoints_.size(); ++k) {
    Segment s{};
    const double dx = waypoints_[k + 1][0] - waypoints_[k][0];
    const double dy = waypoints_[k + 1][1] - waypoints_[k][1];
    s.length_m = std::hypot(dx, dy);
    s.ux = dx / s.length_m;
    s.uy = dy / s.length_m;
    // Trapezoid, or a triangle when the ramps alone cover the segment.
    s.cruise_mps = std::min(speed_, std::sqrt(acceleration_ * s.length_m));
    s.ramp_s = s.cruise_mps / acceleration_;
    s.duration_s = 2.0 * s.ramp_s + (s.length_m - s.cruise_mps * s.ramp_s) / s.cruise_mps;
    s.start_s = t;
    s.cum_m = cum;
    plan_.push_back(s);
    t += s.duration_s + pause_s_[k + 1];
    cum += s.length_m;
  }
}

WorkerUnit::State WorkerUnit::At(double t_s) const {
  State st;
  st.x_m = waypoints_[0][0];
  st.y_m = waypoints_[0][1];
  for (std::size_t k = 0; k < plan_.size(); ++k) {
    const Segment& s = plan_[k];
    if (t_s < s.start_s) break;
    st.segment = k;
    const double tau = t_s - s.start_s;
    double d = s.length_m;
    double v = 0.0, dv = 0.0;
    if (tau < s.ramp_s) {
      dv = acceleration_;
      d = 0.5 * acceleration_ * tau * tau;
      v = acceleration_ * tau;
    } else if (tau < s.duration_s - s.ramp_s) {
      d = 0.5 * s.cruise_mps * s.ramp_s + s.cruise_mps * (tau - s.ramp_s);
      v = s.cruise_mps;
    } else if (tau < s.duration_s) {
      const double left = s.duration_s - tau;
      dv = -acceleration_;
      d = s.length_m - 0.5 * acceleration_ * left * left;
      v = acceleration_ * left;
    }
    st.distance_m = s.cum_m + d;
    st.speed_mps = v;
    st.acceleration_mps2 = dv;
    st.cruise_mps = s.cruise_mps;
    st.x_m = waypoints_[k][0] + s.ux * d;
    st.y_m = waypoints_[k][1] + s.uy * d;
  }
  return st;
}

void WorkerUnit::LegOffset(double phase, double& offset_m, double& rate) const {
  const double f = phase - std::floor(phase);
  const double stance = stance_fraction_;
  if (f < stance) {
    // On the floor: the body passes over it.
    offset_m = stride_length_ * (0.5 * stance - f);
    rate = -1.0;
    return;
  }
  // Swing: back to +stance/2 along a half cosine.
  const double u = (f - stance) / (1.0 - stance);
  const double c = 0.5 * (1.0 - std::cos(std::numbers::pi * u));
  offset_m = stride_length_ * (-0.5 * stance + stance * c);
  rate = stance * 0.5 * std::numbers::pi * std::sin(std::numbers::pi * u) / (1.0 - stance);
}

void WorkerUnit::Evaluate(double t_s) {
  const State st = At(t_s);
  double ux = std::cos(initial_yaw_deg_ * std::numbers::pi / 180.0);
  double uy = std::sin(initial_yaw_deg_ * std::numbers::pi / 180.0);
  if (!plan_.empty()) {
    ux = plan_[st.segment].ux;
    uy = plan_[st.segment].uy;
  }
  const double nx = -uy, ny = ux;  // left
  pose_ = {st.x_m, st.y_m, std::atan2(uy, ux)};
  velocity_ = {st.speed_mps * ux, st.speed_mps * uy};
  speed_out_ = st.speed_mps;
  distance_out_ = st.distance_m;
  phase_out_ = initial_phase_ + st.distance_m / stride_length_;
  // The steps' length follows the speed over the segment's cruise speed
  // (w): full strides while cruising, the feet side by side standing.
  const double w = st.cruise_mps > 0.0 ? st.speed_mps / st.cruise_mps : 0.0;
  const double dw = st.cruise_mps > 0.0 ? st.acceleration_mps2 / st.cruise_mps : 0.0;
  for (int leg = 0; leg < 2; ++leg) {
    double offset = 0.0, rate = 0.0;
    LegOffset(phase_out_ - 0.5 * leg, offset, rate);
    const double side = leg == 0 ? 0.5 * leg_spacing_ : -0.5 * leg_spacing_;
    const std::size_t i = 2 * static_cast<std::size_t>(leg);
    legs_[i] = st.x_m + ux * w * offset + nx * side;
    legs_[i + 1] = st.y_m + uy * w * offset + ny * side;
    // d (w offset) / dt = w rate speed + w' offset; while cruising a stance
    // foot is still (rate -1).
    const double along = st.speed_mps * (1.0 + w * rate) + dw * offset;
    leg_velocities_[i] = along * ux;
    leg_velocities_[i + 1] = along * uy;
  }
  const auto put = [&](int c, double x, double y, double vx, double vy, double r, double z0,
                       double z1) {
    double* p = cylinders_.data() + c * kCylinderValues;
    p[0] = x, p[1] = y, p[2] = vx, p[3] = vy, p[4] = r, p[5] = z0, p[6] = z1;
  };
  put(0, legs_[0], legs_[1], leg_velocities_[0], leg_velocities_[1], leg_radius_, 0.0,
      crotch_height_);
  put(1, legs_[2], legs_[3], leg_velocities_[2], leg_velocities_[3], leg_radius_, 0.0,
      crotch_height_);
  put(2, st.x_m, st.y_m, velocity_[0], velocity_[1], torso_radius_, crotch_height_, stature_);
}

void WorkerUnit::Initialize() {
  ThrowIfBadParameters();
  Plan();
  waited_ = 0;
  waited_s_ = 0.0;
  waiting_ = false;
  Evaluate(0.0);
}

bool WorkerUnit::Blocked(double t0_s, double t1_s) const {
  using models::MovingBox;
  if (stop_distance_ <= 0.0) return false;
  const State now = At(t0_s), next = At(t1_s);
  if (next.x_m == now.x_m && next.y_m == now.y_m) return false;  // standing anyway
  for (std::size_t k = 0; k + MovingBox::kValues <= robots_.size(); k += MovingBox::kValues) {
    const double* box = robots_.data() + k;
    if (!(box[MovingBox::kLength] > 0.0 && box[MovingBox::kWidth] > 0.0)) continue;  // absent
    if (std::hypot(box[MovingBox::kVx], box[MovingBox::kVy]) <= 0.05) continue;  // not moving
    const double d_next = models::FootprintDistance(box, next.x_m, next.y_m) - torso_radius_;
    if (d_next >= stop_distance_) continue;
    if (d_next < models::FootprintDistance(box, now.x_m, now.y_m) - torso_radius_) return true;
  }
  return false;
}

cosim::StepResult WorkerUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  if (robots_.empty()) {
    // Without robots the clock is the time (the same numbers as always).
    Evaluate(cosim::NsToSeconds(t + dt - start_));
    return cosim::StepResult::kOk;
  }
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  waiting_ = Blocked(cosim::NsToSeconds(t - start_ - waited_),
                     cosim::NsToSeconds(t + dt - start_ - waited_));
  if (waiting_) waited_ += dt;
  waited_s_ = cosim::NsToSeconds(waited_);
  Evaluate(cosim::NsToSeconds(t + dt - start_ - waited_));
  if (waiting_) {
    // Standing where the plan left off: nothing moves.
    velocity_ = {0.0, 0.0};
    speed_out_ = 0.0;
    std::fill(leg_velocities_.begin(), leg_velocities_.end(), 0.0);
    for (int c = 0; c < kCylinders; ++c) {
      cylinders_[static_cast<std::size_t>(c * kCylinderValues + 2)] = 0.0;
      cylinders_[static_cast<std::size_t>(c * kCylinderValues + 3)] = 0.0;
    }
  }
  return cosim::StepResult::kOk;
}

void WorkerUnit::SaveInternal(cosim::UnitState& state) const {
  state.integers = {waited_, waiting_ ? 1 : 0};
}

void WorkerUnit::RestoreInternal(const cosim::UnitState& state) {
  Plan();
  if (state.integers.size() != 2) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.integers.size()) +
                           " integers, expected 2");
  }
  waited_ = state.integers[0];
  waited_s_ = cosim::NsToSeconds(waited_);
  waiting_ = state.integers[1] != 0;
}

}  // namespace linesim::people
