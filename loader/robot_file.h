#pragma once

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>

#include "loader/config_names.h"
#include "models/robot_description.h"

namespace linesim::loader {

/// A robot description file (models/robots/*.yaml) as read: the typed
/// description, and the settings it gives the units built from it, in the
/// units' own parameter names (passed on as they are).
struct RobotFile {
  models::RobotDescription robot;
  /// Map of chassis unit parameters that are not geometry: contact,
  /// suspension, joint friction, brake, substeps.
  YAML::Node chassis_settings;
  /// Map of dc_motor unit settings shared by every motor (tolerances, how
  /// the shaft speed is held).
  YAML::Node motor_settings;
  /// Map of the wheel controller's parameters that the description gives
  /// directly (rate and acceleration limits, gains, an effective track).
  YAML::Node controller_settings;
  /// Map of path_follower parameters the robot sets (its speed and yaw
  /// rate limits).
  YAML::Node follower_settings;
  /// Per sensor mount (same order as robot.sensor_mounts): the map of
  /// unit parameters its `parameters:` key gives (device options, counts
  /// per revolution), or an empty map.
  std::vector<YAML::Node> sensor_settings;
  /// The vehicle's safety configuration (`safety:` {scanner, field_sets,
  /// parameters}: the S300's field sets and the reaction), used when a
  /// scenario switches the safety function on; undefined when absent.
  YAML::Node safety;

  /// Where the description's values were written, so that a problem the
  /// assembly's units find in a value derived from one is reported at the
  /// file and key the user wrote: the robot file's tree, and each motor
  /// group's model file tree (same order as robot.motor_groups).
  YAML::Node root;
  std::vector<YAML::Node> motor_models;
  /// The robot file's key path `path` ("sensor_mounts.2.z_m"): its node,
  /// or the nearest one above it when the key is absent (a default).
  Origin At(const std::string& path) const;
  /// Key `key` of motor group `group`'s model file.
  Origin MotorAt(std::size_t group, const std::string& key) const;
};

/// Reads the robot description `model` names (a file in models/robots, or a
/// path relative to `relative_to`'s folder) and the motor model files its
/// groups name. Every problem is reported through `r` in the file it is in,
/// with its line and key path: a missing required value names its key, a
/// wheel that names an unknown motor, a motor no wheel uses, a topology the
/// controller kind cannot drive. Problems of the name itself are reported
/// at `at`/`path`. Nothing when the file cannot be used.
/// A payload map ({mass_kg, x_m, y_m, z_m (its centre of mass in base_link),
/// and optionally length_m, width_m, height_m: its box}) at `path`, as a
/// robot file's `payload` and a robot scenario's `robot.payload` write it;
/// nothing (problems reported through `r`) when it is not usable.
std::optional<models::PayloadDescription> ReadPayload(YamlReader& r, const YAML::Node& node,
                                                      const std::string& path);

std::optional<RobotFile> ReadRobotFile(YamlReader& r, const YAML::Node& at,
                                       const std::string& path, const std::string& model,
                                       const std::string& relative_to);

}  // namespace linesim::loader
