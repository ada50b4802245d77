#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "models/scene.h"
#include "units/estimation/distance_map.h"
#include "units/estimation/perfect_match.h"
#include "units/estimation/scan_localizer.h"

namespace linesim::estimation {

/// Laser localization as paper 2 runs it (Sobreira et al. 2019, "Autonomous
/// Robot Navigation for Automotive Assembly Task: An Industry Use-Case",
/// Sec. 4): Perfect Match (PerfectMatch, Lauer, Lange, Riedmiller 2005) of
/// each new scan against a distance map of the scene (DistanceMap), one of
/// several maps chosen per scan by the `map_index` input (paper 2: the
/// factory map outside, the van interior's map inside, the transition set
/// by the position along the robot's path). Its outputs feed pose_fusion's
/// match inputs (the EKF with odometry).
///
/// 3-DoF as paper 2's matcher: each laser's beams are put into base_link by
/// its mount's x, y and yaw; the mount's roll and pitch are ignored. The
/// robot's own attitude (`attitude`): none, the scan plane taken as level
/// (a robot on a flat floor); terrain, the attitude from the scene's known
/// terrain (a ramp) under the wheels' contact points at the match's start
/// pose (the corners of the rectangle wheelbase x track about base_link):
/// the least-squares plane through the ground's heights there (the floor at z 0, or the top face of
/// the highest terrain piece above the point) gives pitch, roll and base_link's height. Each beam's
/// point is then turned by that pitch and roll, its horizontal part matched (a pitched scan reads a
/// wall at d as d / cos pitch), and a point less than ground_clearance above the map's floor_m or
/// above the ground under it is dropped (it hit the floor, the ramp or the van floor: a pitched
/// scan plane cuts them in a line across the route, a phantom wall that moves with the robot).
/// While the ground under the tyres is not one plane (within kink_tolerance: the chassis across the
/// ramp's foot or top) no scan is matched (laser_status 5) and the
/// odometry carries the pose. The odometry that predicts
/// the start is projected too (its vx times cos pitch, vy times cos roll),
/// and the pitch and roll are outputs for pose_fusion's. The maps are horizontal slices of the
/// scene's static solids (structural key `maps`: name, height_m, optional region), all built in
/// Initialize (before time zero); switching maps never resets the pose.
///
/// Per new scan of laser k (scan_count_k changed; several lasers' scans in
/// one step in the order of their match times):
///  - points: beam i at angle first_beam_angle + i angular_step, measured
///    at scan_time + i angular_step / (2 pi) scan_period; returns outside
///    [range_min, usable_range_max] (0 = no return) skipped; against a map
///    built by the robot's own laser (MapSpec::from_own_laser) each range
///    less that laser's mapping_range_bias: SLAM with a scanner whose ranges
///    read b long puts every outline b beyond the face along the mapping
///    beams, so a return of the same device matches the map's outline at
///    r - b on the geometry (first order: exact where the mapping beams met
///    a face along the same line as now, off by b (1 - cos) of the angle
///    between them otherwise); with `deskew`
///    (and motion_prediction odometry) each point is moved from its beam's
///    time to the match time (the middle beam's) by the odometry twist;
///  - map_index outside 0..maps-1: laser_status 4, no match;
///  - fewer than min_points: laser_status 2, no match;
///  - the start: the last accepted match, moved to the match time by the
///    odometry inputs with motion_prediction odometry (Tribots starts from
///    the odometry-predicted pose);
///  - the match; REJECTED (laser_status 3, the estimate unchanged) when its
///    curvature is not positive definite, its mean error E / n exceeds
///    max_mean_error, or it lies farther than max_jump / max_jump_yaw from
///    its start;
///  - else accepted: position, yaw, covariance = the match's
///    s^2 (2 / c^2) H^-1 (PerfectMatch) + range_bias_sigma^2 g g^T (g the
///    match's bias_sensitivity: a range bias common to a scan's beams, the
///    LMS151's systematic error) + diag(floor_p^2, floor_p^2, floor_yaw^2),
///    hessian, match_error, match_inlier_fraction,
///    match_time, match_count + 1.
/// laser_status per laser: 0 ok, 1 no new scan within scan_timeout, 2
/// blacked out, 3 rejected, 4 no such map, 5 held across a kink of the
/// ground (attitude terrain). source: 0 the pose is from a
/// match within scan_timeout, 1 held (or odometry-predicted with
/// motion_prediction odometry) since.
class PerfectMatchLocalizationUnit : public ScanLocalizer {
 public:
  static constexpr const char* kTypeName = "perfect_match_localization";
  static constexpr int kMaxMaps = 16;

  struct MapSpec {
    std::string name;
    double height_m = 0.0;  // the slice's z above the floor
    std::optional<DistanceMap::Region> region;
    /// The lookup grid's cell for this map (m); 0: the lookup_cell parameter.
    double cell_m = 0.0;
    /// Built by SLAM with the robot's own lasers (paper 2 Sec. 3.2: both
    /// its maps "built using SLAM"), not from the geometry: see
    /// mapping_range_bias.
    bool from_own_laser = false;
    /// The floor the map's outlines stand on (m, map z): with attitude
    /// terrain, points lower than it plus ground_clearance are dropped.
    double floor_m = 0.0;
  };

  /// One entry of `beam_counts` per laser (1..kMaxLasers, each 1..100000
  /// beams), 1..kMaxMaps maps with finite heights; throws cosim::UnitError
  /// otherwise. The scene is copied (the maps are built in Initialize).
  PerfectMatchLocalizationUnit(std::string name, const models::Scene& scene,
                               std::vector<int> beam_counts, std::vector<MapSpec> maps);
  ~PerfectMatchLocalizationUnit() override;

  /// The base's checks, and each map's lookup grid within
  /// OccupancyGrid::kMaxCells (refused at load, not when the maps are built).
  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Initialize() override;
  /// The shared step, then the attitude at its end (the outputs, and the
  /// odometry's projection in the next step's prediction).
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  int map_count() const { return static_cast<int>(specs_.size()); }
  /// Map i (after Initialize).
  const DistanceMap& map(int i) const { return *maps_[static_cast<std::size_t>(i)]; }
  const MapSpec& map_spec(int i) const { return specs_[static_cast<std::size_t>(i)]; }
  /// The last match tried (accepted or not).
  const PerfectMatch::Result& last_result() const { return last_result_; }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  void Derive();
  /// With attitude terrain: the ground's plane under the contact points at
  /// (x, y, yaw) into pitch_, roll_, base_height_ and the odometry's
  /// projection factors; with none, level.
  void UpdateAttitude(const Pose& at);
  /// The ground's height at map (x, y): the floor (0) or the highest
  /// terrain top face over it.
  double GroundAt(double x, double y) const;
  /// Drops from the n collected points (px_, py_, pz_) those less than
  /// ground_clearance above the ground under them (placed from `start`):
  /// the ramp, the van floor. Returns the count kept.
  std::size_t DropGroundHits(std::size_t n, const Pose& start);
  void ProcessScan(int k, cosim::TimeNs match_ns) override;

  std::vector<MapSpec> specs_;
  models::Scene scene_;
  std::vector<std::unique_ptr<DistanceMap>> maps_;
  double built_cell_ = 0.0, built_margin_ = 0.0;  // what maps_ were built with
  std::unique_ptr<PerfectMatch> matcher_;

  // Parameters beside the shared ones.
  double lookup_cell_ = 0.02, map_margin_ = 1.0;
  double c_ = 0.25, step_position_ = 0.04, step_yaw_ = 0.1;
  std::int64_t iterations_ = 10, few_iterations_ = 20, few_points_ = 20, refine_iterations_ = 1,
               rprop_stride_ = 1;
  double max_mean_error_ = 0.5;
  double range_bias_sigma_ = 0.0;
  std::string attitude_ = "none";
  double wheelbase_ = 0.5, track_ = 0.5, wheel_radius_ = 0.1;
  std::vector<double> mount_z_;
  double ground_clearance_ = 0.1;
  double kink_tolerance_ = 0.002;

  // Inputs beside the shared ones.
  std::vector<double> mapping_range_bias_;  // per laser
  std::int64_t map_index_ = 0;

  // Outputs beside the shared ones.
  double match_error_ = 0.0, match_inlier_fraction_ = 0.0, map_in_use_ = 0.0;
  double pitch_ = 0.0, roll_ = 0.0, low_points_ = 0.0;
  double base_height_ = 0.0;        // base_link's z in map under the attitude's pose
  double ground_unevenness_ = 0.0;  // the tyres' ground samples' largest departure from their plane

  PerfectMatch::Result last_result_;
};

}  // namespace linesim::estimation
