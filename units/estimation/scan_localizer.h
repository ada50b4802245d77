#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::estimation {

/// What the scan-matching localizers (laser_localization,
/// perfect_match_localization) share around their matchers: the lasers'
/// parameters and inputs, the new scans in the order of their match times,
/// each scan's usable points in base_link (optionally deskewed), the start
/// pose (the last accepted match, moved by the odometry inputs with
/// motion_prediction odometry), laser_status 1 after scan_timeout, the
/// pose output (held or odometry-predicted without a fresh match) and the
/// state of all this. A unit adds its matcher in ProcessScan and declares
/// its variables through the Declare* helpers in its own order (the order
/// and texts `linesim inspect` prints are each unit's).
class ScanLocalizer : public cosim::Unit {
 public:
  static constexpr int kMaxLasers = 8;

  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  int laser_count() const { return static_cast<int>(beam_counts_.size()); }

 protected:
  struct Pose {
    double x = 0.0, y = 0.0, yaw = 0.0;
  };
  /// Wraps a heading; each unit keeps its own convention (hector's range is
  /// [-pi, pi], the Perfect Match unit's (-pi, pi]) so results stay the same.
  using AngleWrap = double (*)(double);

  /// One entry of `beam_counts` per laser (1..kMaxLasers lasers, each
  /// 1..100000 beams); throws cosim::UnitError otherwise. Sizes every
  /// per-laser vector; declares nothing.
  ScanLocalizer(const char* type_name, std::string name, std::vector<int> beam_counts,
                AngleWrap wrap_angle);

  // Declaring the shared variables, a run at a time (texts that differ
  // between the units are arguments).
  void DeclareMountXY();
  void DeclareBeamGeometry(const char* mount_yaw_description);
  void DeclareRangeLimits(const char* range_min_description,
                          const char* usable_range_max_description);
  void DeclareStartPose(cosim::Rule rule, const char* x_description, const char* y_description,
                        const char* yaw_description);
  void DeclareMotionPrediction(const char* prediction_description, const char* deskew_description,
                               const char* timeout_description);
  void DeclareJumpLimits(const char* max_jump_description, const char* max_jump_yaw_description);
  void DeclareMinPoints();
  void DeclareCovarianceFloorPosition(const char* description);
  void DeclareCovarianceFloorYaw();
  /// ranges_k, scan_count_k, scan_time_k of laser k.
  void DeclareScanInputs(std::size_t k);
  void DeclareOdometryInputs();
  /// position, yaw.
  void DeclarePoseOutputs();
  /// covariance, hessian, match_time, match_count.
  void DeclareMatchOutputs(const char* covariance_description, const char* hessian_description);

  /// Matches laser k's current scan, whose pose refers to `match_ns`
  /// (called by DoStep per new scan, in the order of their match times).
  virtual void ProcessScan(int k, cosim::TimeNs match_ns) = 0;

  /// The beams' directions and times, and motion_prediction, from the
  /// parameters.
  void DeriveBeams();
  /// The tracking state and the shared outputs at the initial pose.
  void InitializeTracking();
  /// `p` moved by the odometry inputs over `seconds` (may be < 0).
  Pose Predict(const Pose& p, double seconds) const;
  /// The base's attitude for a scan: each beam's point, put at (mount_x,
  /// mount_y, mount_z) + r (cos, sin, 0) in base_link, is turned by
  /// Ry(pitch) Rx(roll) (ROS REP 103: + pitch lowers the nose, + roll
  /// lowers the right side) into the frame of base_link's yaw alone; a
  /// point lower than min_z there (m, relative to base_link's origin) is
  /// dropped, the others keep their horizontal part.
  struct Tilt {
    double pitch = 0.0, roll = 0.0;
    double mount_z = 0.0;
    double min_z = 0.0;
  };
  /// Laser k's returns in [range_min, usable_range_max] as points in
  /// base_link (px_, py_; their count), each range less `range_offset`;
  /// with `tilt`, projected into the map's plane and the low ones dropped
  /// (their number in dropped_low_; the kept ones' heights above base_link's
  /// origin in pz_); with `deskew` moved from the beam's
  /// time to the match time by the base_link twist (vx, vy, w).
  std::size_t CollectPoints(int k, double range_offset, bool deskew, double vx, double vy, double w,
                            const Tilt* tilt = nullptr);
  /// Where a match at `match_ns` starts.
  Pose MatchStart(cosim::TimeNs match_ns) const;
  /// Within max_jump and max_jump_yaw of `start`.
  bool WithinJumpLimits(double x, double y, double yaw, const Pose& start) const;
  /// The new estimate: the tracking state, match_time and match_count.
  void AcceptMatch(const Pose& matched, cosim::TimeNs match_ns);
  /// The covariance floors added to covariance_'s diagonal.
  void AddCovarianceFloors();
  void SetStatus(int k, int status) { laser_status_[static_cast<std::size_t>(k)] = status; }

  /// The tracking state into `state` (integers and reals first; a unit
  /// appends its own after).
  void SaveTracking(cosim::UnitState& state) const;
  /// The tracking state from `state`, whose sizes the unit has checked
  /// (at least tracking_integers() and tracking_reals()).
  void RestoreTracking(const cosim::UnitState& state);
  /// The state sizes SaveTracking writes.
  std::size_t tracking_integers() const { return 4 + beam_counts_.size(); }
  std::size_t tracking_reals() const { return 6 + beam_counts_.size(); }

  std::vector<int> beam_counts_;
  AngleWrap wrap_angle_;

  // Parameters (lists: one element per laser).
  std::vector<double> mount_x_, mount_y_, mount_yaw_, first_beam_angle_, angular_step_,
      scan_period_;
  double range_min_ = 0.0, usable_range_max_ = 0.0;
  double initial_x_, initial_y_, initial_yaw_;
  std::string motion_prediction_ = "none";
  bool deskew_ = false;
  double scan_timeout_ = 0.2;
  std::int64_t min_points_ = 0;
  double max_jump_ = 0.3, max_jump_yaw_ = 0.3;
  double covariance_floor_position_ = 0.0, covariance_floor_yaw_ = 0.0;

  // Inputs.
  std::vector<std::vector<double>> ranges_;
  std::vector<double> scan_count_, scan_time_;
  std::vector<double> odometry_velocity_;
  double odometry_yaw_rate_ = 0.0;
  /// Factors on the odometry's vx and vy in Predict: a wheel's travel on a
  /// slope is longer than its projection on the map (cos pitch, cos roll;
  /// 1 on the level, set by a unit that knows the attitude).
  double odometry_scale_x_ = 1.0, odometry_scale_y_ = 1.0;

  // Outputs.
  std::vector<double> position_, covariance_, hessian_, laser_status_;
  double yaw_ = 0.0, match_time_ = 0.0, match_count_ = 0.0, source_ = 1.0;

  // Derived: per laser and beam, cos and sin of the beam's direction in
  // base_link and its time after the scan's start.
  std::vector<std::vector<double>> beam_cos_, beam_sin_, beam_dt_;
  std::vector<cosim::TimeNs> mid_offset_ns_;  // the match time after the scan's start
  bool odometry_prediction_ = false;

  // Scratch (sized in the constructor): the points of one scan.
  std::vector<double> px_, py_, pz_;
  std::vector<int> order_;
  std::size_t dropped_low_ = 0;  // the last CollectPoints' points below Tilt::min_z

  // State.
  cosim::TimeNs start_ = 0;
  std::vector<double> last_count_;
  std::vector<cosim::TimeNs> last_scan_ns_;  // the last new scan's start, per laser
  Pose estimate_;                            // the latest accepted match (or the initial pose)
  cosim::TimeNs estimate_ns_ = 0;            // its time
  bool have_match_ = false;
  Pose odom_;  // estimate_ moved by odometry up to odom_ns_
  cosim::TimeNs odom_ns_ = 0;
};

}  // namespace linesim::estimation
