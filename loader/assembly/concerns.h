#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "loader/assembly/builder.h"
#include "loader/robot_file.h"
#include "loader/robot_scenario.h"
#include "models/scene.h"

/// The concerns a robot scenario is assembled from, in the order
/// ExpandRobotScenario applies them. Each adds its units and connections to
/// the builder and records in Signals what it provides; the next concern
/// connects to whatever provides a pose, a twist or a surface velocity,
/// never to a literal unit of another concern.
namespace linesim::loader::assembly {

/// What the assembled units provide, by role: the unit variable that plays
/// it (empty when none does).
struct Signals {
  /// Ground truth of the robot: evaluation reads these, never estimates.
  Port true_position, true_yaw, true_surface_velocity;
  /// What the controllers use: localization's and sensing's choice (the
  /// robot's velocity in map and yaw rate too: Eq. 2 needs them).
  Port position, yaw, velocity, yaw_rate, surface_velocity;
  /// The estimators, when the scenario closes the loop through them: the
  /// odometry unit ("" for none), the surface estimator's filtered value
  /// per PX4Flow in map ("" for none), and each localization's source
  /// output (which source it is using: the fallbacks).
  std::string odometry;
  Port surface_estimate;
  std::vector<Port> localization_sources;

  /// Joints of the drive train: the chassis's index of each wheel's
  /// steering joint (-1: fixed wheel) and drive joint, and the dc_motor
  /// element of each chassis steering and drive joint.
  std::vector<int> wheel_steer_joint, wheel_drive_joint;
  std::vector<std::size_t> steer_motor_element, drive_motor_element;

  /// The wheel controller's command inputs, which the task drives.
  Port velocity_command_input, yaw_rate_command_input;

  /// Map switching (paper 2): the localization's maps by name and its map
  /// index input (empty without one); a route's maps by name (its graph's),
  /// the follower's map index output, its done output and the route's end
  /// pose {x, y, yaw} (empty without a route).
  std::vector<std::string> localization_maps, route_maps;
  Port map_index_input, map_index_output, route_done;
  std::vector<double> route_end;
  /// The beacon system measuring the final pose ("" for none).
  std::string beacon_unit;

  /// Belts of the scene: how many, and the belt unit's outputs.
  std::size_t belt_count = 0;
  /// Whether the scene has terrain pieces (the robot's height varies).
  bool terrain = false;

  /// The sensor units on the robot, one per enabled mount (the unit is
  /// named after the mount, its type is the mount's kind), and the belt's
  /// ground-truth speed ("" when there is none).
  std::vector<models::SensorMount> sensors;
  Port belt_ground_truth;
  int belt_ground_truth_belt = 0;  // the scene belt it measures
  /// The laser whose scan at scan_time_s the plots draw ("" for none).
  std::string scan_unit;
  double scan_time_s = 0.0;
  std::optional<RobotInfo::ScanGeometry> scan_geometry;

  /// What each concern wants recorded, in order.
  std::vector<Port> recorded;
};

/// The robot's pose at time zero (robot.pose).
struct StartPose {
  double x_m = 0.0, y_m = 0.0, yaw_rad = 0.0;
};

/// scene + line: the scenario's scene (`scene:`, with `line.belts` as the
/// overrides of its belts by index) into the expansion's `scene:`; returns
/// the scene as the system loader will read it.
models::Scene AddScene(SystemBuilder& b);

/// robot: the chassis (ODE) and the motors (one CVODE unit for every motor
/// group), wired torque to joint and joint rate to shaft.
Signals AddDriveTrain(SystemBuilder& b, const RobotFile& robot, const StartPose& start,
                      const models::Scene& scene, RobotInfo& info);

/// The line's belt unit, driving the scene's belts under the chassis.
void AddLine(SystemBuilder& b, const models::Scene& scene, Signals& s);

/// sensors: a unit per sensor mount of the robot description (PX4Flow,
/// lasers, IMU, wheel encoders) and the belt's ground-truth encoder, as
/// the scenario's `sensors:` section enables and configures them.
void AddSensors(SystemBuilder& b, const RobotFile& robot, Signals& s);

/// Connects the route follower's map index to the localization's (paper 2's
/// map switching), after the task: the graph's maps and localization.maps
/// must be the same names in the same order. Several maps without a route
/// are refused.
void ConnectMapSwitch(SystemBuilder& b, const Signals& s);

/// Paper 2's ground truth: a beacon system (beacon_localization on the
/// robot's first laser) when the scene has at least three beacons and the
/// task is a route (the beacons are uncovered once it is done).
void AddBeaconGroundTruth(SystemBuilder& b, const RobotFile& robot, const StartPose& start,
                          const models::Scene& scene, Signals& s);

/// sensing.surface_velocity and localization.source: who tells the
/// controllers the surface velocity under each wheel and the pose
/// (ground truth, or the robot's own sensors through the estimators of
/// units/estimation).
void AddSensing(SystemBuilder& b, const RobotFile& robot, const StartPose& start,
                const models::Scene& scene, Signals& s);
/// The robot's wheel positions in base_link as a unit's list parameters
/// wheel_x and wheel_y (the controller's, the odometry's and the surface
/// estimator's wheels).
void SetWheelPositions(Parameters& params, const models::RobotDescription& robot);
/// Whether the robot description mounts a sensor of `kind`.
bool RobotHas(const models::RobotDescription& robot, const std::string& kind);

/// control: the wheel controller of the robot's kind (swerve: Eq. 1 and
/// Algorithm 1; differential), wired to the motors and the joints.
void AddControl(SystemBuilder& b, const RobotFile& robot, Signals& s);

/// task: the path follower (a path, or a point to hold) driving the wheel
/// controller's command inputs from the pose.
void AddTask(SystemBuilder& b, const RobotFile& robot, const StartPose& start, Signals& s,
             RobotInfo& info);

/// Evaluation: the ground-truth deviation from the task, the body's
/// clearance, raw optic flow against the belt's ground truth, and the
/// metrics.
void AddEvaluation(SystemBuilder& b, const models::RobotDescription& robot, Signals& s,
                   RobotInfo& info);

/// recording: what signals.csv holds (unless the scenario says), at about
/// 100 Hz; and the columns the plots read.
void AddRecording(SystemBuilder& b, const Signals& s, RobotInfo& info);
/// The expansion's `recording:`: the scenario's own with `recorded` added to
/// a list it gives, or `recorded` at about 100 Hz.
void AddRecordingSection(SystemBuilder& b, const std::vector<std::string>& recorded);

}  // namespace linesim::loader::assembly
