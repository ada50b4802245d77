#include "units/estimation/scan_localizer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "units/estimation/laser_beams.h"

namespace linesim::estimation {

ScanLocalizer::ScanLocalizer(const char* type_name, std::string name, std::vector<int> beam_counts,
                             AngleWrap wrap_angle)
    : cosim::Unit(type_name, std::move(name)),
      beam_counts_(std::move(beam_counts)),
      wrap_angle_(wrap_angle) {
  if (beam_counts_.empty() || beam_counts_.size() > static_cast<std::size_t>(kMaxLasers)) {
    throw cosim::UnitError(Where() + ": beam_counts must list 1 to " + std::to_string(kMaxLasers) +
                           " lasers, got " + std::to_string(beam_counts_.size()));
  }
  std::size_t max_beams = 0;
  for (std::size_t k = 0; k < beam_counts_.size(); ++k) {
    if (beam_counts_[k] < 1 || beam_counts_[k] > 100000) {
      throw cosim::UnitError(Where() + ": beam_counts[" + std::to_string(k) +
                             "] must be 1..100000, got " + std::to_string(beam_counts_[k]));
    }
    max_beams = std::max(max_beams, static_cast<std::size_t>(beam_counts_[k]));
  }
  const std::size_t L = beam_counts_.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  initial_x_ = initial_y_ = initial_yaw_ = nan;
  for (std::vector<double>* list :
       {&mount_x_, &mount_y_, &mount_yaw_, &first_beam_angle_, &angular_step_, &scan_period_}) {
    list->assign(L, nan);
  }
  ranges_.resize(L);
  beam_cos_.resize(L);
  beam_sin_.resize(L);
  beam_dt_.resize(L);
  for (std::size_t k = 0; k < L; ++k) {
    const auto n = static_cast<std::size_t>(beam_counts_[k]);
    ranges_[k].assign(n, 0.0);
    beam_cos_[k].assign(n, 0.0);
    beam_sin_[k].assign(n, 0.0);
    beam_dt_[k].assign(n, 0.0);
  }
  for (std::vector<double>* per_laser : {&scan_count_, &scan_time_, &laser_status_, &last_count_}) {
    per_laser->assign(L, 0.0);
  }
  odometry_velocity_.assign(2, 0.0);
  position_.assign(2, 0.0);
  covariance_.assign(9, 0.0);
  hessian_.assign(9, 0.0);
  px_.assign(max_beams, 0.0);
  py_.assign(max_beams, 0.0);
  pz_.assign(max_beams, 0.0);
  order_.assign(L, 0);
  mid_offset_ns_.assign(L, 0);
  last_scan_ns_.assign(L, 0);
}

void ScanLocalizer::DeclareMountXY() {
  using cosim::Rule;
  variables().Parameter("mount_x", "m", &mount_x_, "per laser: its origin in base_link, x",
                        Rule::Finite().NoDefault());
  variables().Parameter("mount_y", "m", &mount_y_, "per laser: its origin in base_link, y",
                        Rule::Finite().NoDefault());
}

void ScanLocalizer::DeclareBeamGeometry(const char* mount_yaw_description) {
  using cosim::Rule;
  auto& v = variables();
  v.Parameter("mount_yaw", "rad", &mount_yaw_, mount_yaw_description, Rule::Finite().NoDefault());
  v.Parameter("first_beam_angle", "rad", &first_beam_angle_, "per laser: direction of beam 0",
              Rule::Range(-2 * std::numbers::pi, 2 * std::numbers::pi).NoDefault());
  v.Parameter("angular_step", "rad", &angular_step_, "per laser: angle between neighbouring beams",
              Rule::Range(0, false, std::numbers::pi, true).NoDefault());
  v.Parameter("scan_period", "s", &scan_period_, "per laser: one turn of the mirror (one scan)",
              Rule::Positive().NoDefault());
}

void ScanLocalizer::DeclareRangeLimits(const char* range_min_description,
                                       const char* usable_range_max_description) {
  variables().Parameter("range_min", "m", &range_min_, range_min_description,
                        cosim::Rule::NonNegative());
  variables().Parameter("usable_range_max", "m", &usable_range_max_, usable_range_max_description,
                        cosim::Rule::Positive());
}

void ScanLocalizer::DeclareStartPose(cosim::Rule rule, const char* x_description,
                                     const char* y_description, const char* yaw_description) {
  variables().Parameter("initial_x", "m", &initial_x_, x_description, rule);
  variables().Parameter("initial_y", "m", &initial_y_, y_description, rule);
  variables().Parameter("initial_yaw", "rad", &initial_yaw_, yaw_description, rule);
}

void ScanLocalizer::DeclareMotionPrediction(const char* prediction_description,
                                            const char* deskew_description,
                                            const char* timeout_description) {
  auto& v = variables();
  v.Parameter("motion_prediction", &motion_prediction_, prediction_description,
              cosim::Rule::OneOf({"none", "odometry"}));
  v.Parameter("deskew", &deskew_, deskew_description);
  v.Parameter("scan_timeout", "s", &scan_timeout_, timeout_description, cosim::Rule::Positive());
}

void ScanLocalizer::DeclareJumpLimits(const char* max_jump_description,
                                      const char* max_jump_yaw_description) {
  variables().Parameter("max_jump", "m", &max_jump_, max_jump_description, cosim::Rule::Positive());
  variables().Parameter("max_jump_yaw", "rad", &max_jump_yaw_, max_jump_yaw_description,
                        cosim::Rule::Positive());
}

void ScanLocalizer::DeclareMinPoints() {
  variables().Parameter("min_points", &min_points_,
                        "a scan with fewer usable returns is not matched (laser blacked out)",
                        cosim::Rule::Range(3, 100000));
}

void ScanLocalizer::DeclareCovarianceFloorPosition(const char* description) {
  variables().Parameter("covariance_floor_position", "m", &covariance_floor_position_, description,
                        cosim::Rule::NonNegative());
}

void ScanLocalizer::DeclareCovarianceFloorYaw() {
  variables().Parameter("covariance_floor_yaw", "rad", &covariance_floor_yaw_,
                        "added to the yaw sigma of the covariance (squared, on the diagonal)",
                        cosim::Rule::NonNegative());
}

void ScanLocalizer::DeclareScanInputs(std::size_t k) {
  auto& v = variables();
  const std::string s = std::to_string(k);
  v.Input("ranges_" + s, "m", &ranges_[k], "laser " + s + ": ranges of its last complete scan");
  v.Input("scan_count_" + s, "1", &scan_count_[k], "laser " + s + ": complete scans so far");
  v.Input("scan_time_" + s, "s", &scan_time_[k], "laser " + s + ": start time of its last scan");
}

void ScanLocalizer::DeclareOdometryInputs() {
  variables().Input(
      "odometry_velocity", "m/s", &odometry_velocity_,
      "odometry: velocity of base_link in base_link (motion_prediction odometry only)");
  variables().Input("odometry_yaw_rate", "rad/s", &odometry_yaw_rate_,
                    "odometry: yaw rate (motion_prediction odometry only)");
}

void ScanLocalizer::DeclarePoseOutputs() {
  variables().Output("position", "m", &position_, "base_link x, y in map (latest accepted match)",
                     {});
  variables().Output("yaw", "rad", &yaw_, "base_link yaw in map (latest accepted match)", {});
}

void ScanLocalizer::DeclareMatchOutputs(const char* covariance_description,
                                        const char* hessian_description) {
  auto& v = variables();
  v.Output("covariance", "1", &covariance_, covariance_description, {});
  v.Output("hessian", "1", &hessian_, hessian_description, {});
  v.Output("match_time", "s", &match_time_, "time the pose refers to (middle of the matched scan)",
           {});
  v.Output("match_count", "1", &match_count_, "accepted matches so far", {});
}

std::vector<cosim::ParameterProblem> ScanLocalizer::CheckParameters() const {
  auto problems = cosim::Unit::CheckParameters();
  AddLaserProblems(range_min_, usable_range_max_, beam_counts_, angular_step_, scan_period_,
                   scan_timeout_, problems);
  return problems;
}

void ScanLocalizer::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void ScanLocalizer::DeriveBeams() {
  odometry_prediction_ = motion_prediction_ == "odometry";
  for (std::size_t k = 0; k < beam_counts_.size(); ++k) {
    // The middle of the sweep: the time the matched pose refers to.
    mid_offset_ns_[k] =
        LaserBeams(mount_yaw_[k], first_beam_angle_[k], angular_step_[k], scan_period_[k],
                   beam_counts_[k], beam_cos_[k], beam_sin_[k], beam_dt_[k]);
  }
}

void ScanLocalizer::InitializeTracking() {
  estimate_ = {initial_x_, initial_y_, wrap_angle_(initial_yaw_)};
  estimate_ns_ = start_;
  odom_ = estimate_;
  odom_ns_ = start_;
  have_match_ = false;
  for (std::size_t k = 0; k < beam_counts_.size(); ++k) {
    last_count_[k] = scan_count_[k];
    last_scan_ns_[k] = start_;
    laser_status_[k] = 0.0;
  }
  position_ = {estimate_.x, estimate_.y};
  yaw_ = estimate_.yaw;
  std::fill(hessian_.begin(), hessian_.end(), 0.0);
  std::fill(covariance_.begin(), covariance_.end(), 0.0);
  match_time_ = cosim::NsToSeconds(start_);
  match_count_ = 0.0;
  source_ = 1.0;
}

ScanLocalizer::Pose ScanLocalizer::Predict(const Pose& p, double s) const {
  // Constant twist in base_link over s: the heading at the middle of the
  // interval (second order in the turn).
  const double mid = p.yaw + 0.5 * odometry_yaw_rate_ * s;
  const double c = std::cos(mid), sn = std::sin(mid);
  const double vx = odometry_scale_x_ * odometry_velocity_[0],
               vy = odometry_scale_y_ * odometry_velocity_[1];
  return {p.x + (c * vx - sn * vy) * s, p.y + (sn * vx + c * vy) * s,
          wrap_angle_(p.yaw + odometry_yaw_rate_ * s)};
}

std::size_t ScanLocalizer::CollectPoints(int k, double range_offset, bool deskew, double vx,
                                         double vy, double w, const Tilt* tilt) {
  const auto kk = static_cast<std::size_t>(k);
  const std::vector<double>& r = ranges_[kk];
  const std::vector<double>& bc = beam_cos_[kk];
  const std::vector<double>& bs = beam_sin_[kk];
  const double mx = mount_x_[kk], my = mount_y_[kk];
  // Deskew: the base at beam time t_i relative to the base at the match
  // time is displaced by v dt and turned by w dt (dt = t_i - t_match):
  // p_match = R(w dt) p_i + v dt; R to second order in w dt (w dt <= 0.02
  // rad for 1 rad/s over half of an S300 sweep: error below 1.5e-6 r).
  const double mid_s = cosim::NsToSeconds(mid_offset_ns_[kk]);
  // The tilt's rotation Ry(pitch) Rx(roll): x' = cp x + sp (sr y + cr z),
  // y' = cr y - sr z, z' = -sp x + cp (sr y + cr z).
  const double cp = tilt ? std::cos(tilt->pitch) : 1.0, sp = tilt ? std::sin(tilt->pitch) : 0.0;
  const double cr = tilt ? std::cos(tilt->roll) : 1.0, sr = tilt ? std::sin(tilt->roll) : 0.0;
  std::size_t n = 0;
  dropped_low_ = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (!(r[i] >= range_min_ && r[i] <= usable_range_max_) || r[i] <= 0.0) continue;
    const double ri = r[i] - range_offset;
    double x = mx + ri * bc[i], y = my + ri * bs[i];
    if (tilt) {
      const double up = sr * y + cr * tilt->mount_z;
      const double z = -sp * x + cp * up;
      if (z < tilt->min_z) {
        ++dropped_low_;
        continue;
      }
      pz_[n] = z;
      const double xh = cp * x + sp * up;
      y = cr * y - sr * tilt->mount_z;
      x = xh;
    }
    if (deskew) {
      const double dt = beam_dt_[kk][i] - mid_s;
      const double th = w * dt, c = 1.0 - 0.5 * th * th;
      const double xr = c * x - th * y, yr = th * x + c * y;
      x = xr + vx * dt;
      y = yr + vy * dt;
    }
    px_[n] = x;
    py_[n] = y;
    ++n;
  }
  return n;
}

ScanLocalizer::Pose ScanLocalizer::MatchStart(cosim::TimeNs match_ns) const {
  if (odometry_prediction_) return Predict(odom_, cosim::NsToSeconds(match_ns - odom_ns_));
  return estimate_;
}

bool ScanLocalizer::WithinJumpLimits(double x, double y, double yaw, const Pose& start) const {
  return std::hypot(x - start.x, y - start.y) <= max_jump_ &&
         std::abs(wrap_angle_(yaw - start.yaw)) <= max_jump_yaw_;
}

void ScanLocalizer::AcceptMatch(const Pose& matched, cosim::TimeNs match_ns) {
  estimate_ = matched;
  estimate_ns_ = match_ns;
  have_match_ = true;
  odom_ = matched;
  odom_ns_ = match_ns;
  match_time_ = cosim::NsToSeconds(match_ns);
  match_count_ += 1.0;
}

void ScanLocalizer::AddCovarianceFloors() {
  const double fp = covariance_floor_position_ * covariance_floor_position_;
  covariance_[0] += fp;
  covariance_[4] += fp;
  covariance_[8] += covariance_floor_yaw_ * covariance_floor_yaw_;
}

cosim::StepResult ScanLocalizer::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  const cosim::TimeNs end = t + dt;
  // The new scans, in the order of their match times (each scan's time
  // a time linesim represents: OrderNewScans converts it).
  for (std::size_t k = 0; k < scan_time_.size(); ++k) {
    if (scan_count_[k] != last_count_[k])
      InputTimeNs(scan_time_[k], "scan_time[" + std::to_string(k) + "]");
  }
  const int fresh = OrderNewScans(scan_count_, last_count_, scan_time_, mid_offset_ns_, order_);
  for (int j = 0; j < fresh; ++j) {
    const auto k = static_cast<std::size_t>(order_[static_cast<std::size_t>(j)]);
    const cosim::TimeNs scan_ns = cosim::SecondsToNs(scan_time_[k]);
    last_scan_ns_[k] = scan_ns;
    ProcessScan(static_cast<int>(k), scan_ns + mid_offset_ns_[k]);
  }
  // Lasers silent for longer than scan_timeout.
  const cosim::TimeNs timeout = cosim::SecondsToNs(scan_timeout_);
  for (int k = 0; k < laser_count(); ++k) {
    if (end - last_scan_ns_[static_cast<std::size_t>(k)] > timeout) SetStatus(k, 1);
  }
  // The odometry-moved pose, carried to the step's end.
  if (odometry_prediction_) {
    odom_ = Predict(odom_, cosim::NsToSeconds(end - odom_ns_));
    odom_ns_ = end;
  }
  const bool fresh_match = have_match_ && end - estimate_ns_ <= timeout;
  source_ = fresh_match ? 0.0 : 1.0;
  const Pose& out = (!fresh_match && odometry_prediction_) ? odom_ : estimate_;
  position_[0] = out.x;
  position_[1] = out.y;
  yaw_ = out.yaw;
  return cosim::StepResult::kOk;
}

void ScanLocalizer::SaveTracking(cosim::UnitState& state) const {
  state.integers = {start_, estimate_ns_, have_match_ ? 1 : 0, odom_ns_};
  state.integers.insert(state.integers.end(), last_scan_ns_.begin(), last_scan_ns_.end());
  state.reals = {estimate_.x, estimate_.y, estimate_.yaw, odom_.x, odom_.y, odom_.yaw};
  state.reals.insert(state.reals.end(), last_count_.begin(), last_count_.end());
}

void ScanLocalizer::RestoreTracking(const cosim::UnitState& state) {
  const std::size_t L = beam_counts_.size();
  start_ = state.integers[0];
  estimate_ns_ = state.integers[1];
  have_match_ = state.integers[2] != 0;
  odom_ns_ = state.integers[3];
  for (std::size_t k = 0; k < L; ++k) last_scan_ns_[k] = state.integers[4 + k];
  estimate_ = {state.reals[0], state.reals[1], state.reals[2]};
  odom_ = {state.reals[3], state.reals[4], state.reals[5]};
  for (std::size_t k = 0; k < L; ++k) last_count_[k] = state.reals[6 + k];
}

}  // namespace linesim::estimation
