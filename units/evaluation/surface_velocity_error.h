#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cosim/unit.h"
#include "models/scene.h"

namespace linesim::evaluation {

/// How well downward optic-flow sensors see a belt (paper 1, Sec. VI-A and
/// Fig. 4): each sensor's raw measurement (the surface's velocity relative
/// to the sensor, in the sensor frame) is made absolute with the robot's
/// TRUE motion (paper 1 Eq. 2 with ground truth in place of the
/// localization, so that only the sensor's error remains):
///   v_surf = R(yaw + mount_yaw) v_meas + v_robot + yaw_rate ez x R(yaw) r_mount,
/// and its component along the belt's direction is compared with the belt's
/// ground-truth speed (`reference`, paper 1's encoder wheel on the belt).
/// Only sensors whose point lies over the belt (true pose, scene geometry)
/// are compared; `rmse` is the root mean square of the error over every
/// (sensor, step) pair compared so far.
///
/// What each sensor itself measures, for the plots: `reading`, its raw
/// measurement turned to map along the belt's direction (the surface
/// relative to the sensor's point), and `true_reading`, the same from
/// ground truth (the belt's reference speed where the point is over the
/// belt, 0 over the floor, less the point's true velocity along the belt).
///
/// With `estimated`, the unit also compares an estimator's absolute
/// surface velocity per sensor (map frame, e.g. the filtered value of
/// paper 1's Kalman filter) with the same reference over the same samples:
/// `estimated_speed` and `rmse_estimated`.
///
/// Plateaus and switches (issue 21, "the filter earns its place"): the
/// line is steadily on or off where the reference has not moved more than
/// switch_step away from where it last settled for plateau_delay; `rmse_plateau` and
/// `rmse_plateau_estimated` are the two root mean square errors over those
/// samples only; `rmse_plateau_on` and `rmse_plateau_on_estimated` over
/// those with the line on (the reference beyond switch_step: the device's
/// noise at speed, where its scale error shows). A switch starts where the reference starts
/// changing after a plateau (has moved switch_step); its settling time is the time from then to the
/// last sample, before the next switch, at which the belt's estimate (the mean of the sensors'
/// estimates over the belt: what the surface estimator gives the wheels on it) was more than
/// settle_tolerance off the reference while the reference was at a level (within switch_step / 2 of
/// where it last settled: the next switch's first samples are not this one's); `settling_time` is
/// the largest so far, `switches` their count. (Not each sensor's: with the device's measured
/// noise, 3 cm/s a message, a single filtered estimate leaves 2 cm/s now and then on a plateau, and
/// the time of its last excursion says nothing about the switch.)
class SurfaceVelocityErrorUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "surface_velocity_error";

  /// `sensors` >= 1; `belt` is the scene belt the reference measures;
  /// `estimated`: declare the estimate's input and outputs.
  SurfaceVelocityErrorUnit(std::string name, int sensors, const models::Belt& belt,
                           bool estimated = false);

  void Initialize() override;
  /// surface_speed, error and over_belt follow the inputs at once (they
  /// depend on them directly); rmse and samples move on in DoStep.
  void UpdateOutputs() override { Evaluate(); }
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  void Evaluate();
  void FinishSwitch();

  std::size_t sensors_;
  models::Rect belt_area_;
  double belt_x_, belt_y_;  // unit vector of the belt's direction

  // Parameters, one element per sensor.
  std::vector<double> mount_x_, mount_y_, mount_yaw_;
  // Inputs.
  std::vector<double> measured_;
  std::vector<double> estimated_;  // vx, vy per sensor in map (with `estimated`)
  std::vector<double> linear_velocity_ = std::vector<double>(2, 0.0);
  double yaw_ = 0.0, yaw_rate_ = 0.0, reference_ = 0.0;
  std::vector<double> position_ = std::vector<double>(2, 0.0);
  // Outputs.
  std::vector<double> surface_speed_, error_, over_belt_, estimated_speed_;
  std::vector<double> reading_, true_reading_;
  double rmse_ = 0.0, rmse_estimated_ = 0.0;
  // Sums of squared errors (raw, estimated) and the number of samples in them.
  double sum_squared_ = 0.0, sum_squared_estimated_ = 0.0;
  std::int64_t samples_ = 0;
  double samples_out_ = 0.0;
  // Plateaus and switches: parameters, state and outputs.
  double plateau_delay_ = 1.0, switch_step_ = 0.01, settle_tolerance_ = 0.02;
  double anchor_ = 0.0, last_t_ = 0.0, last_change_ = 0.0;
  bool have_last_ = false, in_switch_ = false, level_taken_ = false;
  double switch_start_ = 0.0, last_bad_ = -1.0, settling_max_ = 0.0;
  double plateau_sum_ = 0.0, plateau_sum_estimated_ = 0.0;
  std::int64_t plateau_samples_ = 0, switches_ = 0;
  // The plateaus with the line on (the reference beyond switch_step).
  double on_sum_ = 0.0, on_sum_estimated_ = 0.0, rmse_on_ = 0.0, rmse_on_estimated_ = 0.0;
  std::int64_t on_samples_ = 0;
  double rmse_plateau_ = 0.0, rmse_plateau_estimated_ = 0.0, settling_out_ = 0.0,
         switches_out_ = 0.0, plateau_samples_out_ = 0.0;
};

}  // namespace linesim::evaluation
