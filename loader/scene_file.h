#pragma once

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "loader/config_names.h"
#include "loader/overrides.h"
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

/// Makes the keys of the scene file that `root`'s `scene: {model: ...}`
/// names reachable by --set: for each override under `scene.` whose first
/// key below `scene` the scenario does not write, that key's value is copied
/// from the scene file into the scenario's scene (merging a copy of the
/// file's own value changes nothing), so `scene.belts.0.speed_mps=0.2` sets
/// the file's first belt. A scene file that cannot be read is left for the
/// scene reader to report.
void ExposeSceneModelToOverrides(YAML::Node& root, const std::vector<Override>& overrides,
                                 const std::string& scenario_file);

}  // namespace linesim::loader
