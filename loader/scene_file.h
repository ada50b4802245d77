#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

#include "loader/config_names.h"
#include "models/scene.h"

namespace linesim::loader {

/// Reads a scene description (the format of models/scenes/*.yaml, described
/// at the top of models/scenes/factory_line.yaml) from `root`, reporting
/// every problem through `r` at key paths under `path`: unknown keys with
/// the closest ones, wrong types, out-of-range values, missing required
/// values, and names of surfaces or belts that the scene does not define.
/// `name` and `file` go into the result as they are.
models::Scene ReadScene(YamlReader& r, const YAML::Node& root, const std::string& path,
                        const std::string& name, const std::string& file);

/// The scene file `file`, or ScenarioError listing every problem of it.
models::Scene LoadSceneFile(const std::string& file);

/// A scenario's top-level `scene` value: OpenFloor() when `scene` is absent
/// or null; what it writes when it names no `model`; else the scene file it
/// names (models/scenes/NAME.yaml, or a path relative to `scenario_file`)
/// with the scenario's keys added or overriding: maps merge by key, list
/// items by index (an item past the file's list is added). Problems of the
/// scene file are reported in the scene file; problems of what the scenario
/// writes (alone or merged) at its key path under `scene` in `r`'s file, so
/// values set with --set say so.
models::Scene ReadScenarioScene(YamlReader& r, const YAML::Node& scene,
                                const std::string& scenario_file);

}  // namespace linesim::loader
