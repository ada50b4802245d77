#include "units/estimation/surface_velocity_estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace linesim::estimation {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Flags of a sensor within one step (scratch).
constexpr char kMoved = 1;     // the map moved it to another surface this step
constexpr char kMeasured = 2;  // a new valid message of quality > 0 this step
constexpr char kStarted = 4;   // its filter (re)started this step

}  // namespace

SurfaceVelocityEstimator::SurfaceVelocityEstimator(std::string name, int sensors, int wheels,
                                                   const models::Scene& scene)
    : cosim::Unit(kTypeName, std::move(name)) {
  if (sensors < 1 || wheels < 1) {
    throw cosim::UnitError(Where() + ": needs at least 1 sensor and 1 wheel, got " +
                           std::to_string(sensors) + " sensors and " + std::to_string(wheels) +
                           " wheels");
  }
  n_ = static_cast<std::size_t>(sensors);
  w_ = static_cast<std::size_t>(wheels);
  belts_ = models::BeltMap(scene.belts);

  sensor_x_.assign(n_, kNaN);
  sensor_y_.assign(n_, kNaN);
  sensor_yaw_.assign(n_, kNaN);
  wheel_x_.assign(w_, kNaN);
  wheel_y_.assign(w_, kNaN);
  sensor_velocity_.assign(2 * n_, 0.0);
  sensor_valid_.assign(n_, 0.0);
  sensor_quality_.assign(n_, 0.0);
  sensor_message_count_.assign(n_, 0.0);
  position_.assign(2, 0.0);
  velocity_.assign(2, 0.0);
  raw_.assign(2 * n_, 0.0);
  filtered_.assign(2 * n_, 0.0);
  sensor_on_belt_.assign(n_, 0.0);
  sensor_status_.assign(n_, kNoEstimate);
  wheel_surface_velocity_.assign(2 * w_, 0.0);
  wheel_map_surface_.assign(w_, 0);
  odometry_wheel_velocity_.assign(2 * w_, 0.0);
  wheel_on_belt_.assign(w_, 0.0);
  wheel_source_.assign(w_, kFloor);

  mount_cos_.assign(n_, 1.0);
  mount_sin_.assign(n_, 0.0);
  x_.assign(2 * n_, 0.0);
  surface_.assign(n_, -1);
  status_.assign(n_, kNoEstimate);
  last_count_.assign(n_, 0.0);
  last_valid_.assign(n_, 0);
  entered_.assign(n_, 0);
  acc_vx_.assign(n_, 0.0);
  acc_ox_.assign(n_, 0.0);
  acc_checked_ns_.assign(n_, 0);
  acc_oy_.assign(n_, 0.0);
  implausible_.assign(n_, 0);
  implausible_count_.assign(n_, 0.0);
  acc_vy_.assign(n_, 0.0);
  acc_c_.assign(n_, 0.0);
  acc_s_.assign(n_, 0.0);
  acc_ns_.assign(n_, 0);
  run_.assign(2 * n_, 0);
  switches_.assign(n_, 0);
  switch_count_.assign(n_, 0.0);
  map_surface_.assign(n_, 0);
  flags_.assign(n_, 0);

  using cosim::Rule;
  auto& v = variables();
  v.Parameter("sensor_x", "m", &sensor_x_, "x of each PX4Flow in base_link (one per sensor)",
              Rule::Finite().NoDefault());
  v.Parameter("sensor_y", "m", &sensor_y_, "y of each PX4Flow in base_link (one per sensor)",
              Rule::Finite().NoDefault());
  v.Parameter("sensor_yaw", "rad", &sensor_yaw_,
              "each PX4Flow's x axis relative to base_link x, counter-clockwise (the px4flow's "
              "mount_yaw; one per sensor)",
              Rule::Finite().NoDefault());
  v.Parameter("wheel_x", "m", &wheel_x_,
              "x of each wheel's contact point in base_link (one per wheel)",
              Rule::Finite().NoDefault());
  v.Parameter("wheel_y", "m", &wheel_y_,
              "y of each wheel's contact point in base_link (one per wheel)",
              Rule::Finite().NoDefault());
  v.Parameter("process_sigma", "m/s", &process_sigma_,
              "standard deviation of the surface velocity's random walk per sample (paper 1: "
              "3 sigma = 1 cm/s)",
              Rule::Positive());
  v.Parameter("measurement_sigma", "m/s", &measurement_sigma_,
              "standard deviation of one PX4Flow velocity measurement (paper 1: 3 cm/s)",
              Rule::Positive());
  v.Parameter("sample_period", "s", &sample_period_,
              "PX4Flow message period: the sample the Riccati equation is solved at (px4flow "
              "publish_rate 10 Hz); a valid message overdue by half of it more holds the sensor",
              Rule::Range(1e-4, 10.0));
  v.Parameter("hold_time_constant", "s", &hold_time_constant_,
              "time constant of the decay toward 0 of a held value (a sensor without valid "
              "messages); default 1 s, about the filter's own time constant (ASSUMPTION)",
              Rule::Positive());
  v.Parameter("stale_after", "s", &stale_after_,
              "a sensor without a valid message for this long gives no estimate (default 2 "
              "hold time constants: ASSUMPTION)",
              Rule::Positive());
  v.Parameter("switch_gate", "1", &switch_gate_,
              "state-switch detector: the gate on each innovation (z - x, per map component) in "
              "steady-state innovation sigmas sqrt(P- + r); 0 turns the detector off (paper 1's "
              "filter alone). Default 2.5: with switch_samples 3 at most 4 Q(2.5)^3 = 9.6e-7 "
              "false restarts per message on the filter's own noise model (one per 29 h per "
              "sensor at 10 Hz), while a 0.2 m/s step is followed at its 3rd message",
              Rule::Range(0.0, 100.0));
  v.Parameter("switch_samples", &switch_samples_,
              "state-switch detector: this many consecutive innovations beyond the gate on the "
              "same side restart the sensor's filter from its latest measurement",
              Rule::Range(1, 100));
  v.Parameter("odometry_gate", "1", &odometry_gate_,
              "the encoders' check of each message, in measurement sigmas: the sensor must read "
              "minus the robot's motion relative to the surface under it at its point, which the "
              "encoders of the wheels the map puts over the same surface measure; a message "
              "farther off than odometry_gate x measurement_sigma is refused as implausible (a "
              "dark image: the firmware matches noise and keeps its quality). 0 (default): off, "
              "odometry_wheel_velocity unused",
              Rule::NonNegative());

  v.Input("sensor_velocity", "m/s", &sensor_velocity_,
          "each PX4Flow's velocity output: the surface relative to the sensor, sensor frame, vx "
          "vy per sensor");
  v.Input("sensor_valid", "1", &sensor_valid_,
          "each PX4Flow's valid output (1: velocity from the last message)");
  v.Input("sensor_quality", "1", &sensor_quality_, "each PX4Flow's quality output (0..255)");
  v.Input("sensor_message_count", "1", &sensor_message_count_,
          "each PX4Flow's message_count output (a change: a new message)");
  v.Input("position", "m", &position_, "estimated x, y of base_link in map");
  v.Input("yaw", "rad", &yaw_, "estimated yaw of base_link in map");
  v.Input("velocity", "m/s", &velocity_, "estimated vx, vy of base_link's origin in map");
  v.Input("yaw_rate", "rad/s", &yaw_rate_, "estimated yaw rate of base_link");
  v.Input("odometry_wheel_velocity", "m/s", &odometry_wheel_velocity_,
          "each wheel's velocity relative to the surface under it by its encoders, base_link, "
          "vx vy per wheel (the wheel odometry's wheel_velocity): for odometry_gate");

  v.Output("raw_surface_velocity", "m/s", &raw_,
           "per sensor, map frame, vx vy: paper 1 Eq. 2 at its last valid message (the "
           "measurement turned to map plus the robot's velocity at the sensor point, both over "
           "the message's window), unfiltered; 0 before the first",
           {});
  v.Output("filtered_surface_velocity", "m/s", &filtered_,
           "per sensor, map frame, vx vy: its steady-state Kalman filter (a held value decays "
           "toward 0); 0 when sensor_status is 2",
           {});
  v.Output("sensor_on_belt", "1", &sensor_on_belt_,
           "per sensor, by the estimated pose and the line map: 0 over the floor, k+1 over "
           "scene belt k",
           {});
  v.Output("sensor_status", "1", &sensor_status_,
           "per sensor: 0 fresh (valid messages), 1 held and decaying (its last message "
           "invalid or of quality 0, or a valid one overdue), 2 no estimate (none since the "
           "start or since the map moved it to another surface, or none valid for "
           "stale_after)",
           {});
  v.Output("wheel_surface_velocity", "m/s", &wheel_surface_velocity_,
           "per wheel, base_link, vx vy: the ABSOLUTE velocity of the surface under the wheel "
           "(0 over the floor)",
           {});
  v.Output("wheel_on_belt", "1", &wheel_on_belt_,
           "per wheel, by the estimated pose and the line map: 0 over the floor, k+1 over scene "
           "belt k",
           {});
  v.Output("wheel_source", "1", &wheel_source_,
           "per wheel: 0 floor by the map (0), 1 mean of the fresh sensors over its belt, 2 "
           "mean of the held sensors over its belt (no fresh one), 3 over a belt no sensor "
           "estimates (gives 0)",
           {});
  v.Output("switch_count", "1", &switch_count_,
           "per sensor: restarts of its filter by the state-switch detector since the start "
           "(the surface under it switched on or off, or sped up or slowed down beyond the "
           "gate)",
           {});
  v.Output("implausible_count", "1", &implausible_count_,
           "per sensor: messages refused by the encoders' check (odometry_gate) so far", {});
  v.Output("kalman_gain", "1", &kalman_gain_,
           "the steady-state gain K solved from process_sigma^2 and measurement_sigma^2", {});
}

std::vector<cosim::ParameterProblem> SurfaceVelocityEstimator::CheckParameters() const {
  auto problems = cosim::Unit::CheckParameters();
  // A sensor is held once a valid message is overdue by half a period
  // (1.5 sample_period); going stale before that would skip the hold.
  if (std::isfinite(stale_after_) && std::isfinite(sample_period_) &&
      stale_after_ <= 1.5 * sample_period_) {
    problems.push_back({"stale_after", std::nullopt,
                        "must exceed 1.5 sample_period (" +
                            cosim::FormatValue(1.5 * sample_period_) + " s), got " +
                            cosim::FormatValue(stale_after_)});
  }
  return problems;
}

void SurfaceVelocityEstimator::Cache() {
  // The gain is solved from the variances per sample (one PX4Flow message
  // every sample_period), never typed in.
  kf_ = SteadyStateKalman(process_sigma_ * process_sigma_, measurement_sigma_ * measurement_sigma_);
  kalman_gain_ = kf_.gain();
  // The gate is in sigmas of the innovation of the same Riccati solution.
  detector_ = SwitchDetector(switch_gate_, switch_samples_, kf_.innovation_variance());
  for (std::size_t i = 0; i < n_; ++i) {
    mount_cos_[i] = std::cos(sensor_yaw_[i]);
    mount_sin_[i] = std::sin(sensor_yaw_[i]);
  }
  sample_period_ns_ = cosim::SecondsToNs(sample_period_);
  stale_after_ns_ = cosim::SecondsToNs(stale_after_);
  decay_dt_ = -1;
  decay_factor_ = 1.0;
}

void SurfaceVelocityEstimator::ResetState() {
  std::fill(x_.begin(), x_.end(), 0.0);
  std::fill(surface_.begin(), surface_.end(), -1);
  std::fill(status_.begin(), status_.end(), kNoEstimate);
  // The px4flow's count starts at 0 (no message yet); its first message
  // (count 1) is new.
  std::fill(last_count_.begin(), last_count_.end(), 0.0);
  std::fill(last_valid_.begin(), last_valid_.end(), start_);
  std::fill(entered_.begin(), entered_.end(), start_);
  std::fill(acc_vx_.begin(), acc_vx_.end(), 0.0);
  std::fill(acc_ox_.begin(), acc_ox_.end(), 0.0);
  std::fill(acc_checked_ns_.begin(), acc_checked_ns_.end(), 0);
  std::fill(acc_oy_.begin(), acc_oy_.end(), 0.0);
  std::fill(implausible_.begin(), implausible_.end(), 0);
  std::fill(acc_vy_.begin(), acc_vy_.end(), 0.0);
  std::fill(acc_c_.begin(), acc_c_.end(), 0.0);
  std::fill(acc_s_.begin(), acc_s_.end(), 0.0);
  std::fill(acc_ns_.begin(), acc_ns_.end(), 0);
  std::fill(run_.begin(), run_.end(), 0);
  std::fill(switches_.begin(), switches_.end(), 0);
  std::fill(raw_.begin(), raw_.end(), 0.0);
}

void SurfaceVelocityEstimator::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void SurfaceVelocityEstimator::Initialize() {
  ThrowIfBadParameters();
  Cache();
  ResetState();
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  MapSurfaces(c, s);
  WriteOutputs(c, s);
}

bool SurfaceVelocityEstimator::SurfaceMean(int surface, int status, char skip, double& vx,
                                           double& vy) const {
  double sx = 0.0, sy = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < n_; ++i) {
    if (surface_[i] != surface || status_[i] != status || (flags_[i] & skip) != 0) continue;
    sx += x_[2 * i];
    sy += x_[2 * i + 1];
    ++count;
  }
  if (count == 0) return false;
  vx = sx / count;
  vy = sy / count;
  return true;
}

bool SurfaceVelocityEstimator::RelativeAt(std::int64_t surface, double px, double py, double& vx,
                                          double& vy) const {
  double sx = 0.0, sy = 0.0;
  int count = 0;
  for (std::size_t j = 0; j < w_; ++j) {
    if (wheel_map_surface_[j] != surface) continue;
    // Rigid body: v(p) = v(r_j) + omega x (p - r_j).
    sx += odometry_wheel_velocity_[2 * j] - yaw_rate_ * (py - wheel_y_[j]);
    sy += odometry_wheel_velocity_[2 * j + 1] + yaw_rate_ * (px - wheel_x_[j]);
    ++count;
  }
  if (count == 0) return false;
  vx = sx / count;
  vy = sy / count;
  return true;
}

void SurfaceVelocityEstimator::WriteOutputs(double c, double s) {
  for (std::size_t i = 0; i < n_; ++i) {
    sensor_on_belt_[i] = static_cast<double>(map_surface_[i]);
    sensor_status_[i] = static_cast<double>(status_[i]);
    const bool has = status_[i] != kNoEstimate;
    filtered_[2 * i] = has ? x_[2 * i] : 0.0;
    filtered_[2 * i + 1] = has ? x_[2 * i + 1] : 0.0;
    switch_count_[i] = static_cast<double>(switches_[i]);
    implausible_count_[i] = static_cast<double>(implausible_[i]);
  }
  // The paper's wheel rule: a wheel over belt k takes belt k's estimate,
  // the mean over the sensors the map puts over belt k (a rigid belt has
  // one velocity); over the floor 0. With the sensors at the corners of a
  // convex planform and a line at least as wide as the robot's extent
  // across it, a wheel over the belt implies a corner over the belt: the
  // wheel lies between the corners across the line, so corners on both
  // sides of the line and none on it would span more than the line's width.
  // (Near a belt's end, or on a narrower line, a wheel can be over a belt
  // no sensor sees: source 3.)
  for (std::size_t j = 0; j < w_; ++j) {
    const auto k = static_cast<int>(wheel_map_surface_[j]);
    double vx = 0.0, vy = 0.0;
    int source = kFloor;
    if (k > 0) {
      if (SurfaceMean(k, kFresh, 0, vx, vy)) {
        source = kFromFresh;
      } else if (SurfaceMean(k, kHeld, 0, vx, vy)) {
        source = kFromHeld;
      } else {
        vx = vy = 0.0;
        source = kBeltNoEstimate;
      }
    }
    // Map to base_link with the estimated yaw.
    wheel_surface_velocity_[2 * j] = c * vx + s * vy;
    wheel_surface_velocity_[2 * j + 1] = -s * vx + c * vy;
    wheel_on_belt_[j] = static_cast<double>(k);
    wheel_source_[j] = static_cast<double>(source);
  }
}

void SurfaceVelocityEstimator::MapSurfaces(double c, double s) {
  // base_link point (x, y) in map, and the surface there.
  const auto at = [&](double x, double y) {
    return belts_.At(position_[0] + c * x - s * y, position_[1] + s * x + c * y);
  };
  for (std::size_t i = 0; i < n_; ++i) map_surface_[i] = at(sensor_x_[i], sensor_y_[i]);
  for (std::size_t j = 0; j < w_; ++j) wheel_map_surface_[j] = at(wheel_x_[j], wheel_y_[j]);
}

cosim::StepResult SurfaceVelocityEstimator::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  // Inputs are held over [t, t + dt]; outputs are for t + dt.
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  const double w = yaw_rate_;
  // The robot's velocity in base_link.
  const double vbx = c * velocity_[0] + s * velocity_[1];
  const double vby = -s * velocity_[0] + c * velocity_[1];

  // 1. Which surface the map puts each sensor over. A sensor the map moves
  // to another surface starts a new filter there: the surface under it
  // changed by a known discrete event (the floor at rest, a belt at ~0.1
  // m/s), so its old state says nothing about the new one, and continuing
  // it would lag the step by the filter's time constant, sample_period /
  // -ln(1 - K) = 0.9 s at paper 1's figures (2 s to within 10 %).
  MapSurfaces(c, s);
  for (std::size_t i = 0; i < n_; ++i) {
    flags_[i] = 0;
    if (map_surface_[i] != surface_[i]) {
      surface_[i] = map_surface_[i];
      status_[i] = kNoEstimate;
      x_[2 * i] = x_[2 * i + 1] = 0.0;
      run_[2 * i] = run_[2 * i + 1] = 0;
      flags_[i] |= kMoved;
      entered_[i] = t;
    }
  }

  // 2. New messages: Eq. 2 over the message's window, then the filter of a
  // sensor that has one, or the hold.
  for (std::size_t i = 0; i < n_; ++i) {
    const double count = sensor_message_count_[i];
    if (count == last_count_[i]) continue;
    last_count_[i] = count;
    // A message integrated while the sensor crossed onto its surface mixes
    // the two (the window is 100 ms: 3 cm at 0.3 m/s): only messages whose
    // whole window lies over the surface the map now puts it on count.
    const bool one_surface = t - acc_ns_[i] >= entered_[i];
    bool measured = sensor_valid_[i] != 0.0 && sensor_quality_[i] > 0.0 && one_surface;
    if (measured && odometry_gate_ > 0.0 && acc_ns_[i] > 0 && acc_checked_ns_[i] == acc_ns_[i]) {
      // The surface relative to the sensor is minus the robot's motion
      // relative to the surface at the sensor point, which the encoders of
      // the wheels on the same surface measure (over the whole window).
      const double inv_t = 1e9 / static_cast<double>(acc_ns_[i]);
      const double ex = sensor_velocity_[2 * i] + acc_ox_[i] * inv_t;
      const double ey = sensor_velocity_[2 * i + 1] + acc_oy_[i] * inv_t;
      if (std::hypot(ex, ey) > odometry_gate_ * measurement_sigma_) {
        measured = false;
        ++implausible_[i];
      }
    }
    if (measured) {
      // The sensor point's mean velocity over the window in the sensor
      // frame, and the mean heading; at the very first step (no window
      // yet) the current values.
      double vpx, vpy, hc, hs;
      const double hn = std::hypot(acc_c_[i], acc_s_[i]);
      if (acc_ns_[i] > 0 && hn > 0.0) {
        const double inv_t = 1e9 / static_cast<double>(acc_ns_[i]);
        vpx = acc_vx_[i] * inv_t;
        vpy = acc_vy_[i] * inv_t;
        hc = acc_c_[i] / hn;
        hs = acc_s_[i] / hn;
      } else {
        const double pbx = vbx - w * sensor_y_[i], pby = vby + w * sensor_x_[i];
        vpx = mount_cos_[i] * pbx + mount_sin_[i] * pby;
        vpy = -mount_sin_[i] * pbx + mount_cos_[i] * pby;
        hc = c;
        hs = s;
      }
      // Eq. 2 in the sensor frame (surface relative to the sensor + the
      // sensor point's velocity = the surface's absolute velocity), then to
      // base_link by the mount and to map by the heading.
      const double ax = sensor_velocity_[2 * i] + vpx, ay = sensor_velocity_[2 * i + 1] + vpy;
      const double bx = mount_cos_[i] * ax - mount_sin_[i] * ay;
      const double by = mount_sin_[i] * ax + mount_cos_[i] * ay;
      raw_[2 * i] = hc * bx - hs * by;
      raw_[2 * i + 1] = hs * bx + hc * by;
      flags_[i] |= kMeasured;
    }
    acc_vx_[i] = acc_vy_[i] = acc_c_[i] = acc_s_[i] = acc_ox_[i] = acc_oy_[i] = 0.0;
    acc_ns_[i] = acc_checked_ns_[i] = 0;
    if (status_[i] == kNoEstimate) continue;  // started in 3
    if (measured) {
      // The state-switch detector on the innovations (both components
      // observed, each keeps its own run): a run of switch_samples beyond
      // the gate on one side means the surface changed state (a line
      // switching on or off, which the random walk does not model); the
      // filter restarts from this measurement, the latest (the mean of the
      // run's measurements would lag a ramp by (N - 1) / 2 messages), and
      // goes on with the steady gain.
      const bool switch_x = detector_.Observe(raw_[2 * i] - x_[2 * i], run_[2 * i]);
      const bool switch_y = detector_.Observe(raw_[2 * i + 1] - x_[2 * i + 1], run_[2 * i + 1]);
      if (switch_x || switch_y) {
        x_[2 * i] = raw_[2 * i];
        x_[2 * i + 1] = raw_[2 * i + 1];
        run_[2 * i] = run_[2 * i + 1] = 0;
        ++switches_[i];
      } else {
        x_[2 * i] = kf_.Update(x_[2 * i], raw_[2 * i]);
        x_[2 * i + 1] = kf_.Update(x_[2 * i + 1], raw_[2 * i + 1]);
      }
      status_[i] = kFresh;
      last_valid_[i] = t;
    } else {
      // Quality 0 or invalid: hold the last filtered value (it decays).
      status_[i] = kHeld;
    }
  }

  // 3. Sensors without an estimate: one the map just moved starts from the
  // fresh estimate of the other sensors over its new surface (a rigid
  // belt's one velocity, known to about the steady-state variance K r,
  // better than one measurement's r), then takes its own measurement if it
  // has one; with no such sensor, from its first valid measurement there.
  // A sensor that went stale or never had a valid message starts the same
  // way at its next valid measurement.
  for (std::size_t i = 0; i < n_; ++i) {
    if (status_[i] != kNoEstimate || (flags_[i] & (kMoved | kMeasured)) == 0) continue;
    double bx = 0.0, by = 0.0;
    const bool borrowed = SurfaceMean(static_cast<int>(surface_[i]), kFresh, kStarted, bx, by);
    if (borrowed) {
      x_[2 * i] = bx;
      x_[2 * i + 1] = by;
      if ((flags_[i] & kMeasured) != 0) {
        x_[2 * i] = kf_.Update(bx, raw_[2 * i]);
        x_[2 * i + 1] = kf_.Update(by, raw_[2 * i + 1]);
      }
    } else if ((flags_[i] & kMeasured) != 0) {
      x_[2 * i] = raw_[2 * i];
      x_[2 * i + 1] = raw_[2 * i + 1];
    } else {
      continue;
    }
    status_[i] = kFresh;
    last_valid_[i] = t;
    run_[2 * i] = run_[2 * i + 1] = 0;
    flags_[i] |= kStarted;
  }

  // 4. Timers. A fresh sensor whose next valid message is overdue (the
  // messages come every sample_period and are seen at the first step
  // after: 1.5 sample_period + dt allows for both) is held; one without a
  // valid message for stale_after gives no estimate. A held value decays
  // toward 0 with hold_time_constant over the step.
  if (dt != decay_dt_) {
    decay_dt_ = dt;
    decay_factor_ = std::exp(-cosim::NsToSeconds(dt) / hold_time_constant_);
  }
  const cosim::TimeNs overdue = sample_period_ns_ + sample_period_ns_ / 2 + dt;
  for (std::size_t i = 0; i < n_; ++i) {
    if (status_[i] == kNoEstimate) continue;
    const cosim::TimeNs age = t - last_valid_[i];
    if (age >= stale_after_ns_) {
      status_[i] = kNoEstimate;
      x_[2 * i] = x_[2 * i + 1] = 0.0;
      run_[2 * i] = run_[2 * i + 1] = 0;
      continue;
    }
    if (status_[i] == kFresh && age > overdue) status_[i] = kHeld;
    if (status_[i] == kHeld) {
      x_[2 * i] *= decay_factor_;
      x_[2 * i + 1] *= decay_factor_;
    }
  }

  // 5. The window of each sensor's next message: its point's velocity in
  // the sensor frame and the heading, over [t, t + dt].
  const double h = cosim::NsToSeconds(dt);
  for (std::size_t i = 0; i < n_; ++i) {
    const double pbx = vbx - w * sensor_y_[i], pby = vby + w * sensor_x_[i];
    acc_vx_[i] += (mount_cos_[i] * pbx + mount_sin_[i] * pby) * h;
    acc_vy_[i] += (-mount_sin_[i] * pbx + mount_cos_[i] * pby) * h;
    double obx = 0.0, oby = 0.0;
    if (odometry_gate_ > 0.0 && RelativeAt(map_surface_[i], sensor_x_[i], sensor_y_[i], obx, oby)) {
      acc_ox_[i] += (mount_cos_[i] * obx + mount_sin_[i] * oby) * h;
      acc_oy_[i] += (-mount_sin_[i] * obx + mount_cos_[i] * oby) * h;
      acc_checked_ns_[i] += dt;
    }
    acc_c_[i] += c * h;
    acc_s_[i] += s * h;
    acc_ns_[i] += dt;
  }

  WriteOutputs(c, s);
  return cosim::StepResult::kOk;
}

// The outputs (raw values, statuses) come back with the variables; the
// rest is here. The scratch (map_surface_, flags_) is recomputed every step.
void SurfaceVelocityEstimator::SaveInternal(cosim::UnitState& state) const {
  state.reals = x_;
  for (const auto* v : {&acc_vx_, &acc_vy_, &acc_c_, &acc_s_, &acc_ox_, &acc_oy_, &last_count_}) {
    state.reals.insert(state.reals.end(), v->begin(), v->end());
  }
  state.integers = {start_};
  for (const auto* v : {&surface_, &status_, &last_valid_, &entered_, &acc_ns_, &acc_checked_ns_,
                        &map_surface_, &switches_, &implausible_}) {
    state.integers.insert(state.integers.end(), v->begin(), v->end());
  }
  state.integers.insert(state.integers.end(), run_.begin(), run_.end());
}

void SurfaceVelocityEstimator::RestoreInternal(const cosim::UnitState& state) {
  if (state.reals.size() != 9 * n_ || state.integers.size() != 1 + 11 * n_) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected " + std::to_string(9 * n_) + " and " +
                           std::to_string(1 + 11 * n_));
  }
  auto r = state.reals.begin();
  const auto n = static_cast<std::ptrdiff_t>(n_);
  std::copy(r, r + 2 * n, x_.begin());
  r += 2 * n;
  for (auto* v : {&acc_vx_, &acc_vy_, &acc_c_, &acc_s_, &acc_ox_, &acc_oy_, &last_count_}) {
    std::copy(r, r + n, v->begin());
    r += n;
  }
  auto k = state.integers.begin();
  start_ = *k++;
  for (auto* v : {&surface_, &status_, &last_valid_, &entered_, &acc_ns_, &acc_checked_ns_,
                  &map_surface_, &switches_, &implausible_}) {
    std::copy(k, k + n, v->begin());
    k += n;
  }
  std::copy(k, k + 2 * n, run_.begin());
  // The parameters came back with the variables.
  Cache();
}

}  // namespace linesim::estimation
