#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::estimation {

/// Wheel odometry from incremental encoder counts, with paper 1's Eq. 3
/// rectification, and dead reckoning of the pose.
///
/// Kinds (structural key `kind`, wheel count `wheels` = W):
///  - swerve (Rob@Work 3): 2W channels, 0..W-1 the steering joints, W..2W-1
///    the drive joints (the chassis' and wheel controller's conventions:
///    steering angle 0 rolls along base_link +x, + counter-clockwise; drive
///    rate + rolls forward along the heading). Per wheel the contact
///    velocity v_i = r w_i (cos a_i, sin a_i); the body twist (vx, vy, omega)
///    is the least-squares solution of v_i = (vx - omega y_i, vy + omega x_i)
///    over all wheels (paper 1 Eq. 1 inverted; the general form of the
///    means and pairs of IPA's undercarriage odometry). The steering angle
///    of a count c is the middle of its count, (c + 1/2) 2 pi / cpr (a
///    decoder's floor leaves the angle anywhere in the count: half a count
///    of error at most instead of a whole one), and the heading over the
///    interval is the mean of the angles at its two ends (the drive counts
///    accumulate along the heading as it turns).
///  - differential (Husky): 2 channels, the left and right drive motor (the
///    base reports one travel per side); v = r (wl + wr) / 2,
///    omega = r (wr - wl) / effective_track (a skid-steer turns slower than
///    its wheels say: the effective track is the robot file's).
/// w is the count difference since the previous sample times 2 pi / cpr over
/// the actual time between the two samples (0 at the first sample).
///
/// Paper 1 Eq. 3 (`rectify`, default on): a wheel's encoder velocity is
/// relative to the surface under it; the absolute surface velocity under it
/// (input `surface_velocity`, base_link, the surface estimator's
/// wheel_surface_velocity) is added before the twist is solved, so dead
/// reckoning stays right on a moving floor. Differential: per side, the mean
/// surface velocity of that side's wheels (sides from the sign of wheel_y)
/// is added to the side's velocity (x: along the body; y: the side is
/// carried sideways), then vx = mean of the sides' x, vy = mean of their y,
/// omega = (right x - left x) / effective_track (the contact balance that
/// gives the effective track sees the surface's velocity like a rim's).
///
/// Sampling (like the wheel encoder it reads): UpdateOutputs computes the
/// sample of the current communication point from the counts there (direct
/// feedthrough), DoStep(t, dt) commits that sample whatever inputs arrive
/// since. Dead reckoning integrates the twist of each interval along the
/// exact arc of a constant twist from the pose at the previous sample
/// (initial_x, initial_y, initial_yaw at the start).
class WheelOdometryUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "wheel_odometry";
  enum class Kind { kSwerve, kDifferential };

  /// Throws cosim::UnitError if wheels < 2 (a twist needs two wheels).
  WheelOdometryUnit(std::string name, Kind kind, int wheels);

  /// The declared rules, and: swerve wheels not all at one point;
  /// differential wheels each off the centre line (wheel_y != 0), at least
  /// one per side.
  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  /// Validates the parameters, takes the current counts as the first
  /// sample (no rate yet) at the initial pose. Idempotent.
  void Initialize() override;
  /// The sample of the current communication point from the current counts
  /// and surface velocity; the committed state is not changed.
  void UpdateOutputs() override;
  /// Commits the sample taken at t.
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  Kind kind() const { return kind_; }
  int wheels() const { return wheels_; }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
  /// The least-squares map from the interleaved wheel velocities to the
  /// twist (swerve), and each wheel's side (differential).
  void Precompute();
  /// Twist (vx, vy, omega) from the stacked wheel velocities (swerve: 2W
  /// interleaved; differential: left x, left y, right x, right y).
  void Solve(const double* wheel_velocity, double twist[3]) const;
  /// The sample at now_ from the current inputs into outputs and pending_*.
  void ComputeSample();

  Kind kind_;
  int wheels_;
  std::size_t channels_;

  // Parameters.
  std::vector<double> wheel_x_, wheel_y_;
  double wheel_radius_ = kUnset;
  std::vector<double> counts_per_revolution_;
  double effective_track_ = kUnset;
  bool rectify_ = true;
  double initial_x_ = kUnset, initial_y_ = kUnset, initial_yaw_ = kUnset;

  // Inputs.
  std::vector<double> counts_, surface_velocity_;

  // Outputs.
  std::vector<double> body_velocity_, raw_body_velocity_, position_, velocity_;
  std::vector<double> wheel_velocity_;  // per wheel, from the encoders alone
  double yaw_rate_ = 0.0, raw_yaw_rate_ = 0.0, yaw_ = 0.0;

  // Derived in Precompute (from parameters only): the 3 x 2W least-squares
  // map, row-major (swerve); per wheel its side, 0 left, 1 right, and the
  // wheel count per side (differential).
  std::vector<double> solve_;
  std::vector<int> side_;
  int side_count_[2] = {0, 0};

  // Committed sample (the previous one): counts, time, pose; `has_previous_`
  // false before the first DoStep (no interval yet).
  std::vector<std::int64_t> committed_counts_;
  cosim::TimeNs committed_time_ = 0;
  double committed_pose_[3] = {0.0, 0.0, 0.0};
  bool has_previous_ = false;
  // The sample of the current communication point (ComputeSample), which
  // DoStep commits.
  std::vector<std::int64_t> pending_counts_;
  double pending_pose_[3] = {0.0, 0.0, 0.0};
  // The current communication point.
  cosim::TimeNs now_ = 0;
  cosim::TimeNs start_ = 0;

  // Scratch of ComputeSample (not state): wheel velocities.
  std::vector<double> scratch_raw_, scratch_surface_;
};

}  // namespace linesim::estimation
