// Registers the laser-only localization (see config/unit_registry.h).
#include "config/unit_registry.h"
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
    const YAML::Node list = config::Child(c.parameters, "beam_counts");
    const std::string path = config::JoinPath(c.path, "beam_counts");
    if (!list.IsDefined() || list.IsNull()) {
      c.reader.Error(c.parameters, c.path,
                     "beam_counts is required: one entry per laser, its beam count (e.g. "
                     "[541, 541] for two SICK S300)");
      return nullptr;
    }
    if (!c.reader.ExpectSequence(list, path)) return nullptr;
    if (list.size() < 1 || list.size() > LaserLocalizationUnit::kMaxLasers) {
      c.reader.Error(list, path,
                     "beam_counts must list 1 to " +
                         std::to_string(LaserLocalizationUnit::kMaxLasers) + " lasers, got " +
                         std::to_string(list.size()));
      return nullptr;
    }
    bool ok = true;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const auto n =
          c.reader.AsInteger(list[i], config::JoinPath(path, std::to_string(i)), 1, 100000);
      if (!n) {
        ok = false;
        continue;
      }
      beams.push_back(static_cast<int>(*n));
    }
    if (!ok) return nullptr;
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
