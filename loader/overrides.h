#pragma once

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "loader/config_names.h"

namespace linesim::loader {

/// A command-line override `dotted.path=value`: map keys by name, list items
/// by index ("units.motors.parameters.gear_ratio.2=5").
struct Override {
  std::string path;
  std::string value;
};

/// Splits "a.b=value"; throws ScenarioError when there is no '=' or path.
Override ParseOverride(const std::string& text);

/// Reports each override whose path goes through a value the file reaches
/// again through a YAML alias (an anchored value and its aliases are one
/// node: writing it through one path would change it at every other). Call
/// on the tree as read from the file, before anything is added to it.
void RefuseOverridesThroughAliases(const YAML::Node& root, const std::vector<Override>& overrides,
                                   const std::string& file, std::vector<Issue>& issues);

/// Writes each override into the tree. Every key on the way must exist (an
/// unknown one is reported with the closest existing paths); the last key of
/// a map may be new, and is then checked like any key of the file. The value
/// is read as YAML, so "true", "3" and "[1, 2]" keep their types.
void ApplyOverrides(YAML::Node& root, const std::vector<Override>& overrides,
                    const std::string& file, std::vector<Issue>& issues);

}  // namespace linesim::loader
