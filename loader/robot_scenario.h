#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <string>
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
  double body_length_m = 0, body_width_m = 0;
  int wheel_count = 0;
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
