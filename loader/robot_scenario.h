#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "loader/config_names.h"
#include "loader/system_spec.h"

namespace linesim::loader {

/// What a robot scenario adds to a run beyond its system: what the plots
/// draw besides the scene, and the columns they read.
struct RobotInfo {
  /// The robot's name in a fleet (`robots:`), which scopes its units and
  /// metrics (raw3_a.chassis); "" for the one-robot shorthand.
  std::string name;
  /// robot.pose at time zero: x (m), y (m), yaw (rad).
  std::array<double, 3> start_pose{};
  std::string task;                         // "path" or "hold"
  std::vector<std::array<double, 2>> path;  // desired path; one point for a hold
  /// The chassis body as the chassis unit gets it; nothing when the value
  /// there is not a positive number (the chassis unit reports it).
  std::optional<double> body_length_m, body_width_m;
  int wheel_count = 0;

  /// Recorded columns (signals.csv headers) of the expanded units that the
  /// plots read: the robot's position and yaw, each wheel's contact point
  /// (x, y), the deviation or drift, and each belt's speed, on state and
  /// travel (which moves the objects it carries).
  std::string x_column, y_column, yaw_column;
  /// base_link's height, over a scene with terrain ("" otherwise).
  std::string z_column;
  std::vector<std::pair<std::string, std::string>> wheel_columns;
  /// The surface under each wheel (chassis wheel_surface: -1 no contact, 0
  /// floor, k + 1 belt k, belts + 1 + j terrain piece j) and the motors'
  /// armature currents, whole arrays (the replay reads them).
  std::string wheel_surface_column, motor_current_column;
  std::string error_column;
  /// The route follower's done output (0/1; "" for other tasks).
  std::string task_done_column;
  std::vector<std::string> belt_speed_columns, belt_on_columns, belt_travel_columns;
  /// Optic flow against the belt's ground truth (paper 1 Fig. 4): what
  /// each PX4Flow reads along the belt (the surface relative to it), its
  /// sensor's name, the same reading from ground truth, and the belt's
  /// ground-truth speed; empty without both.
  std::vector<std::string> flow_columns, flow_sensor_names, flow_truth_columns;
  std::vector<std::string> flow_filtered_columns;  // the estimate's, if any
  std::string flow_reference_column;
  /// The laser unit whose completed scan at scan_time_s the plots draw
  /// (sensors.NAME.snapshot_s; its ranges and scan_time are recorded), or "".
  std::string scan_unit;
  double scan_time_s = 0.0;
  /// That laser's geometry from the system description (its mount, and its
  /// device's numbers: the scenario's or robot file's setting, else its
  /// model file's): mount in base_link (x, y, yaw), the beams' angles in the
  /// scanner frame first + k * step, k < beams, and the range meaning no
  /// echo. Nothing when a number is missing (the laser unit reports it).
  struct ScanGeometry {
    double mount_x_m = 0.0, mount_y_m = 0.0, mount_yaw_rad = 0.0;
    double first_beam_rad = 0.0, beam_step_rad = 0.0, no_return_m = 0.0;
    int beams = 0;
  };
  std::optional<ScanGeometry> scan_geometry;
  /// Workers and the safety fields (loader/assembly/people.cc): each
  /// worker's pose x and y columns; the robot's map velocity x and y, the
  /// safety unit's speed cap and field states, the distance to the nearest
  /// person ("" without them).
  std::vector<std::pair<std::string, std::string>> worker_columns;
  std::string velocity_x_column, velocity_y_column, speed_cap_column, protective_column,
      warning_column, person_distance_column;
  /// Each worker's name and legs' columns ([x_left, y_left, x_right,
  /// y_right]), in the order of worker_columns.
  std::vector<std::string> worker_names;
  std::vector<std::array<std::string, 4>> worker_leg_columns;
  /// The safety unit's active field set (its index) and, per field set,
  /// how far forward its protective and warning fields reach in base_link
  /// (m, the polygons' largest x; NaN: no warning field).
  std::string field_set_column;
  std::vector<std::array<double, 2>> field_reach_m;
  /// `figures.bound`: the published bound the figures judge the run by
  /// (error.png, the replay, a comparison): value (m), legend entry, and
  /// whether it bounds the final pose (drawn from the task's done on)
  /// rather than the whole run. value_m 0: none.
  struct FigureBound {
    double value_m = 0.0;
    std::string label;
    bool final_pose = false;
  };
  FigureBound figure_bound;
  /// A fleet's other robots (the first robot is this one), their columns
  /// scoped by their names.
  std::vector<RobotInfo> fleet;
};

/// The most robots a fleet (`robots:`) may have, checked before anything is
/// built and named at `robots`. Measured (linesim inspect of fleets of
/// Rob@Work 3 with every sensor, peak memory): 74 MB at 20 robots, 271 MB
/// at 80, 615 MB at 160, i.e. about 2.5 MB per robot and 7 KB per pair of
/// robots (each robot's lasers, chassis and clearance take every other
/// body); 350 MB at 100. 1,000 robots needed 10 GB and ended in
/// std::bad_alloc (issue 37). docs/scenarios.md, "A fleet".
inline constexpr std::size_t kMaxRobots = 100;
inline constexpr const char* kMaxRobotsWhy =
    "each robot takes about 2.5 MB and each pair of robots 7 KB, as every robot's lasers, "
    "chassis and clearance take every other body: 100 robots load in 0.35 GB, 1,000 needed "
    "10 GB";
/// The most robot-worker pairs (robots x workers: every robot's lasers and
/// person clearance take every worker's legs and torso, 21 numbers each,
/// element by element), checked before anything is built and named at
/// `workers`. Measured: 1 robot with 200 workers 80 MB, with 800 248 MB;
/// 10 robots with 100 workers 287 MB, with 200 526 MB: about 0.25 MB per
/// pair. 3,400 workers were refused after 20 s at an internal key (issue
/// 37). docs/scenarios.md, "Workers".
inline constexpr std::size_t kMaxRobotWorkerPairs = 1000;
inline constexpr const char* kMaxRobotWorkerPairsWhy =
    "every robot's lasers and person clearance take every worker's legs and torso, about "
    "0.25 MB per robot-worker pair: 1,000 pairs load in 0.25 GB";

/// A robot scenario is written at the level of robot, scene, line, control,
/// task, sensing and localization (docs/scenarios.md); it is recognised by
/// its top-level `robot` key, or `robots` for a fleet (a list of robots,
/// each with its own model, pose, task, control, sensing, localization,
/// sensors and safety, on one scene with its line and workers).
bool IsRobotScenario(const YAML::Node& root);

/// Expands a robot scenario into a system description (scene, units,
/// connections, recording, metrics) that the scenario builder builds, one
/// concern after another (loader/assembly/concerns.h). Problems are
/// reported through `reader` at the robot-level key paths; `info` receives
/// what the plots need. A robot.model given as a path is relative to the
/// folder of `reader`'s file, the scenario.
SystemSpec ExpandRobotScenario(const YAML::Node& root, YamlReader& reader, RobotInfo& info);

}  // namespace linesim::loader
