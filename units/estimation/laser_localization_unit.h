#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "models/scene.h"
#include "units/estimation/occupancy_grid.h"
#include "units/estimation/scan_localizer.h"
#include "units/estimation/scan_matcher.h"

namespace linesim::estimation {

/// Laser-only localization as paper 1 (Sec. IV-B) runs it: hector_mapping's
/// scan matcher (ScanMatcher) against a multi-resolution map of the scene's
/// static solids (OccupancyGrid), one match per new scan of each laser, each
/// started from the latest estimate (hector has no motion model; with
/// motion_prediction: odometry the start is moved by the odometry twist).
///
/// 3-DoF like hector: each laser's scan plane is taken level at its
/// mount_z (roll and pitch of the mount and of the base are ignored); the
/// map holds the scene obstacles whose vertical extent contains one of the
/// mount_z (OccupancyGrid), built in Initialize (before time zero).
///
/// Per new scan of laser k (scan_count_k changed; scans of several lasers
/// in one step in the order of their match times):
///  - points: beam i at angle first_beam_angle + i angular_step of the laser
///    frame, measured at scan_time + i angular_step / (2 pi) scan_period; a
///    range outside [range_min, usable_range_max] (0 = no return) is
///    skipped; the point is put into base_link by the mount (x, y, yaw);
///    with `deskew` it is moved from its beam's time to the match time by
///    the last velocity estimate (velocity, yaw_rate outputs);
///  - fewer than min_points: laser_status 2 (blacked out), no match;
///  - the match; it is REJECTED (laser_status 3, the estimate unchanged) when
///    the Gauss-Newton system is singular, or the mean squared residual
///    (match_cost) exceeds max_cost, or the match's own position sigma
///    (largest of the 2 x 2 block of the unfloored covariance) exceeds
///    max_position_sigma or its yaw sigma max_yaw_sigma (a near-singular
///    Hessian: a featureless corridor), or it lies farther than max_jump /
///    max_jump_yaw from its start (left the coarse level's basin);
///  - else accepted: position, yaw, hessian, match_cost, match_time,
///    covariance, laser_status 0, match_count + 1, and velocity and yaw_rate
///    as the pose change from the oldest accepted match of the last
///    velocity_window (0.2 s) over their match times (between two matches,
///    as hector would, mm-level match noise at 50 matches per second is
///    about +-0.1 m/s).
///
/// Covariance (row-major 3 x 3, x, y, yaw, SI): sigma_r^2 H^-1 with
/// sigma_r^2 = sum (1 - M)^2 / (n - 3) (the Gauss-Newton estimate of the
/// residual variance times the inverse normal matrix), plus
/// diag(covariance_floor_position^2, covariance_floor_position^2,
/// covariance_floor_yaw^2): the raw figure treats the beams as independent
/// and the map as exact (about 1 mm for a 541-beam scan), which a fusion
/// filter would take at face value.
///
/// Map (`map`): `scene` (default) builds the grid from the scene's solids
/// before time zero, as above. `mapping` learns it from the scans as
/// hector_mapping does (OccupancyGrid's learned map: log-odds per cell and
/// level, hits and Bresenham misses, update_factor_occupied /
/// update_factor_free): the grid covers the same floor rectangle + margin,
/// every cell unknown at Initialize. Its frame is the scene's map frame
/// (hector's map frame is its start pose; here the start pose is known:
/// initial_x, initial_y, initial_yaw). Per laser k: while no match has been
/// accepted, laser k's first usable scan enters the map at the current
/// estimate without matching (hector maps its first scan without matching;
/// every laser its own first, since each sees its own side); after that
/// each scan is matched against the current map, and an accepted match
/// enters the map when laser k has not entered it yet or the pose moved
/// more than map_update_distance_thresh (0.4 m) or turned more than
/// map_update_angle_thresh (0.06 rad) since laser k last entered it
/// (hector_mapping's parameters of those names, values of its
/// mapping_default.launch; per laser, where hector has one scan stream).
/// Beams without return or outside [range_min, usable_range_max] enter
/// nothing (hector: no miss for out-of-range beams). The map is saved with
/// the state (log-odds of every level, 4 bytes per cell).
///
/// laser_status per laser: 0 ok, 1 no new scan within scan_timeout, 2
/// blacked out (fewer than min_points returns in its last scan), 3 its last
/// match was rejected. source: 0 the pose is from a match within
/// scan_timeout, 1 no usable laser: the pose is held (motion_prediction
/// none) or predicted from the last accepted match by the odometry inputs
/// (motion_prediction odometry).
class LaserLocalizationUnit : public ScanLocalizer {
 public:
  static constexpr const char* kTypeName = "laser_localization";

  /// One entry of `beam_counts` per laser (1..kMaxLasers lasers, each
  /// 1..100000 beams); throws cosim::UnitError otherwise. The scene's
  /// obstacles and floor are copied (the map is built in Initialize).
  LaserLocalizationUnit(std::string name, const models::Scene& scene, std::vector<int> beam_counts);
  ~LaserLocalizationUnit() override;

  void Initialize() override;

  /// The map (after Initialize).
  const OccupancyGrid* grid() const { return grid_.get(); }
  /// The last match tried (accepted or not).
  const ScanMatcher::Result& last_result() const { return last_result_; }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  void Derive();
  void ProcessScan(int k, cosim::TimeNs match_ns) override;
  /// Enters laser k's points (px_, py_, n of them) into the learned map at `p`.
  void UpdateMap(int k, std::size_t n, const Pose& p);

  std::vector<models::Solid> solids_;
  models::Floor floor_;
  std::vector<models::Solid> map_solids_;  // those the grid holds
  std::unique_ptr<OccupancyGrid> grid_;
  std::unique_ptr<ScanMatcher> matcher_;
  // What the grid was built with (rebuilt only when these change).
  std::vector<double> grid_heights_;
  double grid_resolution_ = 0.0;
  std::int64_t grid_levels_ = 0;
  std::string grid_map_;
  double grid_occupied_ = 0.0, grid_free_ = 0.0;

  // Parameters beside the shared ones.
  std::vector<double> mount_z_;  // per laser
  double map_resolution_ = 0.025;
  std::int64_t map_levels_ = 3, coarse_iterations_ = 3, fine_iterations_ = 5;
  double max_angle_step_ = 0.2;
  double max_cost_ = 0.6, max_position_sigma_ = 0.05, max_yaw_sigma_ = 0.05;
  double velocity_window_ = 0.2;
  std::string map_ = "scene";
  double map_update_distance_thresh_ = 0.4, map_update_angle_thresh_ = 0.06;
  double update_factor_occupied_ = 0.9, update_factor_free_ = 0.4;

  // Outputs beside the shared ones.
  std::vector<double> velocity_;
  double yaw_rate_ = 0.0, match_cost_ = 0.0, map_updates_ = 0.0;

  bool mapping_ = false;  // derived
  ScanMatcher::Result last_result_;

  // The accepted matches of the last velocity_window (a ring, oldest at
  // history_begin_): velocity and yaw rate come from the pose change over
  // the window, not between two matches (a pose's few mm over 20 ms are
  // 0.1 m/s of noise; Eq. 2 adds the velocity to every flow message).
  static constexpr std::size_t kHistory = 64;
  std::array<Pose, kHistory> history_{};
  std::array<cosim::TimeNs, kHistory> history_ns_{};
  std::size_t history_begin_ = 0, history_size_ = 0;
  // map: mapping: per laser, whether its scans have entered the map and the
  // pose it last entered at.
  std::vector<char> mapped_;
  std::vector<Pose> last_map_pose_;
};

}  // namespace linesim::estimation
