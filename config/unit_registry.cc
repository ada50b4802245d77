#include "config/unit_registry.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "cosim/closest_names.h"

namespace linesim::config {

namespace {

// Constructed on first use, so registrars of any translation unit may run
// before or after this file's own static initialization.
std::vector<UnitType>& Registry() {
  static std::vector<UnitType> types;
  return types;
}

}  // namespace

void RegisterUnitType(UnitType type) {
  auto& types = Registry();
  const auto at =
      std::lower_bound(types.begin(), types.end(), type.name,
                       [](const UnitType& t, const std::string& n) { return t.name < n; });
  if (at != types.end() && at->name == type.name) {
    std::fprintf(stderr, "linesim: unit type '%s' is registered twice\n", type.name.c_str());
    std::abort();
  }
  types.insert(at, std::move(type));
}

const std::vector<UnitType>& UnitTypes() { return Registry(); }

const UnitType* FindUnitType(std::string_view name) {
  for (const auto& t : UnitTypes()) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

std::vector<std::string> UnitTypeNames() {
  std::vector<std::string> names;
  for (const auto& t : UnitTypes()) names.push_back(t.name);
  return names;
}

std::string UnknownTypeMessage(const std::string& name) {
  return "unknown unit type '" + name + "'" + cosim::ClosestHint(name, UnitTypeNames()) +
         "; known types: " + JoinNames(UnitTypeNames());
}

// A list of points [x, y] at `key` (at least `min_points` of them).
std::vector<std::array<double, 2>> ReadPoints(const UnitBuildContext& c, const std::string& key,
                                              std::size_t min_points) {
  std::vector<std::array<double, 2>> points;
  const YAML::Node list = Child(c.parameters, key);
  const std::string path = JoinPath(c.path, key);
  if (!list.IsDefined() && (!c.parameters.IsDefined() || c.parameters.IsNull())) {
    return {{0.0, 0.0}};  // `linesim inspect TYPE`: no parameters at all
  }
  if (!list.IsDefined()) {
    c.reader.Error(c.parameters, path, "missing required key: a list of points [x, y] (m)");
    return points;
  }
  if (!c.reader.ExpectSequence(list, path)) return points;
  if (list.size() < min_points) {
    c.reader.Error(list, path, "expected at least " + std::to_string(min_points) + " points");
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (auto p = c.reader.AsPoint(list[i], JoinPath(path, std::to_string(i)))) {
      points.push_back(*p);
    }
  }
  return points;
}

}  // namespace linesim::config
