// Registers the laser-only localization (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/estimation/beam_counts.h"
#include "units/estimation/laser_localization_unit.h"

namespace linesim::estimation {
namespace {

using config::UnitBuildContext;

std::unique_ptr<cosim::Unit> MakeLaserLocalization(const UnitBuildContext& c) {
  const bool inspect = !c.parameters.IsDefined() || c.parameters.IsNull();
  std::vector<int> beams;
  if (inspect) {
    beams = {1};  // `linesim inspect laser_localization`: one laser of one beam
  } else {
    auto read = ReadBeamCounts(c, "e.g. [541, 541] for two SICK S300");
    if (!read) return nullptr;
    beams = std::move(*read);
  }
  return std::make_unique<LaserLocalizationUnit>(c.name, c.scene, std::move(beams));
}

const config::UnitTypeRegistrar kLaserLocalization(
    {LaserLocalizationUnit::kTypeName,
     "laser-only localization (paper 1 Sec. IV-B, hector_mapping's scan matcher): Gauss-Newton "
     "scan matching of each new scan of each laser against a multi-resolution grid of the "
     "scene's static solids",
     "",
     {{"beam_counts",
       "one entry per laser: its beam count (the size of its ranges_<k> input), e.g. [541, 541]"}},
     MakeLaserLocalization});

}  // namespace
}  // namespace linesim::estimation
