#include "units/estimation/laser_beams.h"
#include "units/estimation/laser_localization_unit.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <utility>

namespace linesim::estimation {
namespace {

double WrapAngle(double a) {
  a = std::remainder(a, 2.0 * std::numbers::pi);
  return a;
}

}  // namespace

LaserLocalizationUnit::LaserLocalizationUnit(std::string name, const models::Scene& scene,
                                             std::vector<int> beam_counts)
    : cosim::Unit(kTypeName, std::move(name)), beam_counts_(std::move(beam_counts)) {
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
  for (const models::Obstacle& o : scene.obstacles) solids_.push_back(o.solid);
  floor_ = scene.floor;

  const std::size_t L = beam_counts_.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  initial_x_ = initial_y_ = initial_yaw_ = nan;
  mount_x_.assign(L, nan);
  mount_y_.assign(L, nan);
  mount_z_.assign(L, nan);
  mount_yaw_.assign(L, nan);
  first_beam_angle_.assign(L, nan);
  angular_step_.assign(L, nan);
  scan_period_.assign(L, nan);
  ranges_.resize(L);
  for (std::size_t k = 0; k < L; ++k)
    ranges_[k].assign(static_cast<std::size_t>(beam_counts_[k]), 0.0);
  scan_count_.assign(L, 0.0);
  scan_time_.assign(L, 0.0);
  odometry_velocity_.assign(2, 0.0);
  position_.assign(2, 0.0);
  velocity_.assign(2, 0.0);
  covariance_.assign(9, 0.0);
  hessian_.assign(9, 0.0);
  laser_status_.assign(L, 0.0);
  beam_cos_.resize(L);
  beam_sin_.resize(L);
  beam_dt_.resize(L);
  for (std::size_t k = 0; k < L; ++k) {
    const auto n = static_cast<std::size_t>(beam_counts_[k]);
    beam_cos_[k].assign(n, 0.0);
    beam_sin_[k].assign(n, 0.0);
    beam_dt_[k].assign(n, 0.0);
  }
  mid_offset_ns_.assign(L, 0);
  px_.assign(max_beams, 0.0);
  py_.assign(max_beams, 0.0);
  order_.assign(L, 0);
  last_count_.assign(L, 0.0);
  last_scan_ns_.assign(L, 0);
  mapped_.assign(L, 0);
  last_map_pose_.assign(L, Pose{});

  using cosim::Rule;
  auto& v = variables();
  const auto list = [&](const char* key, const char* unit, std::vector<double>* x, const char* what,
                        Rule rule) { v.Parameter(key, unit, x, what, rule); };
  list("mount_x", "m", &mount_x_, "per laser: its origin in base_link, x",
       Rule::Finite().NoDefault());
  list("mount_y", "m", &mount_y_, "per laser: its origin in base_link, y",
       Rule::Finite().NoDefault());
  list("mount_z", "m", &mount_z_,
       "per laser: its height above the floor (the scan plane: which solids are in the map)",
       Rule::Finite().NoDefault());
  list("mount_yaw", "rad", &mount_yaw_,
       "per laser: its yaw in base_link (roll and pitch ignored: 3-DoF like hector)",
       Rule::Finite().NoDefault());
  list("first_beam_angle", "rad", &first_beam_angle_, "per laser: direction of beam 0",
       Rule::Range(-2 * std::numbers::pi, 2 * std::numbers::pi).NoDefault());
  list("angular_step", "rad", &angular_step_, "per laser: angle between neighbouring beams",
       Rule::Range(0, false, std::numbers::pi, true).NoDefault());
  list("scan_period", "s", &scan_period_, "per laser: one turn of the mirror (one scan)",
       Rule::Positive().NoDefault());
  v.Parameter("range_min", "m", &range_min_,
              "nearer returns are skipped (hector_mapping laser_min_dist default 0.4)",
              Rule::NonNegative());
  v.Parameter("usable_range_max", "m", &usable_range_max_,
              "farther returns are skipped (hector_mapping laser_max_dist default 30)",
              Rule::Positive());
  v.Parameter("map_resolution", "m", &map_resolution_,
              "finest map cell (hector map_resolution default 0.025)", Rule::Range(0.005, 1.0));
  v.Parameter("map_levels", &map_levels_,
              "map levels, level i cell = map_resolution * 2^i (hector default 3)",
              Rule::OneOf({1, 2, 3, 4, 5, 6}));
  v.Parameter("coarse_iterations", &coarse_iterations_,
              "Gauss-Newton iterations on each coarser level (hector: 3)",
              Rule::OneOf({1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
  v.Parameter("fine_iterations", &fine_iterations_,
              "Gauss-Newton iterations on the finest level (hector: 5)",
              Rule::OneOf({1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
  v.Parameter("max_angle_step", "rad", &max_angle_step_,
              "each Gauss-Newton yaw update is clamped to +-this (hector: 0.2)",
              Rule::Range(0, false, 1, true));
  v.Parameter("initial_x", "m", &initial_x_, "start pose in map, x (as an AMCL initial pose)",
              Rule::Required());
  v.Parameter("initial_y", "m", &initial_y_, "start pose in map, y", Rule::Required());
  v.Parameter("initial_yaw", "rad", &initial_yaw_, "start pose in map, yaw", Rule::Required());
  v.Parameter("motion_prediction", &motion_prediction_,
              "none: each match starts from the last estimate (hector); odometry: moved by the "
              "odometry twist since",
              Rule::OneOf({"none", "odometry"}));
  v.Parameter("deskew", &deskew_,
              "move each beam's point from its time to the match time by the last velocity "
              "estimate");
  v.Parameter("scan_timeout", "s", &scan_timeout_,
              "a laser without a new scan for this long has status 1; without an accepted "
              "match for this long the source is 1",
              Rule::Positive());
  v.Parameter("max_cost", "1", &max_cost_,
              "a match whose mean squared residual exceeds this is rejected",
              Rule::Range(0, false, 4, true));
  v.Parameter("max_position_sigma", "m", &max_position_sigma_,
              "a match whose own position sigma (unfloored covariance) exceeds this is rejected "
              "(near-singular Hessian)",
              Rule::Positive());
  v.Parameter("max_yaw_sigma", "rad", &max_yaw_sigma_,
              "a match whose own yaw sigma exceeds this is rejected", Rule::Positive());
  v.Parameter("max_jump", "m", &max_jump_,
              "a match farther than this from its start pose is rejected", Rule::Positive());
  v.Parameter("max_jump_yaw", "rad", &max_jump_yaw_,
              "a match turned more than this from its start pose is rejected", Rule::Positive());
  v.Parameter("velocity_window", "s", &velocity_window_,
              "velocity and yaw_rate: the pose change over the accepted matches of this long "
              "(default 0.2 s, ASSUMPTION: 10 matches of two S300, about 0.02 m/s of noise from "
              "a 3 mm pose noise, 0.1 s of lag; 0: between the last two matches, as hector)",
              Rule::Range(0.0, 1.0));
  v.Parameter("min_points", &min_points_,
              "a scan with fewer usable returns is not matched (laser blacked out)",
              Rule::Range(3, 100000));
  v.Parameter("covariance_floor_position", "m", &covariance_floor_position_,
              "added to the position sigmas of the covariance (squared, on the diagonal)",
              Rule::NonNegative());
  v.Parameter("covariance_floor_yaw", "rad", &covariance_floor_yaw_,
              "added to the yaw sigma of the covariance (squared, on the diagonal)",
              Rule::NonNegative());
  v.Parameter("map", &map_,
              "scene: the map built from the scene's solids before time zero; mapping: learned "
              "from the scans while driving, as hector_mapping (starts unknown)",
              Rule::OneOf({"scene", "mapping"}));
  v.Parameter("map_update_distance_thresh", "m", &map_update_distance_thresh_,
              "map: mapping: a laser's accepted scan enters the map when the pose moved more "
              "than this since that laser last entered it (hector_mapping's parameter of this "
              "name, 0.4 in its mapping_default.launch)",
              Rule::NonNegative());
  v.Parameter("map_update_angle_thresh", "rad", &map_update_angle_thresh_,
              "map: mapping: ... or turned more than this (hector_mapping, 0.06 in its "
              "mapping_default.launch)",
              Rule::NonNegative());
  v.Parameter("update_factor_occupied", "1", &update_factor_occupied_,
              "map: mapping: probability a hit stands for, log-odds log(p / (1 - p)) added to "
              "the beam's end cell (hector_mapping's parameter, 0.9 in mapping_default.launch)",
              Rule::Range(0.5, false, 1.0, false));
  v.Parameter("update_factor_free", "1", &update_factor_free_,
              "map: mapping: probability a miss stands for, added to the cells a beam passes "
              "(hector_mapping's parameter, 0.4 in mapping_default.launch)",
              Rule::Range(0.0, false, 0.5, false));

  for (std::size_t k = 0; k < L; ++k) {
    const std::string s = std::to_string(k);
    v.Input("ranges_" + s, "m", &ranges_[k], "laser " + s + ": ranges of its last complete scan");
    v.Input("scan_count_" + s, "1", &scan_count_[k], "laser " + s + ": complete scans so far");
    v.Input("scan_time_" + s, "s", &scan_time_[k], "laser " + s + ": start time of its last scan");
  }
  v.Input("odometry_velocity", "m/s", &odometry_velocity_,
          "odometry: velocity of base_link in base_link (motion_prediction odometry only)");
  v.Input("odometry_yaw_rate", "rad/s", &odometry_yaw_rate_,
          "odometry: yaw rate (motion_prediction odometry only)");

  v.Output("position", "m", &position_, "base_link x, y in map (latest accepted match)", {});
  v.Output("yaw", "rad", &yaw_, "base_link yaw in map (latest accepted match)", {});
  v.Output("velocity", "m/s", &velocity_,
           "base_link velocity in map: the pose change over the accepted matches of the last "
           "velocity_window",
           {});
  v.Output("yaw_rate", "rad/s", &yaw_rate_,
           "yaw rate: the heading change over the accepted matches of the last velocity_window",
           {});
  v.Output("covariance", "1", &covariance_,
           "row-major 3 x 3 of x (m), y (m), yaw (rad): sigma_r^2 H^-1 + floor", {});
  v.Output("hessian", "1", &hessian_,
           "row-major 3 x 3 Gauss-Newton Hessian of the latest accepted match (1/m^2, 1/(m rad), "
           "1/rad^2)",
           {});
  v.Output("match_time", "s", &match_time_, "time the pose refers to (middle of the matched scan)",
           {});
  v.Output("match_count", "1", &match_count_, "accepted matches so far", {});
  v.Output("match_cost", "1", &match_cost_,
           "mean squared residual (1 - M)^2 of the latest accepted match", {});
  v.Output("laser_status", "1", &laser_status_,
           "per laser: 0 ok, 1 no new scan within scan_timeout, 2 blacked out (fewer than "
           "min_points returns), 3 last match rejected",
           {});
  v.Output("map_updates", "1", &map_updates_,
           "map: mapping: scans entered into the learned map so far (0 with map: scene)", {});
  v.Output("source", "1", &source_,
           "0: pose from a match within scan_timeout; 1: no usable laser, the pose held (or "
           "predicted by odometry with motion_prediction odometry)",
           {});
}

LaserLocalizationUnit::~LaserLocalizationUnit() = default;

std::vector<cosim::ParameterProblem> LaserLocalizationUnit::CheckParameters() const {
  auto problems = cosim::Unit::CheckParameters();
  AddLaserProblems(range_min_, usable_range_max_, beam_counts_, angular_step_, scan_period_,
                   scan_timeout_, problems);
  return problems;
}

void LaserLocalizationUnit::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void LaserLocalizationUnit::Derive() {
  odometry_prediction_ = motion_prediction_ == "odometry";
  mapping_ = map_ == "mapping";
  for (std::size_t k = 0; k < beam_counts_.size(); ++k) {
    // The middle of the sweep: the time the matched pose refers to.
    mid_offset_ns_[k] = LaserBeams(mount_yaw_[k], first_beam_angle_[k], angular_step_[k],
                                   scan_period_[k], beam_counts_[k], beam_cos_[k], beam_sin_[k],
                                   beam_dt_[k]);
  }
  // The map, once per set of the values it depends on.
  if (mapping_ && (!grid_ || grid_map_ != map_ || grid_resolution_ != map_resolution_ ||
                   grid_levels_ != map_levels_ || grid_occupied_ != update_factor_occupied_ ||
                   grid_free_ != update_factor_free_)) {
    OccupancyGrid::Options o;
    o.resolution = map_resolution_;
    o.levels = static_cast<int>(map_levels_);
    grid_ = std::make_unique<OccupancyGrid>(
        floor_, o, OccupancyGrid::UpdateFactors{update_factor_occupied_, update_factor_free_});
    map_solids_.clear();
    grid_map_ = map_;
    grid_heights_.clear();
    grid_resolution_ = map_resolution_;
    grid_levels_ = map_levels_;
    grid_occupied_ = update_factor_occupied_;
    grid_free_ = update_factor_free_;
  } else if (!mapping_ && (!grid_ || grid_map_ != map_ || grid_heights_ != mount_z_ ||
                           grid_resolution_ != map_resolution_ || grid_levels_ != map_levels_)) {
    OccupancyGrid::Options o;
    o.resolution = map_resolution_;
    o.levels = static_cast<int>(map_levels_);
    grid_map_ = map_;
    map_solids_.clear();
    for (const models::Solid& s : solids_) {
      if (OccupancyGrid::CoversPlane(s, mount_z_)) map_solids_.push_back(s);
    }
    grid_ = std::make_unique<OccupancyGrid>(map_solids_, floor_, o);
    grid_heights_ = mount_z_;
    grid_resolution_ = map_resolution_;
    grid_levels_ = map_levels_;
  }
  ScanMatcher::Options mo;
  mo.coarse_iterations = static_cast<int>(coarse_iterations_);
  mo.fine_iterations = static_cast<int>(fine_iterations_);
  mo.max_angle_step = max_angle_step_;
  matcher_ = std::make_unique<ScanMatcher>(*grid_, mo);
}

void LaserLocalizationUnit::Initialize() {
  ThrowIfBadParameters();
  Derive();
  // A learned map starts unknown at every Initialize.
  if (mapping_) grid_->Clear();
  std::fill(mapped_.begin(), mapped_.end(), 0);
  std::fill(last_map_pose_.begin(), last_map_pose_.end(), Pose{});
  map_updates_ = 0.0;
  estimate_ = {initial_x_, initial_y_, WrapAngle(initial_yaw_)};
  estimate_ns_ = start_;
  odom_ = estimate_;
  odom_ns_ = start_;
  step_end_ns_ = start_;
  have_match_ = false;
  history_begin_ = history_size_ = 0;
  for (std::size_t k = 0; k < beam_counts_.size(); ++k) {
    last_count_[k] = scan_count_[k];
    last_scan_ns_[k] = start_;
    laser_status_[k] = 0.0;
  }
  last_result_ = {};
  position_ = {estimate_.x, estimate_.y};
  yaw_ = estimate_.yaw;
  velocity_ = {0.0, 0.0};
  yaw_rate_ = 0.0;
  std::fill(hessian_.begin(), hessian_.end(), 0.0);
  std::fill(covariance_.begin(), covariance_.end(), 0.0);
  match_time_ = cosim::NsToSeconds(start_);
  match_count_ = 0.0;
  match_cost_ = 0.0;
  source_ = 1.0;
}

LaserLocalizationUnit::Pose LaserLocalizationUnit::Predict(const Pose& p, double s) const {
  // Constant twist in base_link over s: the heading at the middle of the
  // interval (second order in the turn).
  const double mid = p.yaw + 0.5 * odometry_yaw_rate_ * s;
  const double c = std::cos(mid), sn = std::sin(mid);
  const double vx = odometry_velocity_[0], vy = odometry_velocity_[1];
  return {p.x + (c * vx - sn * vy) * s, p.y + (sn * vx + c * vy) * s,
          WrapAngle(p.yaw + odometry_yaw_rate_ * s)};
}

void LaserLocalizationUnit::ProcessScan(int k) {
  const auto kk = static_cast<std::size_t>(k);
  const cosim::TimeNs scan_ns = cosim::SecondsToNs(scan_time_[kk]);
  const cosim::TimeNs match_ns = scan_ns + mid_offset_ns_[kk];
  last_scan_ns_[kk] = scan_ns;
  const std::vector<double>& r = ranges_[kk];
  const std::vector<double>& bc = beam_cos_[kk];
  const std::vector<double>& bs = beam_sin_[kk];
  const double mx = mount_x_[kk], my = mount_y_[kk];
  // Deskew: the base at beam time t_i relative to the base at the match
  // time is displaced by v_b dt and turned by w dt (dt = t_i - t_match,
  // v_b the velocity estimate in base_link): p_match = R(w dt) p_i + v_b dt;
  // R to second order in w dt (w dt <= 0.02 rad for 1 rad/s over half of
  // an S300 sweep: error below 1.5e-6 r).
  const double cy = std::cos(estimate_.yaw), sy = std::sin(estimate_.yaw);
  const double vbx = deskew_ ? cy * velocity_[0] + sy * velocity_[1] : 0.0;
  const double vby = deskew_ ? -sy * velocity_[0] + cy * velocity_[1] : 0.0;
  const double w = deskew_ ? yaw_rate_ : 0.0;
  const double mid_s = cosim::NsToSeconds(mid_offset_ns_[kk]);
  std::size_t n = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const double ri = r[i];
    if (!(ri >= range_min_ && ri <= usable_range_max_) || ri <= 0.0) continue;
    double x = mx + ri * bc[i], y = my + ri * bs[i];
    if (deskew_) {
      const double dt = beam_dt_[kk][i] - mid_s;
      const double th = w * dt, c = 1.0 - 0.5 * th * th;
      const double xr = c * x - th * y, yr = th * x + c * y;
      x = xr + vbx * dt;
      y = yr + vby * dt;
    }
    px_[n] = x;
    py_[n] = y;
    ++n;
  }
  if (n < static_cast<std::size_t>(min_points_)) {
    SetStatus(k, 2);
    return;
  }
  Pose start = estimate_;
  if (odometry_prediction_) start = Predict(odom_, cosim::NsToSeconds(match_ns - odom_ns_));
  if (mapping_ && !have_match_ && !mapped_[kk]) {
    // Laser k's first scan before any match: into the map at the start
    // pose, without matching (hector's first scan).
    UpdateMap(k, n, start);
    SetStatus(k, 0);
    return;
  }
  const ScanMatcher::Result res =
      matcher_->Match(std::span<const double>(px_.data(), n),
                      std::span<const double>(py_.data(), n), {start.x, start.y, start.yaw});
  last_result_ = res;
  // Divergence tests.
  const std::array<double, 6> h{res.hessian[0], res.hessian[1], res.hessian[2],
                                res.hessian[4], res.hessian[5], res.hessian[8]};
  std::array<double, 9> inv{};
  bool ok = res.solved && res.cost <= max_cost_ && InverseSymmetric3(h, inv);
  const double var_r =
      res.points > 3 ? res.cost * res.points / static_cast<double>(res.points - 3) : 0.0;
  if (ok) {
    // Largest eigenvalue of the 2 x 2 position block of var_r H^-1.
    const double a = var_r * inv[0], b = var_r * inv[1], d = var_r * inv[4];
    const double lmax = 0.5 * (a + d) + std::sqrt(0.25 * (a - d) * (a - d) + b * b);
    ok = std::sqrt(lmax) <= max_position_sigma_ && std::sqrt(var_r * inv[8]) <= max_yaw_sigma_;
  }
  if (ok) {
    ok = std::hypot(res.pose.x - start.x, res.pose.y - start.y) <= max_jump_ &&
         std::abs(WrapAngle(res.pose.yaw - start.yaw)) <= max_jump_yaw_;
  }
  if (!ok) {
    SetStatus(k, 3);
    return;
  }
  SetStatus(k, 0);
  const Pose matched{res.pose.x, res.pose.y, WrapAngle(res.pose.yaw)};
  // Drop the matches older than the window but the newest of them (the
  // window's start), then the velocity from it to this match.
  const auto window_ns = static_cast<cosim::TimeNs>(std::llround(velocity_window_ * 1e9));
  while (history_size_ >= 2 &&
         history_ns_[(history_begin_ + 1) % kHistory] <= match_ns - window_ns) {
    history_begin_ = (history_begin_ + 1) % kHistory;
    --history_size_;
  }
  if (history_size_ == kHistory) {
    history_begin_ = (history_begin_ + 1) % kHistory;
    --history_size_;
  }
  if (history_size_ > 0) {
    const std::size_t from =
        window_ns > 0 ? history_begin_ : (history_begin_ + history_size_ - 1) % kHistory;
    const Pose& old_pose = history_[from];
    const cosim::TimeNs old_ns = history_ns_[from];
    if (match_ns > old_ns) {
      const double dt = cosim::NsToSeconds(match_ns - old_ns);
      velocity_[0] = (matched.x - old_pose.x) / dt;
      velocity_[1] = (matched.y - old_pose.y) / dt;
      yaw_rate_ = WrapAngle(matched.yaw - old_pose.yaw) / dt;
    }
  }
  const std::size_t slot = (history_begin_ + history_size_) % kHistory;
  history_[slot] = matched;
  history_ns_[slot] = match_ns;
  ++history_size_;
  estimate_ = matched;
  estimate_ns_ = match_ns;
  have_match_ = true;
  odom_ = matched;
  odom_ns_ = match_ns;
  for (std::size_t i = 0; i < 9; ++i) {
    hessian_[i] = res.hessian[i];
    covariance_[i] = var_r * inv[i];
  }
  const double fp = covariance_floor_position_ * covariance_floor_position_;
  covariance_[0] += fp;
  covariance_[4] += fp;
  covariance_[8] += covariance_floor_yaw_ * covariance_floor_yaw_;
  match_time_ = cosim::NsToSeconds(match_ns);
  match_cost_ = res.cost;
  match_count_ += 1.0;
  if (mapping_) {
    // hector's poseDifferenceLargerThan (HectorSlamProcessor::update):
    // strictly more than either threshold.
    const Pose& last = last_map_pose_[kk];
    if (!mapped_[kk] ||
        std::hypot(matched.x - last.x, matched.y - last.y) > map_update_distance_thresh_ ||
        std::abs(WrapAngle(matched.yaw - last.yaw)) > map_update_angle_thresh_) {
      UpdateMap(k, n, matched);
    }
  }
}

void LaserLocalizationUnit::UpdateMap(int k, std::size_t n, const Pose& p) {
  const auto kk = static_cast<std::size_t>(k);
  grid_->UpdateByScan(std::span<const double>(px_.data(), n),
                      std::span<const double>(py_.data(), n), mount_x_[kk], mount_y_[kk], p.x, p.y,
                      p.yaw);
  mapped_[kk] = 1;
  last_map_pose_[kk] = p;
  map_updates_ += 1.0;
}

cosim::StepResult LaserLocalizationUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  const cosim::TimeNs end = t + dt;
  // The new scans, in the order of their match times.
  const int fresh = OrderNewScans(scan_count_, last_count_, scan_time_, mid_offset_ns_, order_);
  for (int j = 0; j < fresh; ++j) ProcessScan(order_[static_cast<std::size_t>(j)]);
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
  step_end_ns_ = end;
  return cosim::StepResult::kOk;
}

void LaserLocalizationUnit::SaveInternal(cosim::UnitState& state) const {
  state.integers = {start_, estimate_ns_, have_match_ ? 1 : 0, odom_ns_, step_end_ns_};
  state.integers.insert(state.integers.end(), last_scan_ns_.begin(), last_scan_ns_.end());
  state.reals = {estimate_.x, estimate_.y, estimate_.yaw, odom_.x, odom_.y, odom_.yaw};
  state.reals.insert(state.reals.end(), last_count_.begin(), last_count_.end());
  // The history, oldest first.
  state.integers.push_back(static_cast<std::int64_t>(history_size_));
  for (std::size_t i = 0; i < history_size_; ++i) {
    const std::size_t k = (history_begin_ + i) % kHistory;
    state.integers.push_back(history_ns_[k]);
    state.reals.insert(state.reals.end(), {history_[k].x, history_[k].y, history_[k].yaw});
  }
  // map: mapping: per laser whether it entered the map and where it last
  // did, and the learned map: each level's log-odds as their float bytes (4
  // bytes per cell: 5.5 MB for the factory line's 31 x 21 m at 0.025 m over
  // 3 levels; the values follow from them, the update stamps only matter
  // within one update).
  for (std::size_t k = 0; k < beam_counts_.size(); ++k) {
    state.integers.push_back(mapped_[k]);
    state.reals.insert(state.reals.end(),
                       {last_map_pose_[k].x, last_map_pose_[k].y, last_map_pose_[k].yaw});
  }
  state.strings.clear();
  if (mapping_) {
    for (int i = 0; i < grid_->levels(); ++i) {
      const std::vector<float>& lo = grid_->level(i).log_odds;
      std::string bytes(lo.size() * sizeof(float), '\0');
      std::memcpy(bytes.data(), lo.data(), bytes.size());
      state.strings.push_back(std::move(bytes));
    }
  }
}

void LaserLocalizationUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t L = beam_counts_.size();
  const std::size_t h = state.integers.size() > 5 + L
                            ? static_cast<std::size_t>(state.integers[5 + L])
                            : kHistory + 1;
  if (h > kHistory || state.integers.size() != 6 + 2 * L + h ||
      state.reals.size() != 6 + 4 * L + 3 * h) {
    throw cosim::UnitError(Where() + ": saved state does not fit this unit");
  }
  history_begin_ = 0;
  history_size_ = h;
  for (std::size_t i = 0; i < h; ++i) {
    history_ns_[i] = state.integers[6 + L + i];
    history_[i] = {state.reals[6 + L + 3 * i], state.reals[7 + L + 3 * i],
                   state.reals[8 + L + 3 * i]};
  }
  start_ = state.integers[0];
  estimate_ns_ = state.integers[1];
  have_match_ = state.integers[2] != 0;
  odom_ns_ = state.integers[3];
  step_end_ns_ = state.integers[4];
  for (std::size_t k = 0; k < L; ++k) last_scan_ns_[k] = state.integers[5 + k];
  estimate_ = {state.reals[0], state.reals[1], state.reals[2]};
  odom_ = {state.reals[3], state.reals[4], state.reals[5]};
  for (std::size_t k = 0; k < L; ++k) last_count_[k] = state.reals[6 + k];
  for (std::size_t k = 0; k < L; ++k) {
    mapped_[k] = state.integers[6 + L + h + k] != 0 ? 1 : 0;
    const std::size_t r = 6 + L + 3 * h + 3 * k;
    last_map_pose_[k] = {state.reals[r], state.reals[r + 1], state.reals[r + 2]};
  }
  // Derived values follow the (restored) parameters.
  Derive();
  if (!mapping_) return;
  const auto levels = static_cast<std::size_t>(grid_->levels());
  if (state.strings.size() != levels) {
    throw cosim::UnitError(Where() + ": saved state holds " + std::to_string(state.strings.size()) +
                           " map levels, map: mapping here has " + std::to_string(levels));
  }
  std::vector<float> lo;
  for (std::size_t i = 0; i < levels; ++i) {
    const std::string& bytes = state.strings[i];
    if (bytes.size() != grid_->level(static_cast<int>(i)).log_odds.size() * sizeof(float)) {
      throw cosim::UnitError(Where() + ": saved map level " + std::to_string(i) +
                             " does not fit this unit's map");
    }
    lo.resize(bytes.size() / sizeof(float));
    std::memcpy(lo.data(), bytes.data(), bytes.size());
    grid_->SetLogOdds(static_cast<int>(i), lo);
  }
}

}  // namespace linesim::estimation
