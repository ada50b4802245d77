#include "units/estimation/laser_beams.h"
#include "units/estimation/perfect_match_localization_unit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <utility>

#include "cosim/variable_table.h"
#include "models/angle.h"
#include "units/estimation/occupancy_grid.h"

namespace linesim::estimation {

PerfectMatchLocalizationUnit::PerfectMatchLocalizationUnit(std::string name,
                                                           const models::Scene& scene,
                                                           std::vector<int> beam_counts,
                                                           std::vector<MapSpec> maps)
    : cosim::Unit(kTypeName, std::move(name)),
      beam_counts_(std::move(beam_counts)),
      specs_(std::move(maps)),
      scene_(scene) {
  if (beam_counts_.empty() || beam_counts_.size() > static_cast<std::size_t>(kMaxLasers)) {
    throw cosim::UnitError(Where() + ": beam_counts must list 1 to " + std::to_string(kMaxLasers) +
                           " lasers, got " + std::to_string(beam_counts_.size()));
  }
  if (specs_.empty() || specs_.size() > static_cast<std::size_t>(kMaxMaps)) {
    throw cosim::UnitError(Where() + ": maps must list 1 to " + std::to_string(kMaxMaps) +
                           " maps, got " + std::to_string(specs_.size()));
  }
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    const MapSpec& m = specs_[i];
    if (!std::isfinite(m.height_m) || !(m.cell_m >= 0.0 && m.cell_m <= 0.5) ||
        (m.region && !(m.region->max_x > m.region->min_x && m.region->max_y > m.region->min_y))) {
      throw cosim::UnitError(
          Where() + ": map " + std::to_string(i) + " (" + m.name +
          ") needs a finite height_m, cell_m in [0, 0.5] and a region with max > min");
    }
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
  mount_x_.assign(L, nan);
  mount_y_.assign(L, nan);
  mount_yaw_.assign(L, nan);
  first_beam_angle_.assign(L, nan);
  angular_step_.assign(L, nan);
  scan_period_.assign(L, nan);
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
  scan_count_.assign(L, 0.0);
  scan_time_.assign(L, 0.0);
  mapping_range_bias_.assign(L, 0.0);
  odometry_velocity_.assign(2, 0.0);
  position_.assign(2, 0.0);
  covariance_.assign(9, 0.0);
  hessian_.assign(9, 0.0);
  laser_status_.assign(L, 0.0);
  mid_offset_ns_.assign(L, 0);
  px_.assign(max_beams, 0.0);
  py_.assign(max_beams, 0.0);
  order_.assign(L, 0);
  last_count_.assign(L, 0.0);
  last_scan_ns_.assign(L, 0);

  using cosim::Rule;
  auto& v = variables();
  v.Parameter("mount_x", "m", &mount_x_, "per laser: its origin in base_link, x",
              Rule::Finite().NoDefault());
  v.Parameter("mount_y", "m", &mount_y_, "per laser: its origin in base_link, y",
              Rule::Finite().NoDefault());
  v.Parameter("mount_yaw", "rad", &mount_yaw_,
              "per laser: its yaw in base_link (roll and pitch ignored: 3-DoF as paper 2)",
              Rule::Finite().NoDefault());
  v.Parameter("first_beam_angle", "rad", &first_beam_angle_, "per laser: direction of beam 0",
              Rule::Range(-2 * std::numbers::pi, 2 * std::numbers::pi).NoDefault());
  v.Parameter("angular_step", "rad", &angular_step_, "per laser: angle between neighbouring beams",
              Rule::Range(0, false, std::numbers::pi, true).NoDefault());
  v.Parameter("scan_period", "s", &scan_period_, "per laser: one turn of the mirror (one scan)",
              Rule::Positive().NoDefault());
  v.Parameter("range_min", "m", &range_min_,
              "nearer returns are skipped (the LMS151's 0.5 m, operating instructions 8012471)",
              Rule::NonNegative());
  v.Parameter("usable_range_max", "m", &usable_range_max_,
              "farther returns are skipped (the LMS151's 50 m, 8012471)", Rule::Positive());
  v.Parameter("lookup_cell", "m", &lookup_cell_,
              "cell of the distance maps' lookup grid, for the maps that give no cell_m (Tribots: "
              "0.05; see distance_map.h for the interpolation error)",
              Rule::Range(0.005, 0.5));
  v.Parameter("map_margin", "m", &map_margin_,
              "the lookup grid extends this far beyond each map's region (or the floor)",
              Rule::Range(0.0, 20.0));
  v.Parameter("c", "m", &c_, "scale of the error 1 - c^2 / (c^2 + d^2) (Tribots: 0.25 m)",
              Rule::Positive());
  v.Parameter("step_position", "m", &step_position_,
              "RPROP's initial step in x and y (Tribots: 0.04 m)", Rule::Positive());
  v.Parameter("step_yaw", "rad", &step_yaw_, "RPROP's initial step in yaw (Tribots: 0.1 rad)",
              Rule::Positive());
  v.Parameter("iterations", &iterations_,
              "RPROP iterations with more than few_points points (Tribots: 10)",
              Rule::Range(1, 1000));
  v.Parameter("few_iterations", &few_iterations_,
              "RPROP iterations with few_points points or fewer (Tribots: 20)",
              Rule::Range(1, 1000));
  v.Parameter("few_points", &few_points_, "see few_iterations (Tribots: 20)",
              Rule::Range(0, 100000));
  v.Parameter("rprop_stride", &rprop_stride_,
              "RPROP's gradient over every n-th scan point (the Gauss-Newton refinement and the "
              "covariance over all): 1 as Tribots; 2 halves RPROP's cost with the same pose "
              "after the refinement (tests/units/estimation/perfect_match_test.cc)",
              cosim::Rule::Range(1.0, true, 16.0, true));
  v.Parameter("refine_iterations", &refine_iterations_,
              "reweighted Gauss-Newton steps after RPROP (0: Tribots' RPROP alone; see "
              "perfect_match.h)",
              Rule::Range(0, 20));
  v.Parameter("initial_x", "m", &initial_x_, "base_link x in map at the start",
              Rule::Finite().NoDefault());
  v.Parameter("initial_y", "m", &initial_y_, "base_link y in map at the start",
              Rule::Finite().NoDefault());
  v.Parameter("initial_yaw", "rad", &initial_yaw_, "base_link yaw in map at the start",
              Rule::Finite().NoDefault());
  v.Parameter("motion_prediction", &motion_prediction_,
              "none: each match starts from the last; odometry: from the last moved by the "
              "odometry inputs (Tribots)",
              Rule::OneOf({"none", "odometry"}));
  v.Parameter("deskew", &deskew_,
              "with motion_prediction odometry: each point moved to the match time by the "
              "odometry twist");
  v.Parameter("scan_timeout", "s", &scan_timeout_,
              "laser_status 1 when a laser's last scan started longer ago", Rule::Positive());
  v.Parameter("min_points", &min_points_,
              "a scan with fewer usable returns is not matched (laser blacked out)",
              Rule::Range(3, 100000));
  v.Parameter("max_mean_error", "1", &max_mean_error_,
              "a match whose mean error E / n exceeds this is rejected (1: never)",
              Rule::Range(0.0, false, 1.0, true));
  v.Parameter("max_jump", "m", &max_jump_, "a match farther than this from its start is rejected",
              Rule::Positive());
  v.Parameter("max_jump_yaw", "rad", &max_jump_yaw_,
              "a match turned more than this from its start is rejected", Rule::Positive());
  v.Parameter("covariance_floor_position", "m", &covariance_floor_position_,
              "added to the position sigmas of the covariance (squared, on the diagonal): errors "
              "the curvature misses (range bias, the map's own error)",
              Rule::NonNegative());
  v.Parameter("range_bias_sigma", "m", &range_bias_sigma_,
              "sigma of a range bias common to a scan's beams (the laser model's bias_sigma: "
              "LMS151 0.015): adds range_bias_sigma^2 g g^T to the covariance, g the match's "
              "sensitivity to it",
              Rule::NonNegative());
  v.Parameter("covariance_floor_yaw", "rad", &covariance_floor_yaw_,
              "added to the yaw sigma of the covariance (squared, on the diagonal)",
              Rule::NonNegative());

  for (std::size_t k = 0; k < L; ++k) {
    const std::string s = std::to_string(k);
    v.Input("ranges_" + s, "m", &ranges_[k], "laser " + s + ": ranges of its last complete scan");
    v.Input("scan_count_" + s, "1", &scan_count_[k], "laser " + s + ": complete scans so far");
    v.Input("scan_time_" + s, "s", &scan_time_[k], "laser " + s + ": start time of its last scan");
    v.Input("mapping_range_bias_" + s, "m", &mapping_range_bias_[k],
            "laser " + s + ": its device's range bias, which the maps it built by SLAM "
            "(maps with from_own_laser) carry in their outlines (its range_bias output)");
  }
  v.Input("odometry_velocity", "m/s", &odometry_velocity_,
          "odometry: velocity of base_link in base_link (motion_prediction odometry only)");
  v.Input("odometry_yaw_rate", "rad/s", &odometry_yaw_rate_,
          "odometry: yaw rate (motion_prediction odometry only)");
  v.Input("map_index", &map_index_,
          "the map each new scan is matched against (0-based, the order of the maps key)");

  v.Output("position", "m", &position_, "base_link x, y in map (latest accepted match)", {});
  v.Output("yaw", "rad", &yaw_, "base_link yaw in map (latest accepted match)", {});
  v.Output("covariance", "1", &covariance_,
           "row-major 3 x 3 of x (m), y (m), yaw (rad): s^2 (2 / c^2) H^-1 + range_bias_sigma^2 "
           "g g^T + floors",
           {});
  v.Output("hessian", "1", &hessian_,
           "row-major 3 x 3 curvature H of the error at the latest accepted match (1/m^2, "
           "1/(m rad), 1/rad^2)",
           {});
  v.Output("match_time", "s", &match_time_, "time the pose refers to (middle of the matched scan)",
           {});
  v.Output("match_count", "1", &match_count_, "accepted matches so far", {});
  v.Output("match_error", "1", &match_error_,
           "mean error E / n of the latest accepted match, in [0, 1] (0 perfect)", {});
  v.Output("match_inlier_fraction", "1", &match_inlier_fraction_,
           "sum of the points' weights c^4 / (c^2 + d^2)^2 over the points, latest accepted match "
           "(1: every point on an outline)",
           {});
  v.Output("map_in_use", "1", &map_in_use_, "the map of the latest scan matched (its index)", {});
  v.Output("laser_status", "1", &laser_status_,
           "per laser: 0 ok, 1 no new scan within scan_timeout, 2 blacked out (fewer than "
           "min_points returns), 3 last match rejected, 4 map_index names no map",
           {});
  v.Output("source", "1", &source_,
           "0: pose from a match within scan_timeout; 1: held (or odometry-predicted) since", {});
}

PerfectMatchLocalizationUnit::~PerfectMatchLocalizationUnit() = default;

std::vector<cosim::ParameterProblem> PerfectMatchLocalizationUnit::CheckParameters() const {
  auto problems = cosim::Unit::CheckParameters();
  AddLaserProblems(range_min_, usable_range_max_, beam_counts_, angular_step_, scan_period_,
                   scan_timeout_, problems);
  // Each map's lookup grid (its region, or the floor, and the margin, at its
  // cell) within the grid's limit: refused here, at load, rather than when
  // the maps are built at initialization.
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    const MapSpec& m = specs_[i];
    const double cell = m.cell_m > 0.0 ? m.cell_m : lookup_cell_;
    const double span_x = (m.region ? m.region->max_x - m.region->min_x
                                    : scene_.floor.max_x_m - scene_.floor.min_x_m) +
                          2.0 * map_margin_;
    const double span_y = (m.region ? m.region->max_y - m.region->min_y
                                    : scene_.floor.max_y_m - scene_.floor.min_y_m) +
                          2.0 * map_margin_;
    const double cells = std::ceil(span_x / cell) * std::ceil(span_y / cell);
    if (cell > 0.0 && std::isfinite(span_x * span_y) && !(cells <= OccupancyGrid::kMaxCells)) {
      problems.push_back(
          {"maps", i,
           "cell_m " + cosim::FormatValue(cell) + " m over the map's " +
               cosim::FormatValue(span_x) + " x " + cosim::FormatValue(span_y) +
               " m (map_margin included) makes " + cosim::FormatValue(cells) +
               " cells, more than the lookup grid's 2^28: expected a cell_m of at least " +
               cosim::FormatValue(std::sqrt(span_x * span_y / OccupancyGrid::kMaxCells)) +
               " m, or a smaller region"});
    }
  }
  return problems;
}

void PerfectMatchLocalizationUnit::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void PerfectMatchLocalizationUnit::Derive() {
  odometry_prediction_ = motion_prediction_ == "odometry";
  for (std::size_t k = 0; k < beam_counts_.size(); ++k) {
    // The middle of the sweep: the time the matched pose refers to.
    mid_offset_ns_[k] = LaserBeams(mount_yaw_[k], first_beam_angle_[k], angular_step_[k],
                                   scan_period_[k], beam_counts_[k], beam_cos_[k], beam_sin_[k],
                                   beam_dt_[k]);
  }
  // The maps, once per lookup grid.
  if (maps_.size() != specs_.size() || built_cell_ != lookup_cell_ ||
      built_margin_ != map_margin_) {
    maps_.clear();
    DistanceMap::Options o;
    o.cell = lookup_cell_;
    o.margin = map_margin_;
    for (const MapSpec& m : specs_) {
      o.cell = m.cell_m > 0.0 ? m.cell_m : lookup_cell_;
      // A map of a region (paper 2's van interior: "only the inner
      // contours") holds the outlines seen from the region's centre, as a
      // map built by SLAM inside it: its thin walls have one face each.
      o.seen_from.reset();
      if (m.region) {
        o.seen_from = std::array<double, 2>{0.5 * (m.region->min_x + m.region->max_x),
                                            0.5 * (m.region->min_y + m.region->max_y)};
      }
      maps_.push_back(std::make_unique<DistanceMap>(scene_, m.height_m, m.region, o));
    }
    built_cell_ = lookup_cell_;
    built_margin_ = map_margin_;
  }
  PerfectMatch::Options mo;
  mo.c = c_;
  mo.step_x = mo.step_y = step_position_;
  mo.step_yaw = step_yaw_;
  mo.iterations = static_cast<int>(iterations_);
  mo.few_iterations = static_cast<int>(few_iterations_);
  mo.few_points = static_cast<int>(few_points_);
  mo.refine_iterations = static_cast<int>(refine_iterations_);
  mo.rprop_stride = static_cast<int>(rprop_stride_);
  matcher_ = std::make_unique<PerfectMatch>(mo);
}

void PerfectMatchLocalizationUnit::Initialize() {
  ThrowIfBadParameters();
  Derive();
  estimate_ = {initial_x_, initial_y_, models::WrapAngle(initial_yaw_)};
  estimate_ns_ = start_;
  odom_ = estimate_;
  odom_ns_ = start_;
  have_match_ = false;
  for (std::size_t k = 0; k < beam_counts_.size(); ++k) {
    last_count_[k] = scan_count_[k];
    last_scan_ns_[k] = start_;
    laser_status_[k] = 0.0;
  }
  last_result_ = {};
  position_ = {estimate_.x, estimate_.y};
  yaw_ = estimate_.yaw;
  std::fill(hessian_.begin(), hessian_.end(), 0.0);
  std::fill(covariance_.begin(), covariance_.end(), 0.0);
  match_time_ = cosim::NsToSeconds(start_);
  match_count_ = 0.0;
  match_error_ = 0.0;
  match_inlier_fraction_ = 0.0;
  map_in_use_ = static_cast<double>(map_index_);
  source_ = 1.0;
}

PerfectMatchLocalizationUnit::Pose PerfectMatchLocalizationUnit::Predict(const Pose& p,
                                                                         double s) const {
  // Constant twist in base_link over s: the heading at the middle of the
  // interval (second order in the turn).
  const double mid = p.yaw + 0.5 * odometry_yaw_rate_ * s;
  const double c = std::cos(mid), sn = std::sin(mid);
  const double vx = odometry_velocity_[0], vy = odometry_velocity_[1];
  return {p.x + (c * vx - sn * vy) * s, p.y + (sn * vx + c * vy) * s,
          models::WrapAngle(p.yaw + odometry_yaw_rate_ * s)};
}

void PerfectMatchLocalizationUnit::ProcessScan(int k) {
  const auto kk = static_cast<std::size_t>(k);
  const cosim::TimeNs scan_ns = cosim::SecondsToNs(scan_time_[kk]);
  const cosim::TimeNs match_ns = scan_ns + mid_offset_ns_[kk];
  last_scan_ns_[kk] = scan_ns;
  if (map_index_ < 0 || map_index_ >= map_count()) {
    SetStatus(k, 4);
    return;
  }
  const std::vector<double>& r = ranges_[kk];
  const std::vector<double>& bc = beam_cos_[kk];
  const std::vector<double>& bs = beam_sin_[kk];
  const double mx = mount_x_[kk], my = mount_y_[kk];
  // Deskew by the odometry twist: the base at beam time t_i relative to the
  // base at the match time is displaced by v dt and turned by w dt
  // (dt = t_i - t_match): p_match = R(w dt) p_i + v dt, R to second order.
  const bool deskew = deskew_ && odometry_prediction_;
  const double vx = odometry_velocity_[0], vy = odometry_velocity_[1], w = odometry_yaw_rate_;
  const double mid_s = cosim::NsToSeconds(mid_offset_ns_[kk]);
  // A map this laser built by SLAM carries its bias (see the header).
  const double map_bias = specs_[static_cast<std::size_t>(map_index_)].from_own_laser
                              ? mapping_range_bias_[kk]
                              : 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (!(r[i] >= range_min_ && r[i] <= usable_range_max_) || r[i] <= 0.0) continue;
    const double ri = r[i] - map_bias;
    double x = mx + ri * bc[i], y = my + ri * bs[i];
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
  if (n < static_cast<std::size_t>(min_points_)) {
    SetStatus(k, 2);
    return;
  }
  Pose start = estimate_;
  if (odometry_prediction_) start = Predict(odom_, cosim::NsToSeconds(match_ns - odom_ns_));
  map_in_use_ = static_cast<double>(map_index_);
  const PerfectMatch::Result res = matcher_->Match(
      *maps_[static_cast<std::size_t>(map_index_)], std::span<const double>(px_.data(), n),
      std::span<const double>(py_.data(), n), start, mx, my);
  last_result_ = res;
  const bool ok = res.ok && res.mean_error <= max_mean_error_ &&
                  std::hypot(res.pose.x - start.x, res.pose.y - start.y) <= max_jump_ &&
                  std::abs(models::WrapAngle(res.pose.yaw - start.yaw)) <= max_jump_yaw_;
  if (!ok) {
    SetStatus(k, 3);
    return;
  }
  SetStatus(k, 0);
  estimate_ = {res.pose.x, res.pose.y, models::WrapAngle(res.pose.yaw)};
  estimate_ns_ = match_ns;
  have_match_ = true;
  odom_ = estimate_;
  odom_ns_ = match_ns;
  for (std::size_t i = 0; i < 9; ++i) {
    hessian_[i] = res.hessian[i];
    covariance_[i] = res.covariance[i];
  }
  const double sb2 = range_bias_sigma_ * range_bias_sigma_;
  for (std::size_t a = 0; a < 3; ++a) {
    for (std::size_t b = 0; b < 3; ++b) {
      covariance_[3 * a + b] += sb2 * res.bias_sensitivity[a] * res.bias_sensitivity[b];
    }
  }
  const double fp = covariance_floor_position_ * covariance_floor_position_;
  covariance_[0] += fp;
  covariance_[4] += fp;
  covariance_[8] += covariance_floor_yaw_ * covariance_floor_yaw_;
  match_time_ = cosim::NsToSeconds(match_ns);
  match_error_ = res.mean_error;
  match_inlier_fraction_ = res.points > 0 ? res.inlier_weight / res.points : 0.0;
  match_count_ += 1.0;
}

cosim::StepResult PerfectMatchLocalizationUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  const cosim::TimeNs end = t + dt;
  // The new scans, in the order of their match times.
  const int fresh = OrderNewScans(scan_count_, last_count_, scan_time_, mid_offset_ns_, order_);
  for (int j = 0; j < fresh; ++j) ProcessScan(order_[static_cast<std::size_t>(j)]);
  const cosim::TimeNs timeout = cosim::SecondsToNs(scan_timeout_);
  for (int k = 0; k < laser_count(); ++k) {
    if (end - last_scan_ns_[static_cast<std::size_t>(k)] > timeout) SetStatus(k, 1);
  }
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

void PerfectMatchLocalizationUnit::SaveInternal(cosim::UnitState& state) const {
  state.integers = {start_, estimate_ns_, have_match_ ? 1 : 0, odom_ns_};
  state.integers.insert(state.integers.end(), last_scan_ns_.begin(), last_scan_ns_.end());
  state.reals = {estimate_.x, estimate_.y, estimate_.yaw, odom_.x, odom_.y, odom_.yaw};
  state.reals.insert(state.reals.end(), last_count_.begin(), last_count_.end());
}

void PerfectMatchLocalizationUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t L = beam_counts_.size();
  if (state.integers.size() != 4 + L || state.reals.size() != 6 + L) {
    throw cosim::UnitError(Where() + ": saved state does not fit this unit");
  }
  start_ = state.integers[0];
  estimate_ns_ = state.integers[1];
  have_match_ = state.integers[2] != 0;
  odom_ns_ = state.integers[3];
  for (std::size_t k = 0; k < L; ++k) last_scan_ns_[k] = state.integers[4 + k];
  estimate_ = {state.reals[0], state.reals[1], state.reals[2]};
  odom_ = {state.reals[3], state.reals[4], state.reals[5]};
  for (std::size_t k = 0; k < L; ++k) last_count_[k] = state.reals[6 + k];
  // Derived values and maps follow the (restored) parameters.
  Derive();
}

}  // namespace linesim::estimation
