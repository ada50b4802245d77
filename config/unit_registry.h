#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "config/yaml_reader.h"
#include "cosim/unit.h"
#include "models/scene.h"

namespace linesim::config {

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
  /// The unit's model file (`parameters.model`, read from the type's
  /// model_folder): a map, or a null node when it names none; and its path, for
  /// messages (YamlReader::InFile). A factory reads its structural keys
  /// from it when the parameters do not give them; the loader applies the
  /// file's other keys as parameters.
  const YAML::Node& model;
  const std::string& model_file;
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

/// Adds a type to the registry (kept sorted by name). Called during static
/// initialization by each family's registration file, through a
/// UnitTypeRegistrar; a name registered twice aborts the program.
void RegisterUnitType(UnitType type);

/// `const config::UnitTypeRegistrar kRegistrar({...});` at namespace scope
/// of a family's registration file registers the type when the program
/// starts. The family library must be linked whole (see linesim_unit_family
/// in the top-level CMakeLists.txt), or the linker drops the object.
struct UnitTypeRegistrar {
  explicit UnitTypeRegistrar(UnitType type) { RegisterUnitType(std::move(type)); }
};

/// Every registered type, sorted by name.
const std::vector<UnitType>& UnitTypes();
const UnitType* FindUnitType(std::string_view name);
std::vector<std::string> UnitTypeNames();
/// "unknown unit type 'x' (closest: ...); known types: a, b".
std::string UnknownTypeMessage(const std::string& name);

/// For factories: a list of points [x, y] at `key` (at least `min_points`
/// of them); one point at the origin when the unit has no parameters at all
/// (`linesim inspect TYPE`).
std::vector<std::array<double, 2>> ReadPoints(const UnitBuildContext& c, const std::string& key,
                                              std::size_t min_points);

}  // namespace linesim::config
