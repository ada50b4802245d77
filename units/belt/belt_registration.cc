// Registers the belt family's unit types (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/belt/belt_unit.h"

namespace linesim::belt {
namespace {

using config::UnitBuildContext;

std::unique_ptr<cosim::Unit> MakeBelt(const UnitBuildContext& c) {
  if (c.scene.belts.empty()) {
    c.reader.Error(c.parameters, c.path,
                   "the scene has no belts: a belt unit drives the belts of the scenario's scene "
                   "(scene.belts)");
    return nullptr;
  }
  return std::make_unique<belt::BeltUnit>(c.name, c.scene.belts, c.seed);
}

const config::UnitTypeRegistrar kBelt(
    {belt::BeltUnit::kTypeName,
     "the belts of the scene (scene.belts): on/off schedule, finite acceleration, seeded "
     "+-variation of speed, travelled distance",
     "",
     {},
     MakeBelt});

}  // namespace
}  // namespace linesim::belt
