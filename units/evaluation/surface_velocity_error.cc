#include "units/evaluation/surface_velocity_error.h"

#include <cmath>
#include <utility>

namespace linesim::evaluation {

SurfaceVelocityErrorUnit::SurfaceVelocityErrorUnit(std::string name, int sensors,
                                                   const models::Belt& belt, bool estimated)
    : cosim::Unit(kTypeName, std::move(name)),
      sensors_(static_cast<std::size_t>(sensors)),
      belt_area_(belt.area),
      belt_x_(std::cos(belt.area.direction_rad)),
      belt_y_(std::sin(belt.area.direction_rad)) {
  if (sensors < 1) {
    throw cosim::UnitError(Where() + ": sensors must be at least 1, got " +
                           std::to_string(sensors));
  }
  const std::size_t n = sensors_;
  mount_x_.assign(n, std::nan(""));
  mount_y_.assign(n, std::nan(""));
  mount_yaw_.assign(n, std::nan(""));
  measured_.assign(2 * n, 0.0);
  surface_speed_.assign(n, 0.0);
  error_.assign(n, 0.0);
  over_belt_.assign(n, 0.0);

  auto& v = variables();
  v.Parameter("mount_x", "m", &mount_x_, "each sensor's x in base_link",
              cosim::Rule::Finite().NoDefault());
  v.Parameter("mount_y", "m", &mount_y_, "each sensor's y in base_link",
              cosim::Rule::Finite().NoDefault());
  v.Parameter("mount_yaw", "rad", &mount_yaw_,
              "each sensor frame's heading relative to base_link x",
              cosim::Rule::Finite().NoDefault());
  v.Input("measured", "m/s", &measured_,
          "each sensor's raw surface velocity relative to it, in its frame: vx, vy per sensor");
  v.Input("position", "m", &position_, "true x, y of base_link in map");
  v.Input("yaw", "rad", &yaw_, "true yaw of base_link");
  v.Input("linear_velocity", "m/s", &linear_velocity_, "true vx, vy of base_link in map");
  v.Input("yaw_rate", "rad/s", &yaw_rate_, "true yaw rate of base_link");
  v.Input("reference", "m/s", &reference_, "the belt's ground-truth speed along its direction");
  v.Output("surface_speed", "m/s", &surface_speed_,
           "each sensor's absolute surface velocity (Eq. 2, true robot motion) along the belt",
           {"measured", "position", "yaw", "linear_velocity", "yaw_rate"});
  v.Output("error", "m/s", &error_,
           "surface_speed - reference for each sensor over the belt; 0 for the others",
           {"measured", "position", "yaw", "linear_velocity", "yaw_rate", "reference"});
  v.Output("over_belt", "1", &over_belt_, "1 where the sensor's point is over the belt",
           {"position", "yaw"});
  v.Output("rmse", "m/s", &rmse_,
           "root mean square of the error over every sensor and step compared so far", {});
  v.Output("samples", "1", &samples_out_, "how many (sensor, step) pairs rmse holds", {});
  if (estimated) {
    estimated_.assign(2 * n, 0.0);
    estimated_speed_.assign(n, 0.0);
    v.Input("estimated", "m/s", &estimated_,
            "an estimator's absolute surface velocity at each sensor, in map: vx, vy per sensor");
    v.Output("estimated_speed", "m/s", &estimated_speed_,
             "each sensor's estimated absolute surface velocity along the belt", {"estimated"});
    v.Output("rmse_estimated", "m/s", &rmse_estimated_,
             "root mean square of estimated_speed - reference over the samples rmse holds", {});
  }
}

void SurfaceVelocityErrorUnit::Evaluate() {
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  const double bx = belt_x_, by = belt_y_;
  for (std::size_t k = 0; k < sensors_; ++k) {
    // The sensor's point in map and its velocity (v + omega x r).
    const double rx = c * mount_x_[k] - s * mount_y_[k];
    const double ry = s * mount_x_[k] + c * mount_y_[k];
    const double px = position_[0] + rx, py = position_[1] + ry;
    const double vx = linear_velocity_[0] - yaw_rate_ * ry;
    const double vy = linear_velocity_[1] + yaw_rate_ * rx;
    const double a = yaw_ + mount_yaw_[k];
    const double ca = std::cos(a), sa = std::sin(a);
    const double mx = measured_[2 * k], my = measured_[2 * k + 1];
    const double ux = ca * mx - sa * my + vx;
    const double uy = sa * mx + ca * my + vy;
    surface_speed_[k] = ux * bx + uy * by;
    const bool over = models::InsideRect(belt_area_, bx, by, px, py);
    over_belt_[k] = over ? 1.0 : 0.0;
    error_[k] = over ? surface_speed_[k] - reference_ : 0.0;
    if (!estimated_.empty()) {
      estimated_speed_[k] = estimated_[2 * k] * bx + estimated_[2 * k + 1] * by;
    }
  }
}

void SurfaceVelocityErrorUnit::Initialize() {
  ThrowIfBadParameters();
  sum_squared_ = sum_squared_estimated_ = 0.0;
  samples_ = 0;
  samples_out_ = 0.0;
  rmse_ = rmse_estimated_ = 0.0;
  Evaluate();
}

cosim::StepResult SurfaceVelocityErrorUnit::DoStep(cosim::TimeNs t, cosim::TimeNs) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  // The inputs are those at the step's start: compare them, then count.
  Evaluate();
  for (std::size_t k = 0; k < sensors_; ++k) {
    if (over_belt_[k] == 0.0) continue;
    sum_squared_ += error_[k] * error_[k];
    if (!estimated_.empty()) {
      const double e = estimated_speed_[k] - reference_;
      sum_squared_estimated_ += e * e;
    }
    ++samples_;
  }
  samples_out_ = static_cast<double>(samples_);
  const double n = static_cast<double>(samples_);
  rmse_ = samples_ > 0 ? std::sqrt(sum_squared_ / n) : 0.0;
  rmse_estimated_ = samples_ > 0 ? std::sqrt(sum_squared_estimated_ / n) : 0.0;
  return cosim::StepResult::kOk;
}

void SurfaceVelocityErrorUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals = {sum_squared_, sum_squared_estimated_};
  state.integers = {samples_};
}

void SurfaceVelocityErrorUnit::RestoreInternal(const cosim::UnitState& state) {
  if (state.reals.size() != 2 || state.integers.size() != 1) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected 2 and 1");
  }
  sum_squared_ = state.reals[0];
  sum_squared_estimated_ = state.reals[1];
  samples_ = state.integers[0];
}

}  // namespace linesim::evaluation
