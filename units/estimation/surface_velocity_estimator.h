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
/// State switches (SwitchDetector in steady_state_kalman.h): the line runs
/// in only two states, on and off (paper 1 Sec. II), and the filter's
/// random walk models only the variation within one; a start or stop (a
/// ramp of about 1 s) would lag by the fixed gain's time constant,
/// sample_period / -ln(1 - K) = 0.9 s. Each innovation nu = raw - x (per
/// map component) is compared with switch_gate sqrt(S), S = P- + r of the
/// same Riccati solution (3.17 cm/s at paper 1's figures); switch_samples
/// consecutive innovations beyond it on the same side restart the sensor's
/// filter from that measurement, after which it goes on with the steady
/// gain (switch_count counts the restarts). Per component, not the 2D
/// normalized innovation squared: the filters are two independent scalar
/// ones with the same S, and the sign of a run is what tells a change of
/// the mean from noise, which the squared norm throws away (a belt at 45
/// deg to the map axes is seen at 0.71 of its change in each component).
/// Defaults switch_gate 2.5, switch_samples 3, from these numbers at
/// paper 1's figures (K = 0.1051, sqrt(S) = 3.17 cm/s, 10 Hz):
///  - false alarms: a run of 3 beyond 2.5 sigma on one side ends at a given
///    message with probability Q(2.5)^3 = 2.4e-7 on white innovations;
///    2 sides x 2 components: <= 9.6e-7 per message, one false restart per
///    >= 29 h per sensor (2.5 sigma and 2 samples: one per 11 min; 2 sigma
///    and 3: one per 35 min; 2 sigma and 4: 26 h but a step is followed a
///    message later);
///  - a 0 -> 0.2 m/s step (6.3 sigma): the innovations 0.2 (1 - K)^(n - 1)
///    stay beyond the gate (0.079 m/s) for 9 messages; the filter restarts
///    at the step's 3rd message, 0.2 to 0.3 s after it (the fixed gain: 2 s
///    to within 10 %);
///  - a 0 -> 0.2 m/s ramp over 1 s (0.02 m/s per message): the innovation
///    0.02 (1 - (1 - K)^n) / K passes the gate at the ramp's 5th message and
///    the filter restarts at its 7th; the estimate is at most 0.103 m/s
///    behind the truth at a message (the innovation that restarts it; the
///    fixed gain: 0.128 m/s, at the ramp's end), and the ramp's last three
///    messages leave innovations under the gate (no second restart).
/// switch_gate 0 turns the detector off: paper 1's filter alone, bit for
/// bit.
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
  const SwitchDetector& switch_detector() const { return detector_; }

  /// Status codes (sensor_status).
  static constexpr int kFresh = 0, kHeld = 1, kNoEstimate = 2;
  /// Source codes (wheel_source).
  static constexpr int kFloor = 0, kFromFresh = 1, kFromHeld = 2, kBeltNoEstimate = 3;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  /// The robot's velocity relative to `surface` at base_link point (px, py)
  /// in base_link by the encoders of the wheels the map puts over it
  /// (wheel_map_surface_; the yaw rate: the localization's, a belt does not
  /// turn); false when none is.
  bool RelativeAt(std::int64_t surface, double px, double py, double& vx, double& vy) const;
  /// Mean filtered value (map) of the sensors whose filter belongs to
  /// `surface` (the one the map puts them over) and whose status is
  /// `status`, skipping those with any of the flags `skip` this step; false
  /// if there is none.
  bool SurfaceMean(int surface, int status, char skip, double& vx, double& vy) const;
  /// map_surface_ and wheel_map_surface_ from the pose inputs (c, s: cos
  /// and sin of yaw).
  void MapSurfaces(double c, double s);
  /// Per-sensor outputs from the state, and the wheel outputs.
  void WriteOutputs(double c, double s);
  void Cache();
  void ResetState();

  std::size_t n_, w_;
  models::BeltMap belts_;  // 0 over the floor, k + 1 over scene belt k

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
  // The state-switch detector (see the class comment for the numbers).
  double switch_gate_ = 2.5;
  std::int64_t switch_samples_ = 3;
  // The encoders' check of each message (in measurement sigmas; 0: off).
  double odometry_gate_ = 0.0;

  // Inputs.
  std::vector<double> sensor_velocity_, sensor_valid_, sensor_quality_, sensor_message_count_;
  std::vector<double> position_, velocity_;
  double yaw_ = 0.0, yaw_rate_ = 0.0;
  std::vector<double> odometry_wheel_velocity_;

  // Outputs.
  std::vector<double> raw_, filtered_, sensor_on_belt_, sensor_status_;
  std::vector<double> wheel_surface_velocity_, wheel_on_belt_, wheel_source_;
  std::vector<double> switch_count_, implausible_count_;
  double kalman_gain_ = 0.0;

  // Cached from the parameters (Cache).
  SteadyStateKalman kf_;
  SwitchDetector detector_;
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
  std::vector<cosim::TimeNs> entered_;     // when the map last moved it to another surface
  // Accumulated since the previous message: the sensor point's velocity in
  // the sensor frame times the step (m), the heading's unit vector times the
  // step (s), and the window (ns).
  std::vector<double> acc_vx_, acc_vy_, acc_c_, acc_s_;
  std::vector<cosim::TimeNs> acc_ns_;
  // The same window: the sensor point's velocity relative to the surface
  // under the wheels by the encoders, in the sensor frame, times the step.
  std::vector<double> acc_ox_, acc_oy_;
  std::vector<cosim::TimeNs> acc_checked_ns_;  // the part of the window they cover
  std::vector<std::int64_t> implausible_;      // messages the encoders refuted
  // The switch detector's signed run per component (2 per sensor), and the
  // restarts it made per sensor.
  std::vector<std::int64_t> run_, switches_;
  // Per sensor: the surface the map puts it over at the last step (saved:
  // an output is written from it), and scratch flags of this step.
  std::vector<std::int64_t> map_surface_;
  // The same for each wheel (scratch: from the pose each step).
  std::vector<std::int64_t> wheel_map_surface_;
  std::vector<char> flags_;

  cosim::TimeNs start_ = 0;
};

}  // namespace linesim::estimation
