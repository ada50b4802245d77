#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "loader/yaml_reader.h"

namespace linesim::loader {

/// What a robot scenario adds to a run beyond its system: the geometry the
/// plots draw and the columns they read.
struct RobotInfo {
  struct Belt {
    double center_x_m, center_y_m, length_m, width_m, direction_rad;
  };
  std::string task;                         // "path" or "hold"
  std::vector<std::array<double, 2>> path;  // desired path; one point for a hold
  std::vector<Belt> belts;
  /// The chassis body as the chassis unit gets it; nothing when no file or
  /// setting gives a usable value (the unit then uses its own default).
  std::optional<double> body_length_m, body_width_m;
  int wheel_count = 0;

  /// Recorded columns (signals.csv headers) of the expanded units that the
  /// plots read: the robot's position and yaw, each wheel's contact point
  /// (x, y), the deviation or drift, and each belt's speed and on state.
  std::string x_column, y_column, yaw_column;
  std::vector<std::pair<std::string, std::string>> wheel_columns;
  std::string error_column;
  std::vector<std::string> belt_speed_columns, belt_on_columns;
};

/// A robot scenario is written at the level of robot, line, control, task,
/// sensing and localization (see README "Scenario files"); it is recognised
/// by its top-level `robot` key.
bool IsRobotScenario(const YAML::Node& root);

/// Expands a robot scenario into a system-level tree (units, connections,
/// recording, metrics) that the system loader builds. Problems are reported
/// through `reader` at the robot-level key paths; `info` receives the plot
/// geometry. A robot.model given as a path is relative to the folder of
/// `reader`'s file, the scenario.
YAML::Node ExpandRobotScenario(const YAML::Node& root, YamlReader& reader, RobotInfo& info);

}  // namespace linesim::loader
