// Registers the world family's unit types (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/world/moving_bodies_unit.h"

namespace linesim::world {
namespace {

std::unique_ptr<cosim::Unit> MakeMovingBodies(const config::UnitBuildContext& c) {
  const auto count = c.reader.Integer(c.parameters, c.path, "count", 1, 1, 10000);
  return std::make_unique<MovingBodiesUnit>(c.name, static_cast<int>(count));
}

const config::UnitTypeRegistrar kMovingBodies(
    {MovingBodiesUnit::kTypeName,
     "a fleet's robots' bodies gathered into one array that every chassis, laser and robot "
     "clearance reads whole",
     "",
     {{"count", "number of bodies (the input bodies_in holds 10 numbers each; default 1)"}},
     MakeMovingBodies});

}  // namespace
}  // namespace linesim::world
