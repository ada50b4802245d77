#include "units/estimation/surface_fusion_unit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "units/estimation/steady_state_kalman.h"

namespace linesim::estimation {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

SurfaceFusionUnit::SurfaceFusionUnit(std::string name, int sensors, int wheels,
                                     const models::Scene& scene, bool imu)
    : cosim::Unit(kTypeName, std::move(name)), imu_(imu) {
  if (sensors < 0 || wheels < 2) {
    throw cosim::UnitError(Where() + ": needs at least 2 wheels (a rigid-body fit) and no "
                                     "negative sensor count, got " +
                           std::to_string(sensors) + " sensors and " + std::to_string(wheels) +
                           " wheels");
  }
  n_ = static_cast<std::size_t>(sensors);
  w_ = static_cast<std::size_t>(wheels);
  belts_ = models::BeltMap(scene.belts);
  const std::size_t k = belts_.size();

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
  laser_position_.assign(2, 0.0);
  wheel_velocity_.assign(2 * w_, 0.0);
  wheel_surface_velocity_.assign(2 * w_, 0.0);
  wheel_on_belt_.assign(w_, 0.0);
  sensor_surface_velocity_.assign(2 * n_, 0.0);
  belt_velocity_.assign(2 * k, 0.0);
  belt_sigma_.assign(k, 0.0);
  switch_count_.assign(k, 0.0);
  rejected_count_.assign(k, 0.0);
  fit_.assign(n_ * 2 * 2 * w_, 0.0);
  mount_cos_.assign(n_, 1.0);
  mount_sin_.assign(n_, 0.0);
  dim_ = 2 + 2 * k;
  if (imu_) {
    imu_index_ = dim_;
    dim_ += 4;  // b, beta
  }
  imu_acceleration_.assign(3, 0.0);
  imu_run_.assign(2, 0);
  state_.assign(dim_, 0.0);
  cov_.assign(dim_ * dim_, 0.0);
  scratch_.assign(4 * dim_ * dim_, 0.0);
  drift_.assign(4 * k, 0.0);
  run_.assign(2, 0);
  slope_run_.assign(2, 0);
  ramp_until_.assign(k, 0);
  switches_.assign(k, 0);
  rejected_.assign(k, 0);
  hist_t_.assign(kHistory, 0);
  hist_p_.assign(kHistory * 2, 0.0);
  match_t_.assign(kMatches, 0.0);
  match_z_.assign(2 * kMatches, 0.0);
  origin_fit_.assign(2 * 2 * w_, 0.0);
  window_surface_.assign(n_, 0);
  last_count_.assign(n_, 0.0);
  acc_y_.assign(2 * n_, 0.0);
  acc_m_.assign(4 * n_, 0.0);
  acc_h_.assign(2 * n_, 0.0);
  acc_ns_.assign(n_, 0);
  wheel_surface_.assign(w_, 0);
  sensor_surface_.assign(n_, 0);

  using cosim::Rule;
  auto& v = variables();
  v.Parameter("sensor_x", "m", &sensor_x_, "x of each PX4Flow in base_link (one per sensor)",
              Rule::Finite().NoDefault());
  v.Parameter("sensor_y", "m", &sensor_y_, "y of each PX4Flow in base_link (one per sensor)",
              Rule::Finite().NoDefault());
  v.Parameter("sensor_yaw", "rad", &sensor_yaw_,
              "each PX4Flow's x axis relative to base_link x, counter-clockwise (one per sensor)",
              Rule::Finite().NoDefault());
  v.Parameter("wheel_x", "m", &wheel_x_,
              "x of each wheel's contact point in base_link (one per wheel)",
              Rule::Finite().NoDefault());
  v.Parameter("wheel_y", "m", &wheel_y_,
              "y of each wheel's contact point in base_link (one per wheel)",
              Rule::Finite().NoDefault());
  v.Parameter("belt_random_walk", "m/s/sqrt(s)", &belt_random_walk_,
              "a belt velocity's random walk within one on/off state (paper 1: 3 sigma = 1 cm/s "
              "per 0.1 s sample, (0.01 / 3) / sqrt(0.1) = 0.0105)",
              Rule::Positive());
  v.Parameter("initial_sigma", "m/s", &initial_sigma_,
              "prior sigma of each belt velocity component (paper 1 Sec. VI-D: lines run below "
              "0.2 m/s)",
              Rule::Positive());
  v.Parameter("flow_sigma", "m/s", &flow_sigma_,
              "standard deviation of one PX4Flow velocity message, per component (paper 1: 3 "
              "cm/s)",
              Rule::Positive());
  v.Parameter("laser_position_sigma", "m", &laser_position_sigma_,
              "standard deviation of one accepted match's position per component (measured on "
              "the S300 matcher standing on the line: 1.4 mm along x, 0.8 mm along y, 1.5 mm "
              "taken; docs/results.md)",
              Rule::Positive());
  v.Parameter("dead_reckoning_noise", "m/sqrt(s)", &dead_reckoning_noise_,
              "random walk of the residual between the laser's position and the encoders' dead "
              "reckoning that the belts do not explain (a contact's creep and slide, the fit's "
              "error)",
              Rule::Positive());
  v.Parameter("outlier_gate", "1", &outlier_gate_,
              "a measurement whose squared Mahalanobis innovation exceeds this is not used (chi "
              "square with 2 dof; 25: probability 3.7e-6 on the model)",
              Rule::Positive());
  v.Parameter("switch_gate", "1", &switch_gate_,
              "state-switch detector: the gate on each component of a match's innovation "
              "(position against dead reckoning) in sigmas sqrt(S_ii); 0 turns it off",
              Rule::Range(0.0, 100.0));
  v.Parameter("switch_samples", &switch_samples_,
              "state-switch detector: this many consecutive match innovations beyond the gate on "
              "one side reopen the velocity of the belts under the wheels",
              Rule::Range(1, 1000));
  v.Parameter("slope_gate", "1", &slope_gate_,
              "state-switch detector on the drift: the least-squares slope of the last "
              "slope_matches residuals against the drift the belts' estimates predict, in sigmas; "
              "0 turns it off",
              Rule::Range(0.0, 100.0));
  v.Parameter("slope_matches", &slope_matches_,
              "matches in the slope detector's window (and a restart's slope)", Rule::Range(3, 16));
  v.Parameter("ramp_random_walk", "m/s/sqrt(s)", &ramp_random_walk_,
              "a belt velocity's random walk during a detected switch: the velocity change of "
              "a ramp of acceleration a over one match interval T as its standard deviation "
              "over T, a sqrt(T) (0.5 m/s^2, the scenes' acceleration_mps2, and 40 ms: 0.1)",
              Rule::Positive());
  v.Parameter("ramp_time", "s", &ramp_time_,
              "how long a detected switch lasts (the line's ramps: about 1 s)", Rule::Positive());

  if (imu_) {
    v.Parameter("imu_yaw", "rad", &imu_yaw_, "the IMU's x axis relative to base_link x (mount yaw)",
                Rule::Finite());
    v.Parameter("imu_velocity_noise", "m/s/sqrt(s)", &imu_velocity_noise_,
                "random walk of the integrated acceleration: the accelerometer's white noise "
                "and its quantization at 100 Hz (ADIS16470: 23 ug/sqrt(Hz) = 2.26e-4, 1.25 mg "
                "LSB / sqrt(12) over 10 ms = 3.5e-4; together 4.2e-4)",
                Rule::Positive());
    v.Parameter("imu_bias_sigma", "m/s2", &imu_bias_sigma_,
                "prior sigma of the accelerometer bias per axis (the imu unit's turn-on bias: "
                "5 mg, models/sensors/adis16470.yaml)",
                Rule::Positive());
    v.Parameter("imu_bias_walk", "m/s2/sqrt(s)", &imu_bias_walk_,
                "random walk of the accelerometer bias (ADIS16470: 13 ug in-run stability at "
                "100 s, 1.27e-4 sqrt(3 / 100) = 2.2e-5)",
                Rule::Positive());
    v.Input("imu_acceleration", "m/s2", &imu_acceleration_,
            "the IMU's linear_acceleration: specific force in the IMU frame (x, y used; the "
            "floor taken level)");
  }
  v.Input("sensor_velocity", "m/s", &sensor_velocity_,
          "each PX4Flow's velocity output: the surface relative to the sensor, sensor frame, vx "
          "vy per sensor");
  v.Input("sensor_valid", "1", &sensor_valid_, "each PX4Flow's valid output");
  v.Input("sensor_quality", "1", &sensor_quality_, "each PX4Flow's quality output (0..255)");
  v.Input("sensor_message_count", "1", &sensor_message_count_,
          "each PX4Flow's message_count output (a change: a new message)");
  v.Input("position", "m", &position_,
          "estimated x, y of base_link in map (which surface each point is over)");
  v.Input("yaw", "rad", &yaw_, "estimated yaw of base_link in map");
  v.Input("laser_position", "m", &laser_position_,
          "the laser localization's latest accepted match: x, y of base_link in map");
  v.Input("match_time", "s", &match_time_, "the time the laser localization's latest match refers to");
  v.Input("match_count", "1", &match_count_,
          "the laser localization's accepted matches (a change: a new position)");
  v.Input("wheel_velocity", "m/s", &wheel_velocity_,
          "each wheel's contact velocity relative to the surface under it by its encoders, "
          "base_link, vx vy per wheel (the wheel odometry's wheel_velocity)");

  v.Output("wheel_surface_velocity", "m/s", &wheel_surface_velocity_,
           "per wheel, base_link, vx vy: the estimated ABSOLUTE velocity of the belt the map "
           "puts it over (0 over the floor)",
           {});
  v.Output("wheel_on_belt", "1", &wheel_on_belt_,
           "per wheel: 0 over the floor, k+1 over scene belt k (estimated pose and line map)", {});
  v.Output("sensor_surface_velocity", "m/s", &sensor_surface_velocity_,
           "per PX4Flow, map, vx vy: the estimate of the belt under it (0 over the floor)", {});
  v.Output("belt_velocity", "m/s", &belt_velocity_, "per scene belt, map, vx vy: the estimate",
           {});
  v.Output("belt_sigma", "m/s", &belt_sigma_,
           "per scene belt: sqrt of the largest eigenvalue of its covariance", {});
  v.Output("switch_count", "1", &switch_count_,
           "per scene belt: switches detected (filter restarts) so far", {});
  v.Output("rejected_count", "1", &rejected_count_,
           "per scene belt: measurements beyond outlier_gate so far", {});
}

void SurfaceFusionUnit::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void SurfaceFusionUnit::Cache() {
  // Rigid-body least squares: wheel j's velocity (vx - w y_j, vy + w x_j),
  // unknowns (vx, vy, w). The normal matrix N = A^T A and L = N^-1 A^T
  // (3 x 2W); the velocity at p is G(p) L e with G = [1 0 -py; 0 1 px].
  double sx = 0.0, sy = 0.0, sr = 0.0;
  for (std::size_t j = 0; j < w_; ++j) {
    sx += wheel_x_[j];
    sy += wheel_y_[j];
    sr += wheel_x_[j] * wheel_x_[j] + wheel_y_[j] * wheel_y_[j];
  }
  const double wn = static_cast<double>(w_);
  // N = [W 0 -sy; 0 W sx; -sy sx sr]; its inverse by cofactors.
  const double n[9] = {wn, 0.0, -sy, 0.0, wn, sx, -sy, sx, sr};
  const double det = n[0] * (n[4] * n[8] - n[5] * n[7]) - n[1] * (n[3] * n[8] - n[5] * n[6]) +
                     n[2] * (n[3] * n[7] - n[4] * n[6]);
  if (!(std::abs(det) > 1e-12)) {
    throw cosim::UnitError(Where() + ": the wheels are at one point (no rigid-body fit)");
  }
  double inv[9];
  inv[0] = (n[4] * n[8] - n[5] * n[7]) / det;
  inv[1] = (n[2] * n[7] - n[1] * n[8]) / det;
  inv[2] = (n[1] * n[5] - n[2] * n[4]) / det;
  inv[3] = (n[5] * n[6] - n[3] * n[8]) / det;
  inv[4] = (n[0] * n[8] - n[2] * n[6]) / det;
  inv[5] = (n[2] * n[3] - n[0] * n[5]) / det;
  inv[6] = (n[3] * n[7] - n[4] * n[6]) / det;
  inv[7] = (n[1] * n[6] - n[0] * n[7]) / det;
  inv[8] = (n[0] * n[4] - n[1] * n[3]) / det;
  // L (3 x 2W): column 2j is N^-1 (1, 0, -y_j), column 2j + 1 N^-1 (0, 1, x_j).
  std::vector<double> l(3 * 2 * w_);
  for (std::size_t j = 0; j < w_; ++j) {
    for (std::size_t r = 0; r < 3; ++r) {
      l[r * 2 * w_ + 2 * j] = inv[3 * r + 0] - inv[3 * r + 2] * wheel_y_[j];
      l[r * 2 * w_ + 2 * j + 1] = inv[3 * r + 1] + inv[3 * r + 2] * wheel_x_[j];
    }
  }
  // The fit at base_link's origin: L's first two rows.
  std::copy(l.begin(), l.begin() + static_cast<std::ptrdiff_t>(4 * w_), origin_fit_.begin());
  for (std::size_t i = 0; i < n_; ++i) {
    double* c = &fit_[i * 4 * w_];
    for (std::size_t col = 0; col < 2 * w_; ++col) {
      c[col] = l[col] - sensor_y_[i] * l[2 * 2 * w_ + col];
      c[2 * w_ + col] = l[2 * w_ + col] + sensor_x_[i] * l[2 * 2 * w_ + col];
    }
    mount_cos_[i] = std::cos(sensor_yaw_[i]);
    mount_sin_[i] = std::sin(sensor_yaw_[i]);
  }
}

void SurfaceFusionUnit::ResetState() {
  // D = 0 with the first match's variance to come: the dead reckoning
  // starts at the estimated position; each belt at rest with the prior.
  std::fill(state_.begin(), state_.end(), 0.0);
  std::fill(cov_.begin(), cov_.end(), 0.0);
  cov_[0] = cov_[dim_ + 1] = kInitialResidualSigma * kInitialResidualSigma;
  const std::size_t belt_end = imu_ ? imu_index_ : dim_;
  for (std::size_t q = 2; q < belt_end; ++q) cov_[q * dim_ + q] = initial_sigma_ * initial_sigma_;
  if (imu_) {
    // b = 0 with V_imu starting at the encoders' velocity (the first step
    // sets it); beta at the device's turn-on bias.
    cov_[imu_index_ * dim_ + imu_index_] = cov_[(imu_index_ + 1) * dim_ + imu_index_ + 1] =
        initial_sigma_ * initial_sigma_;
    for (std::size_t q = imu_index_ + 2; q < dim_; ++q) {
      cov_[q * dim_ + q] = imu_bias_sigma_ * imu_bias_sigma_;
    }
  }
  imu_velocity_[0] = imu_velocity_[1] = 0.0;
  imu_run_[0] = imu_run_[1] = 0;
  run_[0] = run_[1] = 0;
  slope_run_[0] = slope_run_[1] = 0;
  for (std::size_t k = 0; k < belts_.size(); ++k) {
    ramp_until_[k] = start_;
    switches_[k] = rejected_[k] = 0;
  }
  dead_reckoning_[0] = position_[0];
  dead_reckoning_[1] = position_[1];
  std::fill(hist_t_.begin(), hist_t_.end(), 0);
  std::fill(hist_p_.begin(), hist_p_.end(), 0.0);
  first_ = size_ = 0;
  match_first_ = match_size_ = 0;
  std::fill(match_t_.begin(), match_t_.end(), 0.0);
  std::fill(match_z_.begin(), match_z_.end(), 0.0);
  last_match_count_ = match_count_;
  std::fill(window_surface_.begin(), window_surface_.end(), -1);
  std::fill(last_count_.begin(), last_count_.end(), 0.0);
  std::fill(acc_y_.begin(), acc_y_.end(), 0.0);
  std::fill(acc_m_.begin(), acc_m_.end(), 0.0);
  std::fill(acc_h_.begin(), acc_h_.end(), 0.0);
  std::fill(acc_ns_.begin(), acc_ns_.end(), 0);
}

void SurfaceFusionUnit::Initialize() {
  ThrowIfBadParameters();
  Cache();
  ResetState();
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  WriteOutputs(c, s);
}

void SurfaceFusionUnit::Predict(double h, cosim::TimeNs t) {
  const std::size_t n = dim_, nb = belts_.size();
  // F = I + h [0 M_1 .. M_K; 0], applied as P' = F P F^T + Q.
  double* fp = scratch_.data();  // F P
  for (std::size_t q = 0; q < n * n; ++q) fp[q] = cov_[q];
  for (std::size_t k = 0; k < nb; ++k) {
    const double* m = &drift_[4 * k];
    const std::size_t a = 2 + 2 * k;
    for (std::size_t col = 0; col < n; ++col) {
      fp[0 * n + col] += h * (m[0] * cov_[a * n + col] + m[1] * cov_[(a + 1) * n + col]);
      fp[1 * n + col] += h * (m[2] * cov_[a * n + col] + m[3] * cov_[(a + 1) * n + col]);
    }
    state_[0] += h * (m[0] * state_[a] + m[1] * state_[a + 1]);
    state_[1] += h * (m[2] * state_[a] + m[3] * state_[a + 1]);
  }
  // With the IMU: b += h R beta (R: the IMU frame to map).
  const std::size_t ib = imu_index_, ia = imu_index_ + 2;
  if (imu_) {
    const double r[4] = {imu_cos_, -imu_sin_, imu_sin_, imu_cos_};
    for (std::size_t col = 0; col < n; ++col) {
      fp[ib * n + col] += h * (r[0] * cov_[ia * n + col] + r[1] * cov_[(ia + 1) * n + col]);
      fp[(ib + 1) * n + col] += h * (r[2] * cov_[ia * n + col] + r[3] * cov_[(ia + 1) * n + col]);
    }
    state_[ib] += h * (r[0] * state_[ia] + r[1] * state_[ia + 1]);
    state_[ib + 1] += h * (r[2] * state_[ia] + r[3] * state_[ia + 1]);
  }
  // (F P) F^T: the same row operation on the columns.
  for (std::size_t q = 0; q < n * n; ++q) cov_[q] = fp[q];
  for (std::size_t k = 0; k < nb; ++k) {
    const double* m = &drift_[4 * k];
    const std::size_t a = 2 + 2 * k;
    for (std::size_t row = 0; row < n; ++row) {
      cov_[row * n + 0] += h * (m[0] * fp[row * n + a] + m[1] * fp[row * n + a + 1]);
      cov_[row * n + 1] += h * (m[2] * fp[row * n + a] + m[3] * fp[row * n + a + 1]);
    }
  }
  if (imu_) {
    const double r[4] = {imu_cos_, -imu_sin_, imu_sin_, imu_cos_};
    for (std::size_t row = 0; row < n; ++row) {
      cov_[row * n + ib] += h * (r[0] * fp[row * n + ia] + r[1] * fp[row * n + ia + 1]);
      cov_[row * n + ib + 1] += h * (r[2] * fp[row * n + ia] + r[3] * fp[row * n + ia + 1]);
    }
    const double qb = imu_velocity_noise_ * imu_velocity_noise_ * h;
    const double qa = imu_bias_walk_ * imu_bias_walk_ * h;
    cov_[ib * n + ib] += qb;
    cov_[(ib + 1) * n + ib + 1] += qb;
    cov_[ia * n + ia] += qa;
    cov_[(ia + 1) * n + ia + 1] += qa;
  }
  const double qd = dead_reckoning_noise_ * dead_reckoning_noise_ * h;
  cov_[0] += qd;
  cov_[n + 1] += qd;
  for (std::size_t k = 0; k < nb; ++k) {
    const double rw = t < ramp_until_[k] ? ramp_random_walk_ : belt_random_walk_;
    const std::size_t a = 2 + 2 * k;
    cov_[a * n + a] += rw * rw * h;
    cov_[(a + 1) * n + a + 1] += rw * rw * h;
  }
}

bool SurfaceFusionUnit::Update(const double* hm, const double z[2], double r, double nu[2],
                               double s_diag[2]) {
  const std::size_t n = dim_;
  // nu = z - H x; PH = P H^T (n x 2); S = H P H^T + r I; K = PH S^-1.
  double* ph = scratch_.data();
  nu[0] = z[0];
  nu[1] = z[1];
  for (std::size_t q = 0; q < n; ++q) {
    nu[0] -= hm[q] * state_[q];
    nu[1] -= hm[n + q] * state_[q];
  }
  for (std::size_t row = 0; row < n; ++row) {
    double a = 0.0, b = 0.0;
    for (std::size_t q = 0; q < n; ++q) {
      a += cov_[row * n + q] * hm[q];
      b += cov_[row * n + q] * hm[n + q];
    }
    ph[2 * row] = a;
    ph[2 * row + 1] = b;
  }
  double sm[4] = {r, 0.0, 0.0, r};
  for (std::size_t q = 0; q < n; ++q) {
    sm[0] += hm[q] * ph[2 * q];
    sm[1] += hm[q] * ph[2 * q + 1];
    sm[2] += hm[n + q] * ph[2 * q];
    sm[3] += hm[n + q] * ph[2 * q + 1];
  }
  s_diag[0] = sm[0];
  s_diag[1] = sm[3];
  const double det = sm[0] * sm[3] - sm[1] * sm[2];
  if (!(det > 0.0)) return false;
  const double si[4] = {sm[3] / det, -sm[1] / det, -sm[2] / det, sm[0] / det};
  const double d2 =
      nu[0] * (si[0] * nu[0] + si[1] * nu[1]) + nu[1] * (si[2] * nu[0] + si[3] * nu[1]);
  if (!(d2 <= outlier_gate_)) return false;
  // K (n x 2), x += K nu, P -= K (P H^T)^T.
  double* kg = scratch_.data() + 2 * n;
  for (std::size_t row = 0; row < n; ++row) {
    kg[2 * row] = ph[2 * row] * si[0] + ph[2 * row + 1] * si[2];
    kg[2 * row + 1] = ph[2 * row] * si[1] + ph[2 * row + 1] * si[3];
    state_[row] += kg[2 * row] * nu[0] + kg[2 * row + 1] * nu[1];
  }
  for (std::size_t row = 0; row < n; ++row) {
    for (std::size_t col = 0; col < n; ++col) {
      cov_[row * n + col] -= kg[2 * row] * ph[2 * col] + kg[2 * row + 1] * ph[2 * col + 1];
    }
  }
  // Kept symmetric.
  for (std::size_t row = 0; row < n; ++row) {
    for (std::size_t col = row + 1; col < n; ++col) {
      const double v = 0.5 * (cov_[row * n + col] + cov_[col * n + row]);
      cov_[row * n + col] = cov_[col * n + row] = v;
    }
  }
  return true;
}

void SurfaceFusionUnit::UpdatePosition(const double z[2], double lag, double nu[2],
                                       double s_diag[2]) {
  // H = [I, -lag M_1, ..., -lag M_K].
  const std::size_t n = dim_;
  double* hm = scratch_.data() + 2 * n * n;
  std::fill(hm, hm + 2 * n, 0.0);
  hm[0] = hm[n + 1] = 1.0;
  for (std::size_t k = 0; k < belts_.size(); ++k) {
    const double* m = &drift_[4 * k];
    const std::size_t a = 2 + 2 * k;
    hm[a] = -lag * m[0];
    hm[a + 1] = -lag * m[1];
    hm[n + a] = -lag * m[2];
    hm[n + a + 1] = -lag * m[3];
  }
  if (!Update(hm, z, laser_position_sigma_ * laser_position_sigma_, nu, s_diag)) ++rejected_match_;
}

void SurfaceFusionUnit::ReopenBlock(std::size_t a, double sigma) {
  for (std::size_t q = 0; q < dim_; ++q) {
    cov_[a * dim_ + q] = cov_[q * dim_ + a] = 0.0;
    cov_[(a + 1) * dim_ + q] = cov_[q * dim_ + a + 1] = 0.0;
  }
  cov_[a * dim_ + a] = cov_[(a + 1) * dim_ + a + 1] = sigma * sigma;
}

bool SurfaceFusionUnit::Slope(std::size_t count, double slope[2], double& variance) const {
  // Least squares of z = a + b t over the last `count` matches; the
  // slope's variance sigma_p^2 / sum (t - mean t)^2.
  double mt = 0.0, mx = 0.0, my = 0.0;
  for (std::size_t q = 0; q < count; ++q) {
    const std::size_t slot = (match_first_ + match_size_ - count + q) % kMatches;
    mt += match_t_[slot];
    mx += match_z_[2 * slot];
    my += match_z_[2 * slot + 1];
  }
  const double n = static_cast<double>(count);
  mt /= n;
  mx /= n;
  my /= n;
  double stt = 0.0, stx = 0.0, sty = 0.0;
  for (std::size_t q = 0; q < count; ++q) {
    const std::size_t slot = (match_first_ + match_size_ - count + q) % kMatches;
    const double dt = match_t_[slot] - mt;
    stt += dt * dt;
    stx += dt * (match_z_[2 * slot] - mx);
    sty += dt * (match_z_[2 * slot + 1] - my);
  }
  if (!(stt > 1e-8)) return false;
  slope[0] = stx / stt;
  slope[1] = sty / stt;
  variance = laser_position_sigma_ * laser_position_sigma_ / stt;
  return true;
}

bool SurfaceFusionUnit::DeadReckoningAt(cosim::TimeNs time, double out[2]) const {
  // Linear between the two history entries around `time`.
  if (size_ == 0) return false;
  const std::size_t last = (first_ + size_ - 1) % kHistory;
  if (time >= hist_t_[last]) {
    out[0] = hist_p_[2 * last];
    out[1] = hist_p_[2 * last + 1];
    return true;
  }
  for (std::size_t q = size_ - 1; q > 0; --q) {
    const std::size_t b = (first_ + q) % kHistory, a = (first_ + q - 1) % kHistory;
    if (hist_t_[a] <= time) {
      const double f = static_cast<double>(time - hist_t_[a]) /
                       static_cast<double>(std::max<cosim::TimeNs>(1, hist_t_[b] - hist_t_[a]));
      out[0] = hist_p_[2 * a] + f * (hist_p_[2 * b] - hist_p_[2 * a]);
      out[1] = hist_p_[2 * a + 1] + f * (hist_p_[2 * b + 1] - hist_p_[2 * a + 1]);
      return true;
    }
  }
  return false;  // older than the history
}

void SurfaceFusionUnit::UpdateImu(const double enc[2], double h, cosim::TimeNs t) {
  // z = W = V_imu - R fit(e); H = [0, M_1 .. M_K, I, 0].
  const std::size_t n = dim_, nb = belts_.size();
  double* hm = scratch_.data() + 2 * n * n;
  std::fill(hm, hm + 2 * n, 0.0);
  for (std::size_t k = 0; k < nb; ++k) {
    const double* m = &drift_[4 * k];
    const std::size_t a = 2 + 2 * k;
    hm[a] = m[0];
    hm[a + 1] = m[1];
    hm[n + a] = m[2];
    hm[n + a + 1] = m[3];
  }
  hm[imu_index_] = hm[n + imu_index_ + 1] = 1.0;
  const double z[2] = {imu_velocity_[0] - enc[0], imu_velocity_[1] - enc[1]};
  double nu[2], sd[2];
  const double r = dead_reckoning_noise_ * dead_reckoning_noise_ / h;
  Update(hm, z, r, nu, sd);
  // A run beyond the gate: the belts under the wheels switched (reopened
  // as the match detectors do).
  bool fired = false;
  for (std::size_t m = 0; m < 2; ++m) {
    const SwitchDetector detector(switch_gate_, switch_samples_, sd[m]);
    fired = detector.Observe(nu[m], imu_run_[m]) || fired;
  }
  if (!fired) return;
  imu_run_[0] = imu_run_[1] = 0;
  for (std::size_t k = 0; k < nb; ++k) {
    const double* m = &drift_[4 * k];
    if (m[0] == 0.0 && m[1] == 0.0 && m[2] == 0.0 && m[3] == 0.0) continue;
    if (t < ramp_until_[k]) continue;  // already open
    ReopenBlock(2 + 2 * k, initial_sigma_);
    ramp_until_[k] = t + cosim::SecondsToNs(ramp_time_);
    ++switches_[k];
  }
}

void SurfaceFusionUnit::WriteOutputs(double c, double s) {
  for (std::size_t j = 0; j < w_; ++j) {
    const auto k = wheel_surface_[j];
    double vx = 0.0, vy = 0.0;
    if (k > 0) {
      vx = state_[2 + 2 * static_cast<std::size_t>(k - 1)];
      vy = state_[3 + 2 * static_cast<std::size_t>(k - 1)];
    }
    wheel_surface_velocity_[2 * j] = c * vx + s * vy;
    wheel_surface_velocity_[2 * j + 1] = -s * vx + c * vy;
    wheel_on_belt_[j] = static_cast<double>(k);
  }
  for (std::size_t i = 0; i < n_; ++i) {
    const auto k = sensor_surface_[i];
    sensor_surface_velocity_[2 * i] = k > 0 ? state_[2 + 2 * static_cast<std::size_t>(k - 1)] : 0.0;
    sensor_surface_velocity_[2 * i + 1] =
        k > 0 ? state_[3 + 2 * static_cast<std::size_t>(k - 1)] : 0.0;
  }
  for (std::size_t k = 0; k < belts_.size(); ++k) {
    const std::size_t a = 2 + 2 * k;
    belt_velocity_[2 * k] = state_[a];
    belt_velocity_[2 * k + 1] = state_[a + 1];
    const double p00 = cov_[a * dim_ + a], p01 = cov_[a * dim_ + a + 1];
    const double p11 = cov_[(a + 1) * dim_ + a + 1];
    const double half_tr = 0.5 * (p00 + p11);
    const double d = std::sqrt(0.25 * (p00 - p11) * (p00 - p11) + p01 * p01);
    belt_sigma_[k] = std::sqrt(std::max(0.0, half_tr + d));
    switch_count_[k] = static_cast<double>(switches_[k]);
    rejected_count_[k] = static_cast<double>(rejected_[k]);
  }
}

cosim::StepResult SurfaceFusionUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  // Inputs are held over [t, t + dt]; outputs are for t + dt.
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  const double h = cosim::NsToSeconds(dt);
  const std::size_t nb = belts_.size();

  // Which surface the map puts each wheel and sensor over.
  const auto at = [&](double bx, double by) {
    return belts_.At(position_[0] + c * bx - s * by, position_[1] + s * bx + c * by);
  };
  for (std::size_t j = 0; j < w_; ++j) wheel_surface_[j] = at(wheel_x_[j], wheel_y_[j]);
  for (std::size_t i = 0; i < n_; ++i) sensor_surface_[i] = at(sensor_x_[i], sensor_y_[i]);

  double enc[2] = {0.0, 0.0};  // the encoders' fit at the origin, map
  // 1. Dead reckoning by the encoders alone (unrectified: the wheels'
  // motion relative to the surfaces under them), the fit at base_link's
  // origin over the step that ended at t, turned to map by the estimated
  // heading; the history of it for matches that refer to the past.
  {
    double vx = 0.0, vy = 0.0;
    for (std::size_t j = 0; j < w_; ++j) {
      vx += origin_fit_[2 * j] * wheel_velocity_[2 * j] +
            origin_fit_[2 * j + 1] * wheel_velocity_[2 * j + 1];
      vy += origin_fit_[2 * w_ + 2 * j] * wheel_velocity_[2 * j] +
            origin_fit_[2 * w_ + 2 * j + 1] * wheel_velocity_[2 * j + 1];
    }
    enc[0] = c * vx - s * vy;
    enc[1] = s * vx + c * vy;
    dead_reckoning_[0] += enc[0] * h;
    dead_reckoning_[1] += enc[1] * h;
    if (imu_) {
      // The IMU's sample: the mean specific force over its interval, here
      // this step's; to map by the heading and the mount.
      imu_cos_ = std::cos(yaw_ + imu_yaw_);
      imu_sin_ = std::sin(yaw_ + imu_yaw_);
      const double fx = imu_acceleration_[0], fy = imu_acceleration_[1];
      imu_velocity_[0] += (imu_cos_ * fx - imu_sin_ * fy) * h;
      imu_velocity_[1] += (imu_sin_ * fx + imu_cos_ * fy) * h;
    }
    const std::size_t slot = (first_ + size_) % kHistory;
    if (size_ == kHistory) {
      first_ = (first_ + 1) % kHistory;
    } else {
      ++size_;
    }
    hist_t_[slot] = t;
    hist_p_[2 * slot] = dead_reckoning_[0];
    hist_p_[2 * slot + 1] = dead_reckoning_[1];
  }

  // 2. The residual's drift by the belts under the wheels (map): M_k, the
  // sum of the fit's blocks at the origin of the wheels over belt k.
  std::fill(drift_.begin(), drift_.end(), 0.0);
  for (std::size_t j = 0; j < w_; ++j) {
    const auto k = wheel_surface_[j];
    if (k <= 0) continue;
    double* m = &drift_[4 * static_cast<std::size_t>(k - 1)];
    const double b00 = origin_fit_[2 * j], b01 = origin_fit_[2 * j + 1];
    const double b10 = origin_fit_[2 * w_ + 2 * j], b11 = origin_fit_[2 * w_ + 2 * j + 1];
    // R B R^T.
    const double rb[4] = {c * b00 - s * b10, c * b01 - s * b11, s * b00 + c * b10,
                          s * b01 + c * b11};
    m[0] += rb[0] * c - rb[1] * s;
    m[1] += rb[0] * s + rb[1] * c;
    m[2] += rb[2] * c - rb[3] * s;
    m[3] += rb[2] * s + rb[3] * c;
  }
  // Prediction over the step: D += h sum_k M_k u_k; random walks.
  Predict(h, t);
  if (imu_) UpdateImu(enc, h, t);

  // 3. A new accepted match: z = the match's position minus the dead
  // reckoning at its time = D(t_m) = D(t) - (t - t_m) sum_k M_k u_k.
  if (match_count_ != last_match_count_) {
    last_match_count_ = match_count_;
    const auto tm = InputTimeNs(match_time_, "match_time");
    double pe[2];
    if (DeadReckoningAt(tm, pe)) {
      const double z[2] = {laser_position_[0] - pe[0], laser_position_[1] - pe[1]};
      const double lag = cosim::NsToSeconds(t - tm);
      // The recent matches' residuals, for a restart's slope.
      const std::size_t slot = (match_first_ + match_size_) % kMatches;
      if (match_size_ == kMatches) {
        match_first_ = (match_first_ + 1) % kMatches;
      } else {
        ++match_size_;
      }
      match_t_[slot] = match_time_;
      match_z_[2 * slot] = z[0];
      match_z_[2 * slot + 1] = z[1];
      // The slope detector's innovation, before this match's update: the
      // residuals' least-squares slope over the last slope_matches matches
      // against the drift the state predicts, sum_k M_k u_k, in sigmas of
      // both (sigma_p^2 / sum (t - mean t)^2 and M P_uu M^T).
      double slope_nu[2] = {0.0, 0.0}, slope_s[2] = {0.0, 0.0};
      const auto window = static_cast<std::size_t>(slope_matches_);
      bool has_slope_nu = false;
      if (slope_gate_ > 0.0 && match_size_ >= window) {
        double sl[2], var = 0.0;
        if (Slope(window, sl, var)) {
          has_slope_nu = true;
          slope_nu[0] = sl[0];
          slope_nu[1] = sl[1];
          slope_s[0] = slope_s[1] = var;
          for (std::size_t k = 0; k < nb; ++k) {
            const double* m = &drift_[4 * k];
            const std::size_t a = 2 + 2 * k;
            slope_nu[0] -= m[0] * state_[a] + m[1] * state_[a + 1];
            slope_nu[1] -= m[2] * state_[a] + m[3] * state_[a + 1];
            const double p00 = cov_[a * dim_ + a], p01 = cov_[a * dim_ + a + 1];
            const double p11 = cov_[(a + 1) * dim_ + a + 1];
            slope_s[0] += m[0] * m[0] * p00 + 2 * m[0] * m[1] * p01 + m[1] * m[1] * p11;
            slope_s[1] += m[2] * m[2] * p00 + 2 * m[2] * m[3] * p01 + m[3] * m[3] * p11;
          }
        }
      }
      double nu[2], sd[2];
      UpdatePosition(z, lag, nu, sd);
      // The state-switch detectors on the innovation components: the
      // match's, and the slope's.
      bool fired = false;
      for (std::size_t m = 0; m < 2; ++m) {
        const SwitchDetector detector(switch_gate_, switch_samples_, sd[m]);
        fired = detector.Observe(nu[m], run_[m]) || fired;
        if (has_slope_nu) {
          const SwitchDetector slope_detector(slope_gate_, switch_samples_, slope_s[m]);
          fired = slope_detector.Observe(slope_nu[m], slope_run_[m]) || fired;
        }
      }
      if (fired) {
        slope_run_[0] = slope_run_[1] = 0;
        // The restart: the residual at this match (the laser says where the
        // robot is), and the belts' drift from the least-squares slope of
        // the residuals of the run and the match before it (the detector
        // saw them depart from the model), solved through M for a single
        // belt under the wheels (else the belts' velocities only reopen).
        const std::size_t used = std::min<std::size_t>(match_size_, switch_samples_ + 1);
        double slope[2] = {0.0, 0.0}, slope_var = 0.0;
        const bool has_slope = used >= 2 && Slope(used, slope, slope_var);
        run_[0] = run_[1] = 0;
        state_[0] = z[0];
        state_[1] = z[1];
        ReopenBlock(0, laser_position_sigma_);
        std::size_t under = 0, only = 0;
        for (std::size_t k = 0; k < nb; ++k) {
          const double* m = &drift_[4 * k];
          if (m[0] == 0.0 && m[1] == 0.0 && m[2] == 0.0 && m[3] == 0.0) continue;
          ++under;
          only = k;
        }
        if (has_slope && under == 1) {
          const double* m = &drift_[4 * only];
          const double det = m[0] * m[3] - m[1] * m[2];
          // At least about a third of the wheels on the belt (det of
          // (1/3) I): else the slope says too little about the belt.
          if (det > 0.1) {
            const std::size_t ai = 2 + 2 * only;
            state_[ai] = (m[3] * slope[0] - m[1] * slope[1]) / det;
            state_[ai + 1] = (-m[2] * slope[0] + m[0] * slope[1]) / det;
            ReopenBlock(ai, std::sqrt(slope_var / det));
            ramp_until_[only] = t + cosim::SecondsToNs(ramp_time_);
            ++switches_[only];
            under = 0;  // done
          }
        }
        // The residual now: the match's plus the drift since its time.
        for (std::size_t k = 0; k < nb; ++k) {
          const double* m = &drift_[4 * k];
          const std::size_t a = 2 + 2 * k;
          state_[0] += lag * (m[0] * state_[a] + m[1] * state_[a + 1]);
          state_[1] += lag * (m[2] * state_[a] + m[3] * state_[a + 1]);
        }
        match_first_ = match_size_ = 0;
        // Every belt under a wheel: its velocity is open again (the prior)
        // and follows the ramp's process noise for ramp_time.
        for (std::size_t k = 0; k < nb && under > 0; ++k) {
          const double* m = &drift_[4 * k];
          if (m[0] == 0.0 && m[1] == 0.0 && m[2] == 0.0 && m[3] == 0.0) continue;
          ReopenBlock(2 + 2 * k, initial_sigma_);
          ramp_until_[k] = t + cosim::SecondsToNs(ramp_time_);
          ++switches_[k];
        }
      }
    }
  }

  // 4. The flow at each new valid PX4Flow message whose window lay
  // over one belt.
  for (std::size_t i = 0; i < n_; ++i) {
    const double count = sensor_message_count_[i];
    if (count == last_count_[i]) continue;
    last_count_[i] = count;
    const auto k = window_surface_[i];
    const bool usable = sensor_valid_[i] != 0.0 && sensor_quality_[i] > 0.0 && k > 0 &&
                        acc_ns_[i] > 0 && std::hypot(acc_h_[2 * i], acc_h_[2 * i + 1]) > 0.0;
    if (usable) {
      const double inv_t = 1e9 / static_cast<double>(acc_ns_[i]);
      const double hn = std::hypot(acc_h_[2 * i], acc_h_[2 * i + 1]);
      const double hc = acc_h_[2 * i] / hn, hs = acc_h_[2 * i + 1] / hn;
      // The flow to base_link by the mount, to map by the mean heading.
      const double fx = sensor_velocity_[2 * i], fy = sensor_velocity_[2 * i + 1];
      const double bx = mount_cos_[i] * fx - mount_sin_[i] * fy;
      const double by = mount_sin_[i] * fx + mount_cos_[i] * fy;
      const double z[2] = {hc * bx - hs * by + acc_y_[2 * i] * inv_t,
                           hs * bx + hc * by + acc_y_[2 * i + 1] * inv_t};
      const double hm[4] = {1.0 - acc_m_[4 * i] * inv_t, -acc_m_[4 * i + 1] * inv_t,
                            -acc_m_[4 * i + 2] * inv_t, 1.0 - acc_m_[4 * i + 3] * inv_t};
      // H: (I - M_k(p)) on belt k's block.
      const auto b = static_cast<std::size_t>(k - 1);
      double* hb = scratch_.data() + 2 * dim_ * dim_;
      std::fill(hb, hb + 2 * dim_, 0.0);
      hb[2 + 2 * b] = hm[0];
      hb[3 + 2 * b] = hm[1];
      hb[dim_ + 2 + 2 * b] = hm[2];
      hb[dim_ + 3 + 2 * b] = hm[3];
      double nu[2], sd[2];
      if (!Update(hb, z, flow_sigma_ * flow_sigma_, nu, sd)) ++rejected_[b];
    }
    // The next window starts here.
    window_surface_[i] = sensor_surface_[i];
    acc_y_[2 * i] = acc_y_[2 * i + 1] = acc_h_[2 * i] = acc_h_[2 * i + 1] = 0.0;
    for (std::size_t m = 0; m < 4; ++m) acc_m_[4 * i + m] = 0.0;
    acc_ns_[i] = 0;
  }

  // 5. Each sensor's window over [t, t + dt]: the encoders' fit at its
  // point (map) with the surfaces under the wheels, and the heading. A
  // window that crosses onto another surface is not used.
  for (std::size_t i = 0; i < n_; ++i) {
    if (sensor_surface_[i] != window_surface_[i]) window_surface_[i] = -1;
    if (window_surface_[i] <= 0) continue;
    const double* cf = &fit_[i * 4 * w_];
    double fx = 0.0, fy = 0.0;
    double mb[4] = {0.0, 0.0, 0.0, 0.0};  // sum of wheel blocks on the sensor's belt (base_link)
    for (std::size_t j = 0; j < w_; ++j) {
      const double b00 = cf[2 * j], b01 = cf[2 * j + 1];
      const double b10 = cf[2 * w_ + 2 * j], b11 = cf[2 * w_ + 2 * j + 1];
      fx += b00 * wheel_velocity_[2 * j] + b01 * wheel_velocity_[2 * j + 1];
      fy += b10 * wheel_velocity_[2 * j] + b11 * wheel_velocity_[2 * j + 1];
      const auto kj = wheel_surface_[j];
      if (kj == window_surface_[i]) {
        mb[0] += b00;
        mb[1] += b01;
        mb[2] += b10;
        mb[3] += b11;
      } else if (kj > 0) {
        // A wheel on another belt: its estimate moves the point (known).
        const double ux = state_[2 + 2 * static_cast<std::size_t>(kj - 1)];
        const double uy = state_[3 + 2 * static_cast<std::size_t>(kj - 1)];
        const double ubx = c * ux + s * uy, uby = -s * ux + c * uy;
        fx += b00 * ubx + b01 * uby;
        fy += b10 * ubx + b11 * uby;
      }
    }
    acc_y_[2 * i] += (c * fx - s * fy) * h;
    acc_y_[2 * i + 1] += (s * fx + c * fy) * h;
    // R M R^T.
    const double rm[4] = {c * mb[0] - s * mb[2], c * mb[1] - s * mb[3], s * mb[0] + c * mb[2],
                          s * mb[1] + c * mb[3]};
    acc_m_[4 * i] += (rm[0] * c - rm[1] * s) * h;
    acc_m_[4 * i + 1] += (rm[0] * s + rm[1] * c) * h;
    acc_m_[4 * i + 2] += (rm[2] * c - rm[3] * s) * h;
    acc_m_[4 * i + 3] += (rm[2] * s + rm[3] * c) * h;
    acc_h_[2 * i] += c * h;
    acc_h_[2 * i + 1] += s * h;
    acc_ns_[i] += dt;
  }

  WriteOutputs(c, s);
  return cosim::StepResult::kOk;
}

void SurfaceFusionUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals = state_;
  for (const auto* v :
       {&cov_, &hist_p_, &last_count_, &acc_y_, &acc_m_, &acc_h_, &match_t_, &match_z_}) {
    state.reals.insert(state.reals.end(), v->begin(), v->end());
  }
  state.reals.push_back(last_match_count_);
  state.reals.push_back(dead_reckoning_[0]);
  state.reals.push_back(dead_reckoning_[1]);
  state.reals.push_back(imu_velocity_[0]);
  state.reals.push_back(imu_velocity_[1]);
  state.integers = {start_,
                    static_cast<std::int64_t>(first_),
                    static_cast<std::int64_t>(size_),
                    rejected_match_,
                    static_cast<std::int64_t>(match_first_),
                    static_cast<std::int64_t>(match_size_)};
  for (const auto* v : {&run_, &slope_run_, &imu_run_, &ramp_until_, &switches_, &rejected_,
                        &hist_t_, &window_surface_, &acc_ns_, &wheel_surface_, &sensor_surface_}) {
    state.integers.insert(state.integers.end(), v->begin(), v->end());
  }
}

void SurfaceFusionUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t nb = belts_.size();
  const std::size_t reals =
      dim_ + dim_ * dim_ + 2 * kHistory + n_ + 2 * n_ + 4 * n_ + 2 * n_ + 3 * kMatches + 5;
  const std::size_t integers = 6 + 6 + 3 * nb + kHistory + n_ + n_ + w_ + n_;
  if (state.reals.size() != reals || state.integers.size() != integers) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected " + std::to_string(reals) + " and " +
                           std::to_string(integers));
  }
  auto r = state.reals.begin();
  for (auto* v :
       {&state_, &cov_, &hist_p_, &last_count_, &acc_y_, &acc_m_, &acc_h_, &match_t_, &match_z_}) {
    std::copy(r, r + static_cast<std::ptrdiff_t>(v->size()), v->begin());
    r += static_cast<std::ptrdiff_t>(v->size());
  }
  last_match_count_ = *r++;
  dead_reckoning_[0] = *r++;
  dead_reckoning_[1] = *r++;
  imu_velocity_[0] = *r++;
  imu_velocity_[1] = *r++;
  auto k = state.integers.begin();
  start_ = *k++;
  first_ = static_cast<std::size_t>(*k++);
  size_ = static_cast<std::size_t>(*k++);
  rejected_match_ = *k++;
  match_first_ = static_cast<std::size_t>(*k++);
  match_size_ = static_cast<std::size_t>(*k++);
  for (auto* v : {&run_, &slope_run_, &imu_run_, &ramp_until_, &switches_, &rejected_, &hist_t_,
                  &window_surface_, &acc_ns_, &wheel_surface_, &sensor_surface_}) {
    std::copy(k, k + static_cast<std::ptrdiff_t>(v->size()), v->begin());
    k += static_cast<std::ptrdiff_t>(v->size());
  }
  // The parameters came back with the variables.
  Cache();
}

}  // namespace linesim::estimation
