// Registers the van bay's ground truth units (paper 2, Sobreira et al.
// 2019, Sec. 6.1): the beacon-based localization and the final pose error
// (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/evaluation/beacon_localization.h"
#include "units/evaluation/final_pose_error.h"

namespace linesim::evaluation {
namespace {

using config::UnitBuildContext;

std::unique_ptr<cosim::Unit> MakeBeaconLocalization(const UnitBuildContext& c) {
  const bool inspect = !c.parameters.IsDefined() || c.parameters.IsNull();
  const std::size_t issues_before = c.reader.issues().size();
  const std::int64_t beams = c.reader.Integer(
      c.parameters, c.path, "beam_count",
      inspect ? std::optional<std::int64_t>(1) : std::nullopt, 1, 100000);
  std::vector<BeaconLocalizationUnit::Beacon> beacons;
  for (const models::Obstacle* o : BeaconLocalizationUnit::SceneBeacons(c.scene)) {
    if (o->solid.kind != models::Solid::Kind::kCylinder) {
      c.reader.Error(c.parameters, c.path,
                     "scene obstacle '" + o->name +
                         "' is of kind beacon but not a cylinder: the beacons must be vertical "
                         "cylinders");
      continue;
    }
    beacons.push_back({o->solid.x_m, o->solid.y_m, o->solid.radius_m});
  }
  if (!inspect && beacons.size() < 3) {
    c.reader.Error(c.parameters, c.path,
                   "the scene has " + std::to_string(beacons.size()) +
                       " cylinders of kind beacon; a beacon localization needs at least 3");
  }
  if (c.reader.issues().size() != issues_before) return nullptr;
  return std::make_unique<BeaconLocalizationUnit>(c.name, std::move(beacons),
                                                  static_cast<int>(beams), c.seed);
}

const config::UnitTypeRegistrar kBeaconLocalization(
    {BeaconLocalizationUnit::kTypeName,
     "ground truth of paper 2 (Sec. 6.1): the robot's pose from the scene's cylindrical beacons "
     "seen by one laser (circle fits of known radius, association by geometry, then an EKF "
     "over a standing robot)",
     "",
     {{"beam_count", "beams per scan of the laser (the size of `ranges`), e.g. 541 (LMS151)"}},
     MakeBeaconLocalization});

std::unique_ptr<cosim::Unit> MakeFinalPoseError(const UnitBuildContext& c) {
  return std::make_unique<FinalPoseErrorUnit>(c.name);
}

const config::UnitTypeRegistrar kFinalPoseError(
    {FinalPoseErrorUnit::kTypeName,
     "paper 2's final pose error (Table 1): the true and the beacons' pose against the work "
     "pose once the robot stopped, and the beacons' own error",
     "",
     {},
     MakeFinalPoseError});

}  // namespace
}  // namespace linesim::evaluation
