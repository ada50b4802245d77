#include "units/estimation/laser_localization_unit.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <span>
#include <utility>

namespace linesim::estimation {
namespace {

// hector's wrap: remainder() alone, [-pi, pi].
double RemainderAngle(double a) { return std::remainder(a, 2.0 * std::numbers::pi); }

}  // namespace

LaserLocalizationUnit::LaserLocalizationUnit(std::string name, const models::Scene& scene,
                                             std::vector<int> beam_counts)
    : ScanLocalizer(kTypeName, std::move(name), std::move(beam_counts), RemainderAngle) {
  for (const models::Obstacle& o : scene.obstacles) solids_.push_back(o.solid);
  floor_ = scene.floor;
  const std::size_t L = beam_counts_.size();
  mount_z_.assign(L, std::numeric_limits<double>::quiet_NaN());
  velocity_.assign(2, 0.0);
  mapped_.assign(L, 0);
  last_map_pose_.assign(L, Pose{});
  // hector's defaults where the shared parameters differ from Perfect Match.
  range_min_ = 0.4;
  usable_range_max_ = 30.0;
  min_points_ = 50;
  covariance_floor_position_ = 0.01;
  covariance_floor_yaw_ = 0.0087;

  using cosim::Rule;
  auto& v = variables();
  DeclareMountXY();
  v.Parameter("mount_z", "m", &mount_z_,
              "per laser: its height above the floor (the scan plane: which solids are in the map)",
              Rule::Finite().NoDefault());
  DeclareBeamGeometry(
      "per laser: its yaw in base_link (roll and pitch ignored: 3-DoF like hector)");
  DeclareRangeLimits("nearer returns are skipped (hector_mapping laser_min_dist default 0.4)",
                     "farther returns are skipped (hector_mapping laser_max_dist default 30)");
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
  DeclareStartPose(Rule::Required(), "start pose in map, x (as an AMCL initial pose)",
                   "start pose in map, y", "start pose in map, yaw");
  DeclareMotionPrediction(
      "none: each match starts from the last estimate (hector); odometry: moved by the "
      "odometry twist since",
      "move each beam's point from its time to the match time by the last velocity estimate",
      "a laser without a new scan for this long has status 1; without an accepted match for "
      "this long the source is 1");
  v.Parameter("max_cost", "1", &max_cost_,
              "a match whose mean squared residual exceeds this is rejected",
              Rule::Range(0, false, 4, true));
  v.Parameter("max_position_sigma", "m", &max_position_sigma_,
              "a match whose own position sigma (unfloored covariance) exceeds this is rejected "
              "(near-singular Hessian)",
              Rule::Positive());
  v.Parameter("max_yaw_sigma", "rad", &max_yaw_sigma_,
              "a match whose own yaw sigma exceeds this is rejected", Rule::Positive());
  DeclareJumpLimits("a match farther than this from its start pose is rejected",
                    "a match turned more than this from its start pose is rejected");
  v.Parameter("velocity_window", "s", &velocity_window_,
              "velocity and yaw_rate: the pose change over the accepted matches of this long "
              "(default 0.2 s, ASSUMPTION: 10 matches of two S300, about 0.02 m/s of noise from "
              "a 3 mm pose noise, 0.1 s of lag; 0: between the last two matches, as hector)",
              Rule::Range(0.0, 1.0));
  DeclareMinPoints();
  DeclareCovarianceFloorPosition(
      "added to the position sigmas of the covariance (squared, on the diagonal)");
  DeclareCovarianceFloorYaw();
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

  for (std::size_t k = 0; k < L; ++k) DeclareScanInputs(k);
  DeclareOdometryInputs();

  DeclarePoseOutputs();
  v.Output("velocity", "m/s", &velocity_,
           "base_link velocity in map: the pose change over the accepted matches of the last "
           "velocity_window",
           {});
  v.Output("yaw_rate", "rad/s", &yaw_rate_,
           "yaw rate: the heading change over the accepted matches of the last velocity_window",
           {});
  DeclareMatchOutputs(
      "row-major 3 x 3 of x (m), y (m), yaw (rad): sigma_r^2 H^-1 + floor",
      "row-major 3 x 3 Gauss-Newton Hessian of the latest accepted match (1/m^2, 1/(m rad), "
      "1/rad^2)");
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

void LaserLocalizationUnit::Derive() {
  DeriveBeams();
  mapping_ = map_ == "mapping";
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
  InitializeTracking();
  history_begin_ = history_size_ = 0;
  last_result_ = {};
  velocity_ = {0.0, 0.0};
  yaw_rate_ = 0.0;
  match_cost_ = 0.0;
}

void LaserLocalizationUnit::ProcessScan(int k, cosim::TimeNs match_ns) {
  const auto kk = static_cast<std::size_t>(k);
  // Deskew by the last velocity estimate, turned into base_link.
  const double cy = std::cos(estimate_.yaw), sy = std::sin(estimate_.yaw);
  const double vbx = deskew_ ? cy * velocity_[0] + sy * velocity_[1] : 0.0;
  const double vby = deskew_ ? -sy * velocity_[0] + cy * velocity_[1] : 0.0;
  const double w = deskew_ ? yaw_rate_ : 0.0;
  const std::size_t n = CollectPoints(k, 0.0, deskew_, vbx, vby, w);
  if (n < static_cast<std::size_t>(min_points_)) {
    SetStatus(k, 2);
    return;
  }
  const Pose start = MatchStart(match_ns);
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
  ok = ok && WithinJumpLimits(res.pose.x, res.pose.y, res.pose.yaw, start);
  if (!ok) {
    SetStatus(k, 3);
    return;
  }
  SetStatus(k, 0);
  const Pose matched{res.pose.x, res.pose.y, RemainderAngle(res.pose.yaw)};
  // Drop the matches older than the window but the newest of them (the
  // window's start), then the velocity from it to this match.
  const auto window_ns = cosim::SecondsToNs(velocity_window_);
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
      yaw_rate_ = RemainderAngle(matched.yaw - old_pose.yaw) / dt;
    }
  }
  const std::size_t slot = (history_begin_ + history_size_) % kHistory;
  history_[slot] = matched;
  history_ns_[slot] = match_ns;
  ++history_size_;
  AcceptMatch(matched, match_ns);
  for (std::size_t i = 0; i < 9; ++i) {
    hessian_[i] = res.hessian[i];
    covariance_[i] = var_r * inv[i];
  }
  AddCovarianceFloors();
  match_cost_ = res.cost;
  if (mapping_) {
    // hector's poseDifferenceLargerThan (HectorSlamProcessor::update):
    // strictly more than either threshold.
    const Pose& last = last_map_pose_[kk];
    if (!mapped_[kk] ||
        std::hypot(matched.x - last.x, matched.y - last.y) > map_update_distance_thresh_ ||
        std::abs(RemainderAngle(matched.yaw - last.yaw)) > map_update_angle_thresh_) {
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

void LaserLocalizationUnit::SaveInternal(cosim::UnitState& state) const {
  SaveTracking(state);
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
  const std::size_t ti = tracking_integers(), tr = tracking_reals();
  const std::size_t h =
      state.integers.size() > ti ? static_cast<std::size_t>(state.integers[ti]) : kHistory + 1;
  if (h > kHistory || state.integers.size() != ti + 1 + h + L ||
      state.reals.size() != tr + 3 * h + 3 * L) {
    throw cosim::UnitError(Where() + ": saved state does not fit this unit");
  }
  RestoreTracking(state);
  history_begin_ = 0;
  history_size_ = h;
  for (std::size_t i = 0; i < h; ++i) {
    history_ns_[i] = state.integers[ti + 1 + i];
    history_[i] = {state.reals[tr + 3 * i], state.reals[tr + 3 * i + 1],
                   state.reals[tr + 3 * i + 2]};
  }
  for (std::size_t k = 0; k < L; ++k) {
    mapped_[k] = state.integers[ti + 1 + h + k] != 0 ? 1 : 0;
    const std::size_t r = tr + 3 * h + 3 * k;
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
