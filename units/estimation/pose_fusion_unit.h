#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::estimation {

/// Fusion of wheel odometry (or odometry and a gyro) with the laser
/// localization's scan matches: an extended Kalman filter on
///   x = [px, py, theta, bx, by]
/// (base_link in map, and b, a map-frame velocity offset of the odometry
/// modelled as a random walk: what the odometry misses, such as surface
/// motion not rectified (paper 1 Eq. 3 with no or a late surface estimate)
/// or slip).
///
/// Why b: paper 1's Eq. 2 needs the robot's ABSOLUTE velocity, and wheel
/// odometry measures the velocity relative to the surface under the wheels.
/// The laser sees the robot's absolute pose; with b in the state, the
/// matches anchor the velocity estimate R(theta) v_odo + b to the map, so a
/// surface estimate built on it does not merely random-walk.
///
/// Prediction, once per step over [t, t + dt] with the inputs held:
///   p     += R(theta) arc(v_odo, omega, dt) + b dt   (exact arc of a
///                                                     constant twist)
///   theta += omega dt,  b unchanged,
/// omega the odometry's yaw rate, or the IMU's z rate with
/// yaw_rate_source = imu, and v_odo's x times cos(base_pitch), its y times
/// cos(base_roll): on a slope a wheel's travel is longer than its
/// projection on the map (2.07 m of ramp for 2.0 m of map at 15 deg; the
/// attitude from whoever knows it, e.g. perfect_match_localization's
/// attitude terrain; 0, level, when not connected). Process noise (continuous white noise,
/// integrated over the step): velocity_noise^2 dt on each position
/// coordinate, yaw_rate_noise^2 dt on theta, offset_random_walk^2 dt on each
/// of b.
///
/// Correction, when match_count changes: z = (x, y, yaw) of the match with
/// covariance R = match_covariance (symmetrised), its diagonal raised to the
/// floors. The match refers to match_time, up to tens of ms in the past
/// (0.3 m/s x 40 ms = 12 mm of lag otherwise): the filter keeps a ring
/// buffer of its states, covariances and inputs (kHistory steps, allocated
/// once), predicts from the last buffered state at or before match_time to
/// match_time, corrects there, and re-runs the predictions of the later
/// steps to now. A match is refused when its Mahalanobis distance
/// y^T S^-1 y exceeds `gate` (chi-square, 3 degrees of freedom), when it is
/// older than the buffer, or older than the last match applied (out of
/// order: replaying from before it would drop that match).
///
/// `source`: 0 while the last accepted match is at most `timeout` old
/// (fused), 1 otherwise (odometry only: before the first accepted match,
/// or the laser blacked out or its matches are refused).
class PoseFusionUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "pose_fusion";
  /// Steps kept for delayed matches: 256 steps cover 256 ms at a 1 ms step
  /// and 5 s at the 20 ms control period.
  static constexpr std::size_t kHistory = 256;

  PoseFusionUnit(std::string name);

  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  /// Validates the parameters; the state at the initial pose with b = 0 and
  /// the initial covariance. Idempotent.
  void Initialize() override;
  /// Predicts to t + dt with the inputs at t, then applies a new match.
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();

  /// One step of the filter: the state and covariance at time t, and the
  /// inputs (body velocity, yaw rate) of the step that ended at t.
  /// (Plain arrays, column-major for P, so that Eigen stays private to
  /// the .cc.)
  struct Entry {
    cosim::TimeNs t = 0;
    double x[5] = {};
    double p[25] = {};
    double vx = 0.0, vy = 0.0, omega = 0.0;
  };

  /// Predicts x, P (5 and 25 column-major) over dt_s with the inputs.
  void Predict(double* x, double* p, double vx, double vy, double omega, double dt_s) const;
  /// Whether the match (z, column-major covariance r) passes the gate at
  /// (x, P); if so corrects them.
  bool Correct(double* x, double* p, const double z[3], const double r[9]) const;
  /// Restarts the pose from a match (its covariance; the offset's kept, its
  /// variance back to the initial one).
  void Reset(double* x, double* p, const double z[3], const double r[9]) const;
  /// Applies the match at `time` through the history; false if refused.
  /// `reset`: restart from the match instead of correcting with it.
  bool ApplyMatch(cosim::TimeNs time, bool reset = false);
  Entry& At(std::size_t k) { return history_[(first_ + k) % kHistory]; }
  const Entry& At(std::size_t k) const { return history_[(first_ + k) % kHistory]; }
  void Push(const Entry& e);
  void ComputeOutputs();

  // Parameters.
  std::string yaw_rate_source_ = "odometry";
  double velocity_noise_ = 0.02;
  double yaw_rate_noise_ = 0.01;
  double offset_random_walk_ = 0.1;
  double initial_position_sigma_ = 0.1;
  double initial_yaw_sigma_ = 0.1;
  double initial_offset_sigma_ = 0.1;
  double position_floor_ = 0.01;
  double yaw_floor_ = 0.005;
  double gate_ = 16.27;
  double timeout_ = 0.5;
  double initial_x_ = kUnset, initial_y_ = kUnset, initial_yaw_ = kUnset;

  // Inputs.
  std::vector<double> odometry_velocity_;
  double odometry_yaw_rate_ = 0.0;
  double base_pitch_ = 0.0, base_roll_ = 0.0;
  std::vector<double> imu_angular_velocity_;
  std::vector<double> match_position_;
  double match_yaw_ = 0.0;
  std::vector<double> match_covariance_;
  double match_time_ = 0.0;
  double match_count_ = 0.0;

  // Outputs.
  std::vector<double> position_, velocity_, velocity_offset_, covariance_;
  double yaw_ = 0.0, yaw_rate_ = 0.0, source_ = 1.0;
  double rejected_matches_ = 0.0, accepted_matches_ = 0.0, resets_ = 0.0;

  // State. The history (oldest first from first_, size_ entries; the
  // newest is the current estimate), the last match_count seen, the time of
  // the last applied match (kNoMatch before any).
  static constexpr cosim::TimeNs kNoMatch = std::numeric_limits<cosim::TimeNs>::min();
  std::array<Entry, kHistory> history_;
  std::size_t first_ = 0, size_ = 0;
  double last_match_count_ = 0.0;
  cosim::TimeNs last_match_time_ = kNoMatch;
  bool use_imu_ = false;
  cosim::TimeNs start_ = 0;
};

}  // namespace linesim::estimation
