#include "units/evaluation/final_pose_error.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "models/angle.h"

namespace linesim::evaluation {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

}  // namespace

FinalPoseErrorUnit::FinalPoseErrorUnit(std::string name)
    : cosim::Unit(kTypeName, std::move(name)) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  target_x_ = target_y_ = target_yaw_ = nan;
  using cosim::Rule;
  auto& v = variables();
  v.Parameter("target_x", "m", &target_x_, "the work pose in map, x", Rule::Required());
  v.Parameter("target_y", "m", &target_y_, "the work pose in map, y", Rule::Required());
  v.Parameter("target_yaw", "rad", &target_yaw_, "the work pose in map, yaw", Rule::Required());
  v.Parameter("settle_time", "s", &settle_time_,
              "the pose is taken this long after `done` (ASSUMPTION 2 s: the Husky's stop and "
              "its suspension's settling; with the beacons uncovered at `done` and their "
              "uncover_delay of 1 s, 50 LMS151 scans in their filter)",
              Rule::NonNegative());
  v.Parameter("fail_if_unmeasured", &fail_if_unmeasured_,
              "the step reaching the run's stop time fails when the final pose (or the "
              "beacons' pose) was never taken: the run's metrics are then missing, not 0");
  v.Parameter("beacons", &beacons_,
              "a beacon system measures the final pose too (its inputs are connected): "
              "without it only the true pose is required");
  v.Input("position", "m", &position_, "true x, y of base_link in map");
  v.Input("yaw", "rad", &yaw_, "true yaw of base_link");
  v.Input("beacon_position", "m", &beacon_position_,
          "x, y of base_link in map from the beacons (beacon_localization)");
  v.Input("beacon_yaw", "rad", &beacon_yaw_, "yaw from the beacons");
  v.Input("beacon_valid", &beacon_valid_, "the beacons' pose is valid");
  v.Input("done", &done_, "the follower finished its route (latched)");
  v.Output("error_x", "m", &error_x_, "true final x - target_x (0 until measured)", {});
  v.Output("error_y", "m", &error_y_, "true final y - target_y (0 until measured)", {});
  v.Output("error_yaw", "deg", &error_yaw_,
           "true final yaw - target_yaw, wrapped, in degrees (0 until measured)", {});
  v.Output("beacon_error_x", "m", &beacon_error_x_,
           "the beacons' final x - target_x (0 until measured)", {});
  v.Output("beacon_error_y", "m", &beacon_error_y_,
           "the beacons' final y - target_y (0 until measured)", {});
  v.Output("beacon_error_yaw", "deg", &beacon_error_yaw_,
           "the beacons' final yaw - target_yaw, wrapped, in degrees (0 until measured)", {});
  v.Output("beacon_self_error_position", "m", &beacon_self_error_position_,
           "distance between the beacons' and the true final position (0 until measured)", {});
  v.Output("beacon_self_error_x", "m", &beacon_self_error_x_,
           "the beacons' x - the true x at that time (0 until measured)", {});
  v.Output("beacon_self_error_y", "m", &beacon_self_error_y_,
           "the beacons' y - the true y at that time (0 until measured)", {});
  v.Output("beacon_self_error_yaw", "deg", &beacon_self_error_yaw_,
           "the beacons' yaw - the true yaw at that time, wrapped, in degrees (0 until "
           "measured)",
           {});
  v.Output("done_time", "s", &done_time_, "when `done` first read 1 (0 before)", {});
  v.Output("measured", &measured_, "the true final pose has been taken", {});
  v.Output("beacon_measured", &beacon_measured_, "the beacons' final pose has been taken", {});
}

void FinalPoseErrorUnit::Setup(cosim::TimeNs start, cosim::TimeNs stop) {
  start_ = start;
  stop_ = stop;
}

void FinalPoseErrorUnit::Initialize() {
  ThrowIfBadParameters();
  error_x_ = error_y_ = error_yaw_ = 0.0;
  beacon_error_x_ = beacon_error_y_ = beacon_error_yaw_ = 0.0;
  beacon_self_error_position_ = beacon_self_error_yaw_ = 0.0;
  beacon_self_error_x_ = beacon_self_error_y_ = 0.0;
  done_time_ = 0.0;
  measured_ = beacon_measured_ = false;
  seen_done_ = false;
  done_ns_ = 0;
}

cosim::StepResult FinalPoseErrorUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  // The inputs are those at t.
  if (done_ && !seen_done_) {
    seen_done_ = true;
    done_ns_ = t;
    done_time_ = cosim::NsToSeconds(t);
  }
  const bool settled = seen_done_ && t - done_ns_ >= cosim::SecondsToNs(settle_time_);
  if (settled && !measured_) {
    error_x_ = position_[0] - target_x_;
    error_y_ = position_[1] - target_y_;
    error_yaw_ = models::WrapAngle(yaw_ - target_yaw_) * kRadToDeg;
    measured_ = true;
  }
  if (settled && !beacon_measured_ && beacon_valid_) {
    beacon_error_x_ = beacon_position_[0] - target_x_;
    beacon_error_y_ = beacon_position_[1] - target_y_;
    beacon_error_yaw_ = models::WrapAngle(beacon_yaw_ - target_yaw_) * kRadToDeg;
    beacon_self_error_x_ = beacon_position_[0] - position_[0];
    beacon_self_error_y_ = beacon_position_[1] - position_[1];
    beacon_self_error_position_ = std::hypot(beacon_self_error_x_, beacon_self_error_y_);
    beacon_self_error_yaw_ = models::WrapAngle(beacon_yaw_ - yaw_) * kRadToDeg;
    beacon_measured_ = true;
  }
  if (fail_if_unmeasured_ && stop_ > start_ && t + dt >= stop_ &&
      (!measured_ || (beacons_ && !beacon_measured_))) {
    std::string why;
    if (!seen_done_) {
      why = "the route never finished (done never read 1)";
    } else if (!measured_) {
      why = "done came at " + cosim::FormatValue(done_time_) + " s, less than settle_time (" +
            cosim::FormatValue(settle_time_) + " s) before the end";
    } else {
      why = "the beacons never gave a valid pose after the robot settled";
    }
    return Fail("no final pose error: " + why +
                " (the metrics are missing; fail_if_unmeasured false keeps the run)");
  }
  return cosim::StepResult::kOk;
}

void FinalPoseErrorUnit::SaveInternal(cosim::UnitState& state) const {
  state.integers = {start_, stop_, seen_done_ ? 1 : 0, done_ns_};
  state.reals.clear();
}

void FinalPoseErrorUnit::RestoreInternal(const cosim::UnitState& state) {
  if (state.integers.size() != 4 || !state.reals.empty()) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected 0 and 4");
  }
  start_ = state.integers[0];
  stop_ = state.integers[1];
  seen_done_ = state.integers[2] != 0;
  done_ns_ = state.integers[3];
}

}  // namespace linesim::evaluation
