// Registers the chassis family's unit types (see config/unit_registry.h).
#include <string>

#include "config/unit_registry.h"
#include "units/chassis/chassis_unit.h"

namespace linesim::chassis {
namespace {

using config::Child;
using config::JoinPath;
using config::UnitBuildContext;

// A per-wheel list of motor indices (`key`) of `wheels` entries, each in
// [min, wheels - 1] (motor indices are below the wheel count, at most
// ChassisUnit::kMaxWheels); `fallback` when the key is absent.
std::vector<int> ReadMotorList(const UnitBuildContext& c, const std::string& key, int wheels,
                               int min, std::vector<int> fallback) {
  const YAML::Node list = Child(c.parameters, key);
  const std::string path = JoinPath(c.path, key);
  if (!list.IsDefined() || list.IsNull()) return fallback;
  if (!c.reader.ExpectSequence(list, path)) return fallback;
  if (list.size() != static_cast<std::size_t>(wheels)) {
    c.reader.Error(list, path,
                   "expected one motor index per wheel (wheel_count " + std::to_string(wheels) +
                       "), got " + std::to_string(list.size()));
    return fallback;
  }
  std::vector<int> out;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const auto m = c.reader.AsInteger(list[k], JoinPath(path, std::to_string(k)), min, wheels - 1);
    if (!m) return fallback;
    out.push_back(static_cast<int>(*m));
  }
  return out;
}

std::unique_ptr<cosim::Unit> MakeChassis(const UnitBuildContext& c) {
  const int wheels = static_cast<int>(c.reader.Integer(c.parameters, c.path, "wheel_count", 4, 1,
                                                       chassis::ChassisUnit::kMaxWheels));
  // Without the keys: every wheel with its own steering and drive motor (a
  // generic swerve topology, not a robot).
  std::vector<int> own(static_cast<std::size_t>(wheels));
  for (int k = 0; k < wheels; ++k) own[static_cast<std::size_t>(k)] = k;
  const std::vector<int> steer = ReadMotorList(c, "steer_motor", wheels, -1, own);
  const std::vector<int> drive = ReadMotorList(c, "drive_motor", wheels, 0, own);
  if (const std::string bad = chassis::ChassisUnit::TopologyProblem(steer, drive); !bad.empty()) {
    c.reader.Error(c.parameters, c.path, bad);
    return nullptr;
  }
  // Only the scenario sets them (what else moves in the scene).
  const auto boxes = c.reader.Integer(c.parameters, c.path, "moving_boxes", 0, 0, 10000);
  const auto cylinders = c.reader.Integer(c.parameters, c.path, "moving_cylinders", 0, 0, 10000);
  return std::make_unique<chassis::ChassisUnit>(c.name, steer, drive, c.scene,
                                                static_cast<int>(boxes),
                                                static_cast<int>(cylinders));
}

const config::UnitTypeRegistrar kChassis(
    {chassis::ChassisUnit::kTypeName,
     "robot body, steered or fixed wheels (coupled per drive motor) and wheel/floor/belt "
     "contact in ODE, the body colliding with the scene's obstacles and carried objects",
     "",
     {{"wheel_count", "number of wheels, 1 to " + std::to_string(chassis::ChassisUnit::kMaxWheels) +
                          " (default 4)"},
      {"steer_motor",
       "per wheel: index of its steering motor, -1 for a fixed wheel (default: wheel k on "
       "motor k)"},
      {"drive_motor",
       "per wheel: index of its drive motor; wheels with one index are coupled (default: "
       "wheel k on motor k)"},
      {"moving_boxes",
       "number of moving boxes (other robots' bodies) the body collides with: adds the input "
       "moving_boxes, 10 numbers each (default 0)"},
      {"moving_cylinders",
       "number of moving cylinders (workers' legs and torsos) the body collides with: adds the "
       "input moving_cylinders, 7 numbers each (default 0)"}},
     MakeChassis});

}  // namespace
}  // namespace linesim::chassis
