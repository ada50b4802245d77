#include "units/estimation/perfect_match_localization_unit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
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
    : ScanLocalizer(kTypeName, std::move(name), std::move(beam_counts), models::WrapAngle),
      specs_(std::move(maps)),
      scene_(scene) {
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
  const std::size_t L = beam_counts_.size();
  mapping_range_bias_.assign(L, 0.0);
  mount_z_.assign(L, 0.0);
  // The LMS151's limits (paper 2's laser) where the shared parameters
  // differ from hector's.
  range_min_ = 0.5;
  usable_range_max_ = 50.0;
  min_points_ = 20;

  using cosim::Rule;
  auto& v = variables();
  DeclareMountXY();
  v.Parameter("mount_z", "m", &mount_z_,
              "per laser: its origin's height above base_link (with attitude terrain)",
              Rule::Finite());
  DeclareBeamGeometry("per laser: its yaw in base_link (roll and pitch ignored: 3-DoF as paper 2)");
  DeclareRangeLimits(
      "nearer returns are skipped (the LMS151's 0.5 m, operating instructions 8012471)",
      "farther returns are skipped (the LMS151's 50 m, 8012471)");
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
  DeclareStartPose(Rule::Finite().NoDefault(), "base_link x in map at the start",
                   "base_link y in map at the start", "base_link yaw in map at the start");
  DeclareMotionPrediction(
      "none: each match starts from the last; odometry: from the last moved by the odometry "
      "inputs (Tribots)",
      "with motion_prediction odometry: each point moved to the match time by the odometry "
      "twist",
      "laser_status 1 when a laser's last scan started longer ago");
  DeclareMinPoints();
  v.Parameter("max_mean_error", "1", &max_mean_error_,
              "a match whose mean error E / n exceeds this is rejected (1: never)",
              Rule::Range(0.0, false, 1.0, true));
  DeclareJumpLimits("a match farther than this from its start is rejected",
                    "a match turned more than this from its start is rejected");
  DeclareCovarianceFloorPosition(
      "added to the position sigmas of the covariance (squared, on the diagonal): errors the "
      "curvature misses (range bias, the map's own error)");
  v.Parameter("range_bias_sigma", "m", &range_bias_sigma_,
              "sigma of a range bias common to a scan's beams (the laser model's bias_sigma: "
              "LMS151 0.015): adds range_bias_sigma^2 g g^T to the covariance, g the match's "
              "sensitivity to it",
              Rule::NonNegative());
  DeclareCovarianceFloorYaw();
  v.Parameter("attitude", &attitude_,
              "none: the scan plane is level (3-DoF on a flat floor); terrain: the base's pitch "
              "and roll from the scene's terrain under the wheels at the estimated pose, the "
              "points projected into the map's plane and those below the map's floor_m + "
              "ground_clearance dropped, the odometry projected",
              Rule::OneOf({"none", "terrain"}));
  v.Parameter("wheelbase", "m", &wheelbase_,
              "attitude terrain: the contact points' spread along base_link x", Rule::Positive());
  v.Parameter("track", "m", &track_, "attitude terrain: the contact points' spread across",
              Rule::Positive());
  v.Parameter("wheel_radius", "m", &wheel_radius_,
              "attitude terrain: the wheels' radius (each rests on the ground's profile as a "
              "circle)",
              Rule::Positive());
  v.Parameter("kink_tolerance", "m", &kink_tolerance_,
              "attitude terrain: no match while the ground under the tyres departs from one "
              "plane by more than this (the chassis across a ramp's foot or top)",
              Rule::Positive());
  v.Parameter("ground_clearance", "m", &ground_clearance_,
              "attitude terrain: a point less than this above the map's floor (or below it) hit "
              "the ground and is dropped",
              Rule::NonNegative());

  for (std::size_t k = 0; k < L; ++k) {
    DeclareScanInputs(k);
    const std::string s = std::to_string(k);
    v.Input("mapping_range_bias_" + s, "m", &mapping_range_bias_[k],
            "laser " + s +
                ": its device's range bias, which the maps it built by SLAM "
                "(maps with from_own_laser) carry in their outlines (its range_bias output)");
  }
  DeclareOdometryInputs();
  v.Input("map_index", &map_index_,
          "the map each new scan is matched against (0-based, the order of the maps key)");

  DeclarePoseOutputs();
  DeclareMatchOutputs(
      "row-major 3 x 3 of x (m), y (m), yaw (rad): s^2 (2 / c^2) H^-1 + range_bias_sigma^2 g "
      "g^T + floors",
      "row-major 3 x 3 curvature H of the error at the latest accepted match (1/m^2, 1/(m "
      "rad), 1/rad^2)");
  v.Output("match_error", "1", &match_error_,
           "mean error E / n of the latest accepted match, in [0, 1] (0 perfect)", {});
  v.Output("match_inlier_fraction", "1", &match_inlier_fraction_,
           "sum of the points' weights c^4 / (c^2 + d^2)^2 over the points, latest accepted match "
           "(1: every point on an outline)",
           {});
  v.Output("map_in_use", "1", &map_in_use_, "the map of the latest scan matched (its index)", {});
  v.Output("pitch", "rad", &pitch_,
           "attitude terrain: the base's pitch at the current estimate (ROS: + nose down; 0 "
           "with none)",
           {});
  v.Output("roll", "rad", &roll_,
           "attitude terrain: the base's roll at the current estimate (+ right side down)", {});
  v.Output("low_points", "1", &low_points_,
           "points of the latest scan dropped as ground hits (attitude terrain)", {});
  v.Output("laser_status", "1", &laser_status_,
           "per laser: 0 ok, 1 no new scan within scan_timeout, 2 blacked out (fewer than "
           "min_points returns), 3 last match rejected, 4 map_index names no map, 5 held: "
           "the chassis across a kink of the ground (attitude terrain)",
           {});
  v.Output("source", "1", &source_,
           "0: pose from a match within scan_timeout; 1: held (or odometry-predicted) since", {});
}

PerfectMatchLocalizationUnit::~PerfectMatchLocalizationUnit() = default;

std::vector<cosim::ParameterProblem> PerfectMatchLocalizationUnit::CheckParameters() const {
  auto problems = ScanLocalizer::CheckParameters();
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

void PerfectMatchLocalizationUnit::Derive() {
  DeriveBeams();
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
  InitializeTracking();
  last_result_ = {};
  match_error_ = 0.0;
  match_inlier_fraction_ = 0.0;
  map_in_use_ = static_cast<double>(map_index_);
  low_points_ = 0.0;
  UpdateAttitude(estimate_);
}

void PerfectMatchLocalizationUnit::UpdateAttitude(const Pose& at) {
  if (attitude_ != "terrain") {
    pitch_ = roll_ = base_height_ = ground_unevenness_ = 0.0;
    odometry_scale_x_ = odometry_scale_y_ = 1.0;
    return;
  }
  // Each wheel a circle of wheel_radius rolling on the ground's profile
  // along the heading: its centre rests at the highest of ground + sqrt(R^2
  // - u^2) over the contact patch's neighbourhood |u| <= R (on a slope the
  // tyre touches ahead of or behind its axle, so the chassis starts to
  // pitch before the axle reaches the ramp: R tan(pitch / 2) earlier).
  const double c = std::cos(at.yaw), s = std::sin(at.yaw);
  const double a = 0.5 * wheelbase_, b = 0.5 * track_, R = wheel_radius_;
  constexpr int kSamples = 16;  // intervals over the diameter: 2 cm for the Husky's 0.165 m
  std::array<double, 4> h{};    // wheel centres: front left, front right, rear left, rear right
  const std::array<std::array<double, 2>, 4> corner = {{{a, b}, {a, -b}, {-a, b}, {-a, -b}}};
  // The ground's samples under the four tyres, and the least-squares plane
  // through them (normal equations of z = z0 + gx u + gy w).
  std::array<double, 9> m{};
  std::array<double, 3> rhs{};
  std::array<std::array<double, 3>, 4 * (kSamples + 1)> samples{};
  std::size_t count = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    double top = -std::numeric_limits<double>::infinity();
    for (int j = 0; j <= kSamples; ++j) {
      const double u = R * (2.0 * j / kSamples - 1.0);
      const double along = corner[i][0] + u, w = corner[i][1];
      const double lift = std::sqrt(std::max(0.0, R * R - u * u));
      const double g = GroundAt(at.x + c * along - s * w, at.y + s * along + c * w);
      top = std::max(top, g + lift);
      samples[count++] = {along, w, g};
      const std::array<double, 3> row = {1.0, along, w};
      for (std::size_t r = 0; r < 3; ++r) {
        rhs[r] += row[r] * g;
        for (std::size_t q = 0; q < 3; ++q) m[3 * r + q] += row[r] * row[q];
      }
    }
    h[i] = top;
  }
  // Cramer's rule on the 3 x 3 normal equations (well conditioned: the
  // samples span the wheelbase and the track).
  const auto det3 = [](const std::array<double, 9>& q) {
    return q[0] * (q[4] * q[8] - q[5] * q[7]) - q[1] * (q[3] * q[8] - q[5] * q[6]) +
           q[2] * (q[3] * q[7] - q[4] * q[6]);
  };
  const double d = det3(m);
  std::array<double, 3> plane{};
  for (std::size_t col = 0; col < 3; ++col) {
    std::array<double, 9> q = m;
    for (std::size_t r = 0; r < 3; ++r) q[3 * r + col] = rhs[r];
    plane[col] = det3(q) / d;
  }
  ground_unevenness_ = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    const auto& p = samples[k];
    ground_unevenness_ = std::max(ground_unevenness_,
                                  std::abs(p[2] - (plane[0] + plane[1] * p[0] + plane[2] * p[1])));
  }
  // The least-squares plane z = z0 + gx u + gy w through the wheel centres
  // (exact for four coplanar ones; across a kink the four wheels' mean
  // slope: an idealisation, a rigid chassis there rests on three).
  const double gx = ((h[0] + h[1]) - (h[2] + h[3])) / (4.0 * a);
  const double gy = ((h[0] + h[2]) - (h[1] + h[3])) / (4.0 * b);
  const double norm = std::sqrt(1.0 + gx * gx + gy * gy);
  // base_link's origin: on the contact plane, R below the centres' plane
  // along its normal.
  base_height_ = 0.25 * (h[0] + h[1] + h[2] + h[3]) - R * norm;
  // The body's z axis is the plane's normal (-gx, -gy, 1) / |n|; in
  // Ry(pitch) Rx(roll) it is (cos roll sin pitch, -sin roll, cos roll cos
  // pitch).
  pitch_ = std::atan2(-gx, 1.0);
  roll_ = std::asin(gy / norm);
  odometry_scale_x_ = std::cos(pitch_);
  odometry_scale_y_ = std::cos(roll_);
}

double PerfectMatchLocalizationUnit::GroundAt(double x, double y) const {
  double z = 0.0;
  for (const models::TerrainPiece& t : scene_.terrain) {
    if (const auto top = models::TerrainTopAt(t, x, y)) z = std::max(z, *top);
  }
  return z;
}

std::size_t PerfectMatchLocalizationUnit::DropGroundHits(std::size_t n, const Pose& start) {
  const double c = std::cos(start.yaw), s = std::sin(start.yaw);
  std::size_t kept = 0, low = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = start.x + c * px_[i] - s * py_[i], y = start.y + s * px_[i] + c * py_[i];
    if (base_height_ + pz_[i] < GroundAt(x, y) + ground_clearance_) {
      ++low;
      continue;
    }
    px_[kept] = px_[i];
    py_[kept] = py_[i];
    pz_[kept] = pz_[i];
    ++kept;
  }
  low_points_ += static_cast<double>(low);
  return kept;
}

cosim::StepResult PerfectMatchLocalizationUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  const cosim::StepResult result = ScanLocalizer::DoStep(t, dt);
  UpdateAttitude({position_[0], position_[1], yaw_});
  return result;
}

void PerfectMatchLocalizationUnit::ProcessScan(int k, cosim::TimeNs match_ns) {
  const auto kk = static_cast<std::size_t>(k);
  if (map_index_ < 0 || map_index_ >= map_count()) {
    SetStatus(k, 4);
    return;
  }
  // A map this laser built by SLAM carries its bias (see the header).
  const double map_bias =
      specs_[static_cast<std::size_t>(map_index_)].from_own_laser ? mapping_range_bias_[kk] : 0.0;
  const Pose start = MatchStart(match_ns);
  // With attitude terrain: the points projected by the base's attitude
  // under the start, those below the map's floor dropped.
  std::optional<Tilt> tilt;
  if (attitude_ == "terrain") {
    UpdateAttitude(start);
    // Across a kink (a ramp's foot or top) the chassis' pitch is the
    // tyres' and the suspension's, not the ground's plane, and it changes
    // with the position along the route: an attitude from the estimate
    // would then feed the estimate's error back (a wall 4.5 m ahead moves
    // 20 mm per degree of pitch at 15 deg). The odometry carries the pose
    // over it.
    if (ground_unevenness_ > kink_tolerance_) {
      SetStatus(k, 5);
      return;
    }
    const double floor_m = specs_[static_cast<std::size_t>(map_index_)].floor_m;
    tilt = Tilt{pitch_, roll_, mount_z_[kk], floor_m + ground_clearance_ - base_height_};
  }
  // Deskew by the odometry twist (projected with the attitude).
  const std::size_t collected = CollectPoints(
      k, map_bias, deskew_ && odometry_prediction_, odometry_scale_x_ * odometry_velocity_[0],
      odometry_scale_y_ * odometry_velocity_[1], odometry_yaw_rate_, tilt ? &*tilt : nullptr);
  low_points_ = static_cast<double>(dropped_low_);
  const std::size_t n = tilt ? DropGroundHits(collected, start) : collected;
  if (n < static_cast<std::size_t>(min_points_)) {
    SetStatus(k, 2);
    return;
  }
  map_in_use_ = static_cast<double>(map_index_);
  const PerfectMatch::Result res = matcher_->Match(
      *maps_[static_cast<std::size_t>(map_index_)], std::span<const double>(px_.data(), n),
      std::span<const double>(py_.data(), n), {start.x, start.y, start.yaw}, mount_x_[kk],
      mount_y_[kk]);
  last_result_ = res;
  const bool ok = res.ok && res.mean_error <= max_mean_error_ &&
                  WithinJumpLimits(res.pose.x, res.pose.y, res.pose.yaw, start);
  if (!ok) {
    SetStatus(k, 3);
    return;
  }
  SetStatus(k, 0);
  AcceptMatch({res.pose.x, res.pose.y, models::WrapAngle(res.pose.yaw)}, match_ns);
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
  AddCovarianceFloors();
  match_error_ = res.mean_error;
  match_inlier_fraction_ = res.points > 0 ? res.inlier_weight / res.points : 0.0;
}

void PerfectMatchLocalizationUnit::SaveInternal(cosim::UnitState& state) const {
  SaveTracking(state);
}

void PerfectMatchLocalizationUnit::RestoreInternal(const cosim::UnitState& state) {
  if (state.integers.size() != tracking_integers() || state.reals.size() != tracking_reals()) {
    throw cosim::UnitError(Where() + ": saved state does not fit this unit");
  }
  RestoreTracking(state);
  // Derived values and maps follow the (restored) parameters.
  Derive();
}

}  // namespace linesim::estimation
