#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "models/scene.h"
#include "units/estimation/steady_state_kalman.h"

namespace linesim::estimation {

/// Surface-velocity estimation of paper 1 (Unhelkar et al., ICRA 2014),
/// Sec. IV-A: N PX4Flow optic-flow sensors (at the corners of the planform)
/// measure the surface under them; the estimated pose and the known line map
/// say which wheels and sensors are over which belt.
///
/// Per sensor i, at each NEW px4flow message (sensor_message_count changed):
///   raw_i = Eq. 2 in the map frame: the measurement (surface relative to
///   the sensor, sensor frame) turned to base_link by sensor_yaw and to map
///   by the robot's yaw, plus the robot's velocity at the sensor point
///   v + omega x r. Both terms are taken over the same window, the interval
///   since the previous message (the flow is integrated over it): the
///   sensor point's velocity is accumulated in the sensor frame every step,
///   and the sum is turned to map by the mean heading over the window. For a
///   robot that turns at omega while translating at |v| this removes the
///   |v| omega T / 2 error (7.5 mm/s at 0.3 m/s, 0.5 rad/s, T = 0.1 s) of
///   taking the robot's velocity and yaw at one instant.
///   filtered_i = SteadyStateKalman (x, y separately) of raw_i, in the map
///   frame, where a belt's velocity is constant; updated only from valid
///   messages of quality > 0.
///
/// Per wheel j (the paper's rule for a convex planform): the wheel point in
/// map from the estimated pose; over scene belt k it takes belt k's estimate,
/// the mean of the filtered values of the sensors the map puts over belt k
/// (the belt is rigid: one velocity); over the floor 0. The result is turned
/// to base_link with the estimated yaw (the controllers' input).
///
/// Fallbacks: see the status and source codes of the outputs, and the .cc.
///
/// No output depends directly on an input: the outputs after DoStep(t, dt)
/// come from the inputs set for t (one communication step of delay, 20 ms
/// at the control period, against messages 100 ms apart), so the unit adds
/// no algebraic loop to localization -> estimation -> control.
class SurfaceVelocityEstimator : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "surface_velocity_estimator";

  /// `sensors` PX4Flow sensors and `wheels` wheels (each >= 1, else
  /// cosim::UnitError); the belts are every belt of `scene` (none: every
  /// point is over the floor).
  SurfaceVelocityEstimator(std::string name, int sensors, int wheels, const models::Scene& scene);

  /// The declared rules, plus stale_after longer than one sample_period.
  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  int sensor_count() const { return static_cast<int>(n_); }
  int wheel_count() const { return static_cast<int>(w_); }
  const SteadyStateKalman& filter() const { return kf_; }

  /// Status codes (sensor_status).
  static constexpr int kFresh = 0, kHeld = 1, kNoEstimate = 2;
  /// Source codes (wheel_source).
  static constexpr int kFloor = 0, kFromFresh = 1, kFromHeld = 2, kBeltNoEstimate = 3;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  struct BeltArea {
    models::Rect area;
    double cos_dir, sin_dir;
  };
  /// 0 over the floor, k + 1 over scene belt k (the first that holds the
  /// point, as the px4flow and the chassis take it).
  int SurfaceAt(double x, double y) const;
  /// Mean filtered value (map) of the sensors whose filter belongs to
  /// `surface` (the one the map puts them over) and whose status is
  /// `status`, skipping those with any of the flags `skip` this step; false
  /// if there is none.
  bool SurfaceMean(int surface, int status, char skip, double& vx, double& vy) const;
  /// map_surface_ from the pose inputs (c, s: cos and sin of yaw).
  void MapSurfaces(double c, double s);
  /// Per-sensor outputs from the state, and the wheel outputs.
  void WriteOutputs(double c, double s);
  void Cache();
  void ResetState();

  std::size_t n_, w_;
  std::vector<BeltArea> belts_;

  // Parameters.
  std::vector<double> sensor_x_, sensor_y_, sensor_yaw_, wheel_x_, wheel_y_;
  double process_sigma_ = 0.01 / 3.0;
  double measurement_sigma_ = 0.03;
  double sample_period_ = 0.1;
  // ASSUMPTION (no source gives them): 1 s is about the filter's own time
  // constant at paper 1's figures, sample_period / -ln(1 - K) = 0.1 / 0.111
  // = 0.90 s, so a held value fades no faster than the filter would have
  // followed a real change (a line stopping: paper 1, Sec. II, factories
  // give no reliable on/off signal) and keeps a stopped belt's speed little
  // longer than the filter's lag would. stale_after = two of those (the held
  // value down to e^-2 = 14 %, 20 missed messages).
  double hold_time_constant_ = 1.0;
  double stale_after_ = 2.0;

  // Inputs.
  std::vector<double> sensor_velocity_, sensor_valid_, sensor_quality_, sensor_message_count_;
  std::vector<double> position_, velocity_;
  double yaw_ = 0.0, yaw_rate_ = 0.0;

  // Outputs.
  std::vector<double> raw_, filtered_, sensor_on_belt_, sensor_status_;
  std::vector<double> wheel_surface_velocity_, wheel_on_belt_, wheel_source_;
  double kalman_gain_ = 0.0;

  // Cached from the parameters (Cache).
  SteadyStateKalman kf_;
  std::vector<double> mount_cos_, mount_sin_;
  cosim::TimeNs sample_period_ns_ = 0, stale_after_ns_ = 0;
  // exp(-dt / hold_time_constant) for the last dt (a pure function of dt).
  cosim::TimeNs decay_dt_ = -1;
  double decay_factor_ = 1.0;

  // Internal state, per sensor.
  std::vector<double> x_;                  // filter state (map), 2 per sensor
  std::vector<std::int64_t> surface_;      // surface the filter belongs to; -1: none
  std::vector<std::int64_t> status_;       // kFresh, kHeld, kNoEstimate
  std::vector<double> last_count_;         // message count last seen
  std::vector<cosim::TimeNs> last_valid_;  // time of the last valid message (or restart)
  // Accumulated since the previous message: the sensor point's velocity in
  // the sensor frame times the step (m), the heading's unit vector times the
  // step (s), and the window (ns).
  std::vector<double> acc_vx_, acc_vy_, acc_c_, acc_s_;
  std::vector<cosim::TimeNs> acc_ns_;
  // Per sensor: the surface the map puts it over at the last step (saved:
  // an output is written from it), and scratch flags of this step.
  std::vector<std::int64_t> map_surface_;
  std::vector<char> flags_;

  cosim::TimeNs start_ = 0;
};

}  // namespace linesim::estimation
