#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::evaluation {

/// Paper 2's final pose error (Sobreira et al. 2019, Sec. 6, Table 1): once
/// the robot has stopped at the end of its route, its pose against the
/// work pose (target_x, target_y, target_yaw), from the truth and from the
/// beacon-based ground truth system, and that system's own error against
/// the truth.
///
/// Taken once: at the first communication point at least settle_time after
/// `done` first read 1 (the follower latches it at the route's end), from
/// the inputs at that point; the beacon errors at the first such point at
/// which `beacon_valid` is 1 (the beacons may need a few scans after they
/// are uncovered). Signed errors are measured - target in the map frame,
/// yaw wrapped to (-180, 180] deg; the beacon's own error is the distance
/// between its and the true position, and its yaw - the true yaw.
///
/// Never taken (the route never finished, or finished less than
/// settle_time before the run's end, or the beacons never gave a valid
/// pose): the outputs stay 0 with `measured` / `beacon_measured` 0, and with
/// fail_if_unmeasured (default) the step that reaches the run's stop time
/// fails naming what is missing. The run is then `failed` and a sweep
/// reports its metrics as missing (empty), never as a 0 error: the
/// master refuses non-finite outputs, so a NaN cannot carry "missing" here.
class FinalPoseErrorUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "final_pose_error";

  explicit FinalPoseErrorUnit(std::string name);

  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  // Parameters.
  double target_x_, target_y_, target_yaw_;
  double settle_time_ = 2.0;
  bool fail_if_unmeasured_ = true;
  bool beacons_ = true;
  // Inputs.
  std::vector<double> position_ = std::vector<double>(2, 0.0);
  std::vector<double> beacon_position_ = std::vector<double>(2, 0.0);
  double yaw_ = 0.0, beacon_yaw_ = 0.0;
  bool beacon_valid_ = false, done_ = false;
  // Outputs.
  double error_x_ = 0.0, error_y_ = 0.0, error_yaw_ = 0.0;
  double beacon_error_x_ = 0.0, beacon_error_y_ = 0.0, beacon_error_yaw_ = 0.0;
  double beacon_self_error_position_ = 0.0, beacon_self_error_yaw_ = 0.0;
  double beacon_self_error_x_ = 0.0, beacon_self_error_y_ = 0.0;
  double done_time_ = 0.0;
  bool measured_ = false, beacon_measured_ = false;
  // State.
  cosim::TimeNs start_ = 0, stop_ = 0;
  bool seen_done_ = false;
  cosim::TimeNs done_ns_ = 0;
};

}  // namespace linesim::evaluation
