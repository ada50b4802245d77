#include "units/estimation/wheel_odometry_unit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "models/angle.h"
#include "units/estimation/planar_arc.h"

namespace linesim::estimation {

namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
}  // namespace

WheelOdometryUnit::WheelOdometryUnit(std::string name, Kind kind, int wheels)
    : cosim::Unit(kTypeName, std::move(name)), kind_(kind), wheels_(wheels) {
  if (wheels < 2) {
    throw cosim::UnitError(Where() + ": wheels must be at least 2 (a twist needs two), got " +
                           std::to_string(wheels));
  }
  const auto w = static_cast<std::size_t>(wheels);
  channels_ = kind == Kind::kSwerve ? 2 * w : 2;
  wheel_x_.assign(w, kUnset);
  wheel_y_.assign(w, kUnset);
  counts_per_revolution_.assign(channels_, kUnset);
  counts_.assign(channels_, 0.0);
  surface_velocity_.assign(2 * w, 0.0);
  body_velocity_.assign(2, 0.0);
  raw_body_velocity_.assign(2, 0.0);
  wheel_velocity_.assign(2 * static_cast<std::size_t>(wheels), 0.0);
  position_.assign(2, 0.0);
  velocity_.assign(2, 0.0);
  solve_.assign(3 * 2 * w, 0.0);
  side_.assign(w, 0);
  committed_counts_.assign(channels_, 0);
  pending_counts_.assign(channels_, 0);
  scratch_raw_.assign(2 * w, 0.0);
  scratch_surface_.assign(2 * w, 0.0);

  const bool swerve = kind == Kind::kSwerve;
  auto& v = variables();
  v.Parameter("wheel_x", "m", &wheel_x_,
              swerve ? "x of each wheel's steering axis in base_link (robot-specific)"
                     : "x of each wheel's contact in base_link (robot-specific)",
              cosim::Rule::Required());
  v.Parameter("wheel_y", "m", &wheel_y_,
              swerve ? "y of each wheel's steering axis in base_link (robot-specific)"
                     : "y of each wheel's contact in base_link: > 0 left side, < 0 right side "
                       "(robot-specific)",
              cosim::Rule::Required());
  v.Parameter("wheel_radius", "m", &wheel_radius_, "rolling radius of the wheels (robot-specific)",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("counts_per_revolution", "1", &counts_per_revolution_,
              swerve ? "counts per joint revolution of each encoder channel: W steering joints, "
                       "then W drive joints (the wheel_encoder's; robot-specific)"
                     : "counts per wheel revolution of the left and the right drive channel "
                       "(the wheel_encoder's; robot-specific)",
              cosim::Rule::Positive().NoDefault().Count());
  if (!swerve) {
    v.Parameter("effective_track", "m", &effective_track_,
                "track that relates the sides' speed difference to the yaw rate, omega = "
                "(v_right - v_left) / effective_track; a skid-steer's exceeds its geometric "
                "track (the robot file gives it)",
                cosim::Rule::Positive().NoDefault());
  }
  v.Parameter("rectify", &rectify_,
              "paper 1 Eq. 3: add the absolute surface velocity under each wheel to its encoder "
              "velocity before solving the twist");
  v.Parameter("initial_x", "m", &initial_x_, "x of base_link in map at the start",
              cosim::Rule::Required());
  v.Parameter("initial_y", "m", &initial_y_, "y of base_link in map at the start",
              cosim::Rule::Required());
  v.Parameter("initial_yaw", "rad", &initial_yaw_, "yaw of base_link in map at the start",
              cosim::Rule::Required());

  v.Input("counts", "1", &counts_,
          swerve ? "encoder counts (the wheel_encoder's counts): W steering joints, then W "
                   "drive joints"
                 : "encoder counts of the left and the right drive motor");
  v.Input("surface_velocity", "m/s", &surface_velocity_,
          "absolute velocity of the surface under each wheel in base_link, vx, vy per wheel "
          "(the surface estimator's wheel_surface_velocity; 0 on the floor)");

  const std::vector<std::string> both = {"counts", "surface_velocity"};
  v.Output("body_velocity", "m/s", &body_velocity_,
           "vx, vy of base_link in base_link from the wheels (rectified by the surface velocity "
           "when rectify)",
           both);
  v.Output("yaw_rate", "rad/s", &yaw_rate_, "yaw rate from the wheels (rectified when rectify)",
           both);
  v.Output("raw_body_velocity", "m/s", &raw_body_velocity_,
           "vx, vy of base_link in base_link from the encoders alone (relative to the surface)",
           {"counts"});
  v.Output("raw_yaw_rate", "rad/s", &raw_yaw_rate_,
           "yaw rate from the encoders alone (relative to the surface)", {"counts"});
  v.Output("wheel_velocity", "m/s", &wheel_velocity_,
           "each wheel's velocity relative to the surface under it from the encoders alone, in "
           "base_link, vx vy per wheel (differential: the body's velocity at the wheel from the "
           "encoders' twist, since a skid-steer wheel scrubs)",
           {"counts"});
  v.Output("position", "m", &position_, "dead-reckoned x, y of base_link in map", both);
  v.Output("yaw", "rad", &yaw_, "dead-reckoned yaw of base_link in map, in (-pi, pi]", both);
  v.Output("velocity", "m/s", &velocity_,
           "body_velocity rotated into map by the dead-reckoned yaw: vx, vy", both);
}

std::vector<cosim::ParameterProblem> WheelOdometryUnit::CheckParameters() const {
  auto problems = cosim::Unit::CheckParameters();
  const auto w = static_cast<std::size_t>(wheels_);
  bool finite = true;
  for (std::size_t i = 0; i < w; ++i) {
    finite = finite && std::isfinite(wheel_x_[i]) && std::isfinite(wheel_y_[i]);
  }
  if (!finite) return problems;  // the rules name the unset ones
  if (kind_ == Kind::kSwerve) {
    bool apart = false;
    for (std::size_t i = 1; i < w; ++i) {
      apart = apart || wheel_x_[i] != wheel_x_[0] || wheel_y_[i] != wheel_y_[0];
    }
    if (!apart) {
      problems.push_back({"wheel_x", std::nullopt,
                          "the wheels are all at one point (wheel_x, wheel_y): the yaw rate "
                          "cannot be solved"});
    }
    return problems;
  }
  int sides[2] = {0, 0};
  for (std::size_t i = 0; i < w; ++i) {
    if (wheel_y_[i] == 0.0) {
      problems.push_back({"wheel_y", i, "must be > 0 (left) or < 0 (right), got 0"});
    } else {
      ++sides[wheel_y_[i] > 0.0 ? 0 : 1];
    }
  }
  if (sides[0] == 0 || sides[1] == 0) {
    problems.push_back({"wheel_y", std::nullopt,
                        std::string("no wheel on the ") + (sides[0] == 0 ? "left" : "right") +
                            " side (wheel_y " + (sides[0] == 0 ? "> 0" : "< 0") + ")"});
  }
  return problems;
}

void WheelOdometryUnit::Precompute() {
  const auto w = static_cast<std::size_t>(wheels_);
  if (kind_ == Kind::kSwerve) {
    // Rows per wheel: [1 0 -y_i] and [0 1 x_i]; solve = (A^T A)^-1 A^T.
    Eigen::MatrixXd a(2 * w, 3);
    for (std::size_t i = 0; i < w; ++i) {
      const auto r = static_cast<Eigen::Index>(2 * i);
      a.row(r) << 1.0, 0.0, -wheel_y_[i];
      a.row(r + 1) << 0.0, 1.0, wheel_x_[i];
    }
    const Eigen::MatrixXd pinv = (a.transpose() * a).ldlt().solve(a.transpose());
    for (Eigen::Index k = 0; k < 3; ++k) {
      for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(2 * w); ++j) {
        solve_[static_cast<std::size_t>(k) * 2 * w + static_cast<std::size_t>(j)] = pinv(k, j);
      }
    }
    return;
  }
  side_count_[0] = side_count_[1] = 0;
  for (std::size_t i = 0; i < w; ++i) {
    side_[i] = wheel_y_[i] > 0.0 ? 0 : 1;
    ++side_count_[side_[i]];
  }
}

void WheelOdometryUnit::Solve(const double* v, double twist[3]) const {
  if (kind_ == Kind::kSwerve) {
    const std::size_t n = 2 * static_cast<std::size_t>(wheels_);
    for (std::size_t k = 0; k < 3; ++k) {
      const double* row = &solve_[k * n];
      double s = 0.0;
      for (std::size_t j = 0; j < n; ++j) s += row[j] * v[j];
      twist[k] = s;
    }
    return;
  }
  // Left x, left y, right x, right y.
  twist[0] = 0.5 * (v[0] + v[2]);
  twist[1] = 0.5 * (v[1] + v[3]);
  twist[2] = (v[2] - v[0]) / effective_track_;
}

void WheelOdometryUnit::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void WheelOdometryUnit::Initialize() {
  ThrowIfBadParameters();
  Precompute();
  has_previous_ = false;
  now_ = start_;
  committed_time_ = start_;
  committed_pose_[0] = initial_x_;
  committed_pose_[1] = initial_y_;
  committed_pose_[2] = models::WrapAngle(initial_yaw_);
  std::fill(committed_counts_.begin(), committed_counts_.end(), 0);
  ComputeSample();
}

void WheelOdometryUnit::UpdateOutputs() { ComputeSample(); }

void WheelOdometryUnit::ComputeSample() {
  const auto w = static_cast<std::size_t>(wheels_);
  for (std::size_t c = 0; c < channels_; ++c) {
    if (!(std::abs(counts_[c]) <= cosim::kMaxExactCount)) {
      CheckCount(counts_[c], "counts[" + std::to_string(c) + "]");  // throws
    }
    pending_counts_[c] = static_cast<std::int64_t>(std::llround(counts_[c]));
  }
  const double interval_s = cosim::NsToSeconds(now_ - committed_time_);
  const bool rate_known = has_previous_ && interval_s > 0.0;
  // Rolling speed of a drive channel (m/s at the rim): the count difference
  // over the interval (an integer difference: exact).
  const auto rim_speed = [&](std::size_t c) {
    if (!rate_known) return 0.0;
    const double turned = static_cast<double>(pending_counts_[c] - committed_counts_[c]) * kTwoPi /
                          counts_per_revolution_[c];
    return wheel_radius_ * turned / interval_s;
  };

  double* raw = scratch_raw_.data();
  double* surf = scratch_surface_.data();
  if (kind_ == Kind::kSwerve) {
    for (std::size_t i = 0; i < w; ++i) {
      // The middle of the steering count; over the interval the mean of
      // its two ends (the shorter way round).
      const double quantum = kTwoPi / counts_per_revolution_[i];
      double a = (static_cast<double>(pending_counts_[i]) + 0.5) * quantum;
      if (rate_known) {
        const double a0 = (static_cast<double>(committed_counts_[i]) + 0.5) * quantum;
        a = a0 + 0.5 * models::WrapAngle(a - a0);
      }
      const double speed = rim_speed(w + i);
      raw[2 * i] = speed * std::cos(a);
      raw[2 * i + 1] = speed * std::sin(a);
      surf[2 * i] = surface_velocity_[2 * i];
      surf[2 * i + 1] = surface_velocity_[2 * i + 1];
    }
  } else {
    raw[0] = rim_speed(0);
    raw[1] = 0.0;
    raw[2] = rim_speed(1);
    raw[3] = 0.0;
    surf[0] = surf[1] = surf[2] = surf[3] = 0.0;
    for (std::size_t i = 0; i < w; ++i) {
      const auto s = static_cast<std::size_t>(side_[i]);
      const double share = 1.0 / side_count_[s];
      surf[2 * s] += share * surface_velocity_[2 * i];
      surf[2 * s + 1] += share * surface_velocity_[2 * i + 1];
    }
  }
  double raw_twist[3];
  Solve(raw, raw_twist);
  for (std::size_t i = 0; i < w; ++i) {
    if (kind_ == Kind::kSwerve) {
      // A steered wheel rolls without side slip: its own velocity.
      wheel_velocity_[2 * i] = raw[2 * i];
      wheel_velocity_[2 * i + 1] = raw[2 * i + 1];
    } else {
      // A skid-steer wheel scrubs: its rim speed is not the body's speed at
      // it; the body's twist (through the effective track) is.
      wheel_velocity_[2 * i] = raw_twist[0] - raw_twist[2] * wheel_y_[i];
      wheel_velocity_[2 * i + 1] = raw_twist[1] + raw_twist[2] * wheel_x_[i];
    }
  }
  double twist[3] = {raw_twist[0], raw_twist[1], raw_twist[2]};
  if (rectify_) {
    // Eq. 3 per wheel, and the solve is linear: solve(raw + surface) =
    // solve(raw) + solve(surface).
    double surface_twist[3];
    Solve(surf, surface_twist);
    for (int k = 0; k < 3; ++k) twist[k] += surface_twist[k];
  }
  raw_body_velocity_[0] = raw_twist[0];
  raw_body_velocity_[1] = raw_twist[1];
  raw_yaw_rate_ = raw_twist[2];
  body_velocity_[0] = twist[0];
  body_velocity_[1] = twist[1];
  yaw_rate_ = twist[2];

  // Dead reckoning: the exact arc of this interval's twist from the
  // committed pose.
  const double yaw0 = committed_pose_[2];
  double dx = 0.0, dy = 0.0;
  if (interval_s > 0.0) ArcDisplacement(twist[0], twist[1], twist[2], interval_s, &dx, &dy);
  const double c0 = std::cos(yaw0), s0 = std::sin(yaw0);
  pending_pose_[0] = committed_pose_[0] + c0 * dx - s0 * dy;
  pending_pose_[1] = committed_pose_[1] + s0 * dx + c0 * dy;
  pending_pose_[2] = models::WrapAngle(yaw0 + twist[2] * interval_s);
  position_[0] = pending_pose_[0];
  position_[1] = pending_pose_[1];
  yaw_ = pending_pose_[2];
  const double c1 = std::cos(yaw_), s1 = std::sin(yaw_);
  velocity_[0] = c1 * twist[0] - s1 * twist[1];
  velocity_[1] = s1 * twist[0] + c1 * twist[1];
}

cosim::StepResult WheelOdometryUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  // Commit the sample of t (UpdateOutputs or Initialize computed it); the
  // next one is at t + dt.
  committed_counts_ = pending_counts_;  // same size: no allocation
  committed_time_ = now_;
  for (int k = 0; k < 3; ++k) committed_pose_[k] = pending_pose_[k];
  has_previous_ = true;
  now_ = t + dt;
  return cosim::StepResult::kOk;
}

void WheelOdometryUnit::SaveInternal(cosim::UnitState& state) const {
  state.integers.assign(committed_counts_.begin(), committed_counts_.end());
  state.integers.insert(state.integers.end(), pending_counts_.begin(), pending_counts_.end());
  state.integers.push_back(committed_time_);
  state.integers.push_back(now_);
  state.integers.push_back(start_);
  state.integers.push_back(has_previous_ ? 1 : 0);
  state.reals.assign(committed_pose_, committed_pose_ + 3);
  state.reals.insert(state.reals.end(), pending_pose_, pending_pose_ + 3);
}

void WheelOdometryUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t ni = 2 * channels_ + 4;
  if (state.integers.size() != ni || state.reals.size() != 6) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.integers.size()) +
                           " integers and " + std::to_string(state.reals.size()) +
                           " reals, expected " + std::to_string(ni) + " and 6");
  }
  const auto mid = state.integers.begin() + static_cast<std::ptrdiff_t>(channels_);
  std::copy(state.integers.begin(), mid, committed_counts_.begin());
  std::copy(mid, mid + static_cast<std::ptrdiff_t>(channels_), pending_counts_.begin());
  committed_time_ = state.integers[2 * channels_];
  now_ = state.integers[2 * channels_ + 1];
  start_ = state.integers[2 * channels_ + 2];
  has_previous_ = state.integers[2 * channels_ + 3] != 0;
  std::copy(state.reals.begin(), state.reals.begin() + 3, committed_pose_);
  std::copy(state.reals.begin() + 3, state.reals.end(), pending_pose_);
  // The parameters came back with the variables.
  Precompute();
}

}  // namespace linesim::estimation
