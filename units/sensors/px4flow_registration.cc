// Registers the px4flow unit type of the sensors family (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/sensors/px4flow_unit.h"

namespace linesim::sensors {
namespace {

using config::UnitBuildContext;

std::unique_ptr<cosim::Unit> MakePx4Flow(const UnitBuildContext& c) {
  if (c.scene.surfaces.empty()) {
    c.reader.Error(c.parameters, c.path,
                   "the scene has no surfaces: a px4flow sensor looks at the scene's floor");
    return nullptr;
  }
  return std::make_unique<Px4FlowUnit>(c.name, c.scene, c.seed);
}

const config::UnitTypeRegistrar kPx4Flow(
    {Px4FlowUnit::kTypeName,
     "PX4Flow optic-flow sensor looking down at the floor or a belt: auto exposure, the "
     "firmware's block matching (fast statistical model calibrated against an image-level "
     "reference), OPTICAL_FLOW_RAD integration, sonar distance",
     "sensors",
     {{"model", "model file from models/sensors/ (name, e.g. px4flow) or a path relative to the "
                "scenario"}},
     MakePx4Flow});

}  // namespace
}  // namespace linesim::sensors
