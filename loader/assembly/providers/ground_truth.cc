// The ground truth as the controllers' surface velocity and pose: the
// belt unit's and the chassis's own outputs.
// A provider (loader/assembly/providers.h): it registers itself.
#include "loader/assembly/providers.h"

namespace linesim::loader::assembly {
namespace {

// The belt unit's true surface velocity under each wheel.
void SurfaceGroundTruth(SystemBuilder&, const ProviderContext&, Signals& s) {
  s.surface_velocity = s.true_surface_velocity;
}

const ProviderRegistrar kSurfaceGroundTruth(ProviderRole::kSurfaceVelocity, "ground_truth",
                                            SurfaceGroundTruth);

void LocalizationGroundTruth(SystemBuilder&, const ProviderContext&, Signals& s) {
  s.position = s.true_position;
  s.yaw = s.true_yaw;
  s.velocity = Signal(kChassis, "linear_velocity");
  s.yaw_rate = Signal(kChassis, "yaw_rate");
}

const ProviderRegistrar kLocalizationGroundTruth(ProviderRole::kLocalization, "ground_truth",
                                                 LocalizationGroundTruth);

}  // namespace
}  // namespace linesim::loader::assembly
