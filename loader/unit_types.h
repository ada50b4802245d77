#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "cosim/unit.h"
#include "loader/yaml_reader.h"
#include "models/scene.h"

namespace linesim::loader {

/// What a unit type's factory gets: the instance name, its seed, and the
/// unit's `parameters` map for the structural keys that shape the variable
/// table (channel counts, modes). Every other key is applied afterwards to
/// the unit's declared parameters.
struct UnitBuildContext {
  const std::string& name;
  std::uint64_t seed;
  YamlReader& reader;
  const YAML::Node& parameters;  // may be undefined
  const std::string& path;       // "units.NAME.parameters"
  /// The scenario's scene (models/scene.h), read once by the loader;
  /// models::OpenFloor() when the scenario names none.
  const models::Scene& scene;
};

struct UnitType {
  std::string name;
  std::string description;
  /// Folder under models/ holding model files for `parameters.model`; empty
  /// if the type takes none.
  std::string model_folder;
  struct Key {
    std::string name;
    std::string description;
  };
  /// Keys the factory reads itself (shown by `linesim inspect TYPE`).
  std::vector<Key> structural_keys;
  /// Returns nullptr after reporting issues through the reader.
  std::function<std::unique_ptr<cosim::Unit>(const UnitBuildContext&)> create;
};

const std::vector<UnitType>& UnitTypes();
const UnitType* FindUnitType(std::string_view name);
std::vector<std::string> UnitTypeNames();
/// "unknown unit type 'x' (closest: ...); known types: a, b".
std::string UnknownTypeMessage(const std::string& name);

}  // namespace linesim::loader
