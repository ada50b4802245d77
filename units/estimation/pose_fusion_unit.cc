#include "units/estimation/pose_fusion_unit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <utility>

#include "models/angle.h"
#include "units/estimation/planar_arc.h"

namespace linesim::estimation {

namespace {
using Vec5 = Eigen::Matrix<double, 5, 1>;
using Mat5 = Eigen::Matrix<double, 5, 5>;
}  // namespace

PoseFusionUnit::PoseFusionUnit(std::string name) : cosim::Unit(kTypeName, std::move(name)) {
  odometry_velocity_.assign(2, 0.0);
  imu_angular_velocity_.assign(3, 0.0);
  match_position_.assign(2, 0.0);
  match_covariance_.assign(9, 0.0);
  position_.assign(2, 0.0);
  velocity_.assign(2, 0.0);
  velocity_offset_.assign(2, 0.0);
  covariance_.assign(9, 0.0);

  auto& v = variables();
  v.Parameter("yaw_rate_source", &yaw_rate_source_,
              "what drives theta in the prediction: odometry (odometry_yaw_rate) or imu (the "
              "z rate of imu_angular_velocity)",
              cosim::Rule::OneOf({"odometry", "imu"}));
  // ASSUMPTION (no datasheet gives it): wheel odometry drifts by a few
  // per cent of the distance (slip, radius tolerance, floor unevenness);
  // 0.02 m/sqrt(s) is 2 cm of position uncertainty after 1 s, 2 % of the
  // distance at the robots' 1 m/s.
  v.Parameter("velocity_noise", "m/(s.Hz^0.5)", &velocity_noise_,
              "white-noise density of the odometry's velocity: each position coordinate's "
              "variance grows by velocity_noise^2 dt",
              cosim::Rule::Positive());
  // ASSUMPTION: 0.01 rad/sqrt(s) is 0.1 deg of heading uncertainty over a
  // 40 ms scan period (the scan matcher resolves about 0.3 deg) and 0.6 deg
  // after 1 s, the order of a skid-steer's scrub error. An ADIS16470 gyro
  // is better (angle random walk 0.34 deg/sqrt(h) = 1e-4 rad/sqrt(s),
  // Analog Devices ADIS16470 data sheet): set it lower with imu.
  v.Parameter("yaw_rate_noise", "rad/(s.Hz^0.5)", &yaw_rate_noise_,
              "white-noise density of the yaw rate: theta's variance grows by "
              "yaw_rate_noise^2 dt",
              cosim::Rule::Positive());
  // b is what the odometry misses: the surface's motion while it is not
  // (yet) rectified, as when a line starts under the robot before the
  // surface estimator follows it. Paper 1's figure for the surface's
  // variation in the on state (3 sigma = 1 cm/s per 0.1 s sample: 0.0105
  // m/s/sqrt(s)) leaves b a second and more behind such a start (hold_on_belt
  // closed loop: 0.19 m of drift); a line reaches 0.2 m/s in 0.4 s (its
  // 0.5 m/s^2), which a random walk covers at one sigma in that time with
  // about 0.2 / sqrt(0.4) = 0.3 m/s/sqrt(s). ASSUMPTION: 0.1 m/s/sqrt(s), the
  // smallest of 0.0105, 0.05, 0.1, 0.3 that took the drift under 0.1 m
  // (0.19, 0.11, 0.093, 0.081 m; the crossing 4.8, 5.0, 5.3, 5.0 mm).
  v.Parameter("offset_random_walk", "m/(s2.Hz^0.5)", &offset_random_walk_,
              "random-walk intensity of the velocity offset b: each coordinate's variance grows "
              "by offset_random_walk^2 dt (0 with initial_offset_sigma 0: b stays 0, a 3-state "
              "EKF on x, y, yaw, as for a skid-steer robot off the belt line, paper 2)",
              cosim::Rule::NonNegative());
  // ASSUMPTIONS: the start pose is known to a tenth of a metre and radian
  // (the scenario gives it); b starts at 0 with the representative belt
  // speed of automotive lines, 0.1 m/s (paper 1, Sec. V), as its sigma.
  v.Parameter("initial_position_sigma", "m", &initial_position_sigma_,
              "standard deviation of the initial x and y", cosim::Rule::Positive());
  v.Parameter("initial_yaw_sigma", "rad", &initial_yaw_sigma_,
              "standard deviation of the initial yaw", cosim::Rule::Positive());
  v.Parameter("initial_offset_sigma", "m/s", &initial_offset_sigma_,
              "standard deviation of the initial velocity offset (b starts at 0; 0 keeps it 0 "
              "with offset_random_walk 0)",
              cosim::Rule::NonNegative());
  // The finest hector_mapping grid cell is 0.025 m (paper 1's
  // localization): a match is not better than its quantization,
  // 0.025 / sqrt(12) = 7 mm; 0.01 m with margin. Yaw: 0.005 rad, the angle
  // of one cell seen 5 m away.
  v.Parameter("position_floor", "m", &position_floor_,
              "least standard deviation of a match's x and y (raises the covariance's "
              "diagonal)",
              cosim::Rule::Positive());
  v.Parameter("yaw_floor", "rad", &yaw_floor_,
              "least standard deviation of a match's yaw (raises the covariance's diagonal)",
              cosim::Rule::Positive());
  // Chi-square with 3 degrees of freedom: P(d^2 <= 16.27) = 0.999.
  v.Parameter("gate", "1", &gate_,
              "Mahalanobis gate: a match with y^T S^-1 y above this is refused (16.27: 99.9 % "
              "of chi-square with 3 degrees of freedom)",
              cosim::Rule::Positive());
  // ASSUMPTION: 0.5 s is 12 scan periods of the S300 (25 Hz): a few
  // refused or missing scans do not count, a blackout does.
  v.Parameter("timeout", "s", &timeout_,
              "source becomes 1 (odometry only) when no match was accepted for longer than this",
              cosim::Rule::Positive());
  v.Parameter("initial_x", "m", &initial_x_, "x of base_link in map at the start",
              cosim::Rule::Required());
  v.Parameter("initial_y", "m", &initial_y_, "y of base_link in map at the start",
              cosim::Rule::Required());
  v.Parameter("initial_yaw", "rad", &initial_yaw_, "yaw of base_link in map at the start",
              cosim::Rule::Required());

  v.Input("odometry_velocity", "m/s", &odometry_velocity_,
          "vx, vy of base_link in base_link from the wheel odometry (its body_velocity)");
  v.Input("odometry_yaw_rate", "rad/s", &odometry_yaw_rate_,
          "yaw rate from the wheel odometry (its yaw_rate)");
  v.Input("base_pitch", "rad", &base_pitch_,
          "the base's pitch (ROS: + nose down): the odometry's vx is projected on the map by "
          "its cosine (0: level)");
  v.Input("base_roll", "rad", &base_roll_,
          "the base's roll: the odometry's vy is projected on the map by its cosine (0: level)");
  v.Input("imu_angular_velocity", "rad/s", &imu_angular_velocity_,
          "angular velocity from the IMU (its frame ~ base_link); z is used with "
          "yaw_rate_source = imu");
  v.Input("match_position", "m", &match_position_, "x, y of base_link in map from the scan match");
  v.Input("match_yaw", "rad", &match_yaw_, "yaw of base_link in map from the scan match");
  v.Input("match_covariance", "1", &match_covariance_,
          "covariance of the match's x (m), y (m), yaw (rad): 3 x 3 row-major, SI units");
  v.Input("match_time", "s", &match_time_, "time the match refers to (the scan's time)");
  v.Input("match_count", "1", &match_count_, "matches so far: a new match when it changes");

  v.Output("position", "m", &position_, "x, y of base_link in map", {});
  v.Output("yaw", "rad", &yaw_, "yaw of base_link in map, in (-pi, pi]", {});
  v.Output("velocity", "m/s", &velocity_,
           "vx, vy of base_link in map: R(yaw) odometry_velocity + velocity_offset", {});
  v.Output("yaw_rate", "rad/s", &yaw_rate_, "yaw rate the prediction used", {});
  v.Output("velocity_offset", "m/s", &velocity_offset_,
           "b: the map-frame velocity the odometry misses (unrectified surface motion, slip)", {});
  v.Output("covariance", "1", &covariance_,
           "covariance of x (m), y (m), yaw (rad): 3 x 3 row-major, SI units", {});
  v.Output("source", "1", &source_,
           "0: fused (a match accepted within timeout); 1: odometry only (none accepted for "
           "longer than timeout, or none yet)",
           {});
  v.Output("rejected_matches", "1", &rejected_matches_,
           "matches refused so far (gate, older than the history, or out of order)", {});
  v.Output("accepted_matches", "1", &accepted_matches_, "matches applied so far", {});
  v.Output("resets", "1", &resets_,
           "restarts from a match: a match the gate refused while none had been accepted for "
           "longer than timeout (the odometry alone drifted out of the gate; the matcher's own "
           "checks passed it)",
           {});
}

std::vector<cosim::ParameterProblem> PoseFusionUnit::CheckParameters() const {
  return cosim::Unit::CheckParameters();
}

void PoseFusionUnit::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void PoseFusionUnit::Initialize() {
  ThrowIfBadParameters();
  use_imu_ = yaw_rate_source_ == "imu";
  Entry e;
  e.t = start_;
  Eigen::Map<Vec5>(e.x) << initial_x_, initial_y_, models::WrapAngle(initial_yaw_), 0.0, 0.0;
  const double sp = initial_position_sigma_ * initial_position_sigma_;
  const double sb = initial_offset_sigma_ * initial_offset_sigma_;
  Eigen::Map<Mat5> p(e.p);
  p.setZero();
  p.diagonal() << sp, sp, initial_yaw_sigma_ * initial_yaw_sigma_, sb, sb;
  first_ = 0;
  size_ = 0;
  Push(e);
  last_match_count_ = 0.0;
  last_match_time_ = kNoMatch;
  rejected_matches_ = 0.0;
  accepted_matches_ = 0.0;
  resets_ = 0.0;
  yaw_rate_ = 0.0;
  ComputeOutputs();
}

void PoseFusionUnit::Push(const Entry& e) {
  if (size_ < kHistory) {
    ++size_;
  } else {
    first_ = (first_ + 1) % kHistory;
  }
  At(size_ - 1) = e;
}

void PoseFusionUnit::Predict(double* xs, double* ps, double vx, double vy, double omega,
                             double dt_s) const {
  Eigen::Map<Vec5> x(xs);
  Eigen::Map<Mat5> p(ps);
  double dx, dy;
  ArcDisplacement(vx, vy, omega, dt_s, &dx, &dy);
  const double c = std::cos(x(2)), s = std::sin(x(2));
  const double mx = c * dx - s * dy, my = s * dx + c * dy;  // the arc in map
  x(0) += mx + x(3) * dt_s;
  x(1) += my + x(4) * dt_s;
  x(2) = models::WrapAngle(x(2) + omega * dt_s);
  // F = I + d/dtheta of the arc in map, + dt on the offset columns.
  Mat5 f = Mat5::Identity();
  f(0, 2) = -my;
  f(1, 2) = mx;
  f(0, 3) = dt_s;
  f(1, 4) = dt_s;
  p = f * p * f.transpose();
  const double qv = velocity_noise_ * velocity_noise_ * dt_s;
  const double qb = offset_random_walk_ * offset_random_walk_ * dt_s;
  p(0, 0) += qv;
  p(1, 1) += qv;
  p(2, 2) += yaw_rate_noise_ * yaw_rate_noise_ * dt_s;
  p(3, 3) += qb;
  p(4, 4) += qb;
}

bool PoseFusionUnit::Correct(double* xs, double* ps, const double zs[3], const double rs[9]) const {
  Eigen::Map<Vec5> x(xs);
  Eigen::Map<Mat5> p(ps);
  const Eigen::Map<const Eigen::Vector3d> z(zs);
  const Eigen::Map<const Eigen::Matrix3d> r(rs);
  Eigen::Vector3d y = z - x.head<3>();
  y(2) = models::WrapAngle(y(2));
  const Eigen::Matrix3d s = p.topLeftCorner<3, 3>() + r;
  const Eigen::LLT<Eigen::Matrix3d> llt(s);
  if (llt.info() != Eigen::Success) return false;
  const double d2 = y.dot(llt.solve(y));
  if (!(d2 <= gate_)) return false;
  // K = P H^T S^-1 with H = [I3 0]; Joseph form keeps P symmetric and
  // positive.
  const Eigen::Matrix<double, 5, 3> k = llt.solve(p.leftCols<3>().transpose()).transpose();
  x += k * y;
  x(2) = models::WrapAngle(x(2));
  Mat5 ikh = Mat5::Identity();
  ikh.leftCols<3>() -= k;
  p = ikh * p * ikh.transpose() + k * r * k.transpose();
  return true;
}

void PoseFusionUnit::Reset(double* xs, double* ps, const double zs[3], const double rs[9]) const {
  Eigen::Map<Vec5> x(xs);
  Eigen::Map<Mat5> p(ps);
  x.head<3>() = Eigen::Map<const Eigen::Vector3d>(zs);
  const double pb = initial_offset_sigma_ * initial_offset_sigma_;
  p.setZero();
  p.topLeftCorner<3, 3>() = Eigen::Map<const Eigen::Matrix3d>(rs);
  p(3, 3) = pb;
  p(4, 4) = pb;
}

bool PoseFusionUnit::ApplyMatch(cosim::TimeNs time, bool reset) {
  const Entry& newest = At(size_ - 1);
  if (time > newest.t) time = newest.t;  // not in the future
  if (time < At(0).t || time < last_match_time_) return false;
  // The newest entry at or before the match.
  std::size_t j = size_ - 1;
  while (At(j).t > time) --j;

  const double z[3] = {match_position_[0], match_position_[1], match_yaw_};
  double r[9];
  for (std::size_t a = 0; a < 3; ++a) {
    for (std::size_t b = 0; b < 3; ++b) {
      r[3 * a + b] = 0.5 * (match_covariance_[3 * a + b] + match_covariance_[3 * b + a]);
    }
  }
  r[0] = std::max(r[0], position_floor_ * position_floor_);
  r[4] = std::max(r[4], position_floor_ * position_floor_);
  r[8] = std::max(r[8], yaw_floor_ * yaw_floor_);

  // x, P carried from entry j to the match and on to now.
  Entry w = At(j);
  double* x = w.x;
  double* p = w.p;
  const bool inside = j + 1 < size_ && time > At(j).t;
  if (inside) {
    const Entry& next = At(j + 1);
    Predict(x, p, next.vx, next.vy, next.omega, cosim::NsToSeconds(time - At(j).t));
  }
  if (reset) {
    Reset(x, p, z, r);
  } else if (!Correct(x, p, z, r)) {
    return false;
  }
  last_match_time_ = time;
  const auto store = [&](Entry& e) {
    std::copy(x, x + 5, e.x);
    std::copy(p, p + 25, e.p);
  };
  if (!inside) {
    store(At(j));
  } else {
    // The rest of the step the match fell in, then the later steps again.
    Entry& next = At(j + 1);
    Predict(x, p, next.vx, next.vy, next.omega, cosim::NsToSeconds(next.t - time));
    store(next);
  }
  for (std::size_t k = j + (inside ? 2 : 1); k < size_; ++k) {
    Entry& e = At(k);
    Predict(x, p, e.vx, e.vy, e.omega, cosim::NsToSeconds(e.t - At(k - 1).t));
    store(e);
  }
  return true;
}

cosim::StepResult PoseFusionUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  Entry e = At(size_ - 1);
  e.t = t + dt;
  // The wheels' travel projected on the map's plane (1 on the level).
  e.vx = std::cos(base_pitch_) * odometry_velocity_[0];
  e.vy = std::cos(base_roll_) * odometry_velocity_[1];
  e.omega = use_imu_ ? imu_angular_velocity_[2] : odometry_yaw_rate_;
  Predict(e.x, e.p, e.vx, e.vy, e.omega, cosim::NsToSeconds(dt));
  Push(e);
  yaw_rate_ = e.omega;

  if (match_count_ != last_match_count_) {
    last_match_count_ = match_count_;
    const auto time = InputTimeNs(match_time_, "match_time");
    // Fused up to now: the state predicts where the match should be.
    const bool fused =
        last_match_time_ != kNoMatch && cosim::NsToSeconds(e.t - last_match_time_) <= timeout_;
    if (ApplyMatch(time)) {
      accepted_matches_ += 1.0;
    } else {
      rejected_matches_ += 1.0;
      // On the odometry alone for longer than timeout and refused again:
      // the odometry drifted (a wrong surface velocity in Eq. 3, slip), and
      // waiting for a match inside the gate would never end. The matcher
      // passed its own tests, so the pose restarts from it.
      // The same when the first match is refused (a start pose off by more
      // than the gate) once the history reaches back timeout.
      const bool waited =
          last_match_time_ != kNoMatch || cosim::NsToSeconds(e.t - At(0).t) > timeout_;
      if (!fused && waited && ApplyMatch(time, true)) resets_ += 1.0;
    }
  }
  ComputeOutputs();
  return cosim::StepResult::kOk;
}

void PoseFusionUnit::ComputeOutputs() {
  const Entry& e = At(size_ - 1);
  position_[0] = e.x[0];
  position_[1] = e.x[1];
  yaw_ = e.x[2];
  velocity_offset_[0] = e.x[3];
  velocity_offset_[1] = e.x[4];
  const double c = std::cos(e.x[2]), s = std::sin(e.x[2]);
  velocity_[0] = c * e.vx - s * e.vy + e.x[3];
  velocity_[1] = s * e.vx + c * e.vy + e.x[4];
  for (std::size_t a = 0; a < 3; ++a) {
    for (std::size_t b = 0; b < 3; ++b) covariance_[3 * a + b] = e.p[a + 5 * b];
  }
  const bool fused =
      last_match_time_ != kNoMatch && cosim::NsToSeconds(e.t - last_match_time_) <= timeout_;
  source_ = fused ? 0.0 : 1.0;
}

// Per entry: t (integer), x (5), P (25), vx, vy, omega (reals), oldest
// first; then the scalars.
namespace {
constexpr std::size_t kRealsPerEntry = 5 + 25 + 3;
}  // namespace

void PoseFusionUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals.clear();
  state.integers.clear();
  state.reals.reserve(size_ * kRealsPerEntry + 1);
  for (std::size_t k = 0; k < size_; ++k) {
    const Entry& e = At(k);
    state.integers.push_back(e.t);
    state.reals.insert(state.reals.end(), e.x, e.x + 5);
    state.reals.insert(state.reals.end(), e.p, e.p + 25);
    state.reals.push_back(e.vx);
    state.reals.push_back(e.vy);
    state.reals.push_back(e.omega);
  }
  state.reals.push_back(last_match_count_);
  state.integers.push_back(last_match_time_);
  state.integers.push_back(start_);
  state.integers.push_back(use_imu_ ? 1 : 0);
}

void PoseFusionUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t n = state.integers.size() < 3 ? 0 : state.integers.size() - 3;
  if (state.integers.size() < 4 || n > kHistory || state.reals.size() != n * kRealsPerEntry + 1) {
    throw cosim::UnitError(
        Where() + ": saved state has " + std::to_string(state.integers.size()) + " integers and " +
        std::to_string(state.reals.size()) +
        " reals, expected 3 + n and 33 n + 1 for 1 <= n <= " + std::to_string(kHistory));
  }
  first_ = 0;
  size_ = n;
  const double* r = state.reals.data();
  for (std::size_t k = 0; k < n; ++k) {
    Entry& e = history_[k];
    e.t = state.integers[k];
    std::copy(r, r + 5, e.x);
    std::copy(r + 5, r + 30, e.p);
    e.vx = r[30];
    e.vy = r[31];
    e.omega = r[32];
    r += kRealsPerEntry;
  }
  last_match_count_ = *r;
  last_match_time_ = state.integers[n];
  start_ = state.integers[n + 1];
  use_imu_ = state.integers[n + 2] != 0;
}

}  // namespace linesim::estimation
