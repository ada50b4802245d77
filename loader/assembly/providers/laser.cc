// The pose from hector_mapping alone (paper 1 Sec. IV-B).
// A provider (loader/assembly/providers.h): it registers itself.
#include "loader/assembly/providers.h"

namespace linesim::loader::assembly {
namespace {

// hector_mapping alone: the pose of the last match, its velocity
// from successive matches.
void LocalizationLaser(SystemBuilder& b, const ProviderContext& c, Signals& s) {
  if (!Require(b, c, s, "laser_scanner", "laser")) return;
  AddLaserLocalization(b, c, s);
  // hector alone starts each match from the last pose; with the
  // wheel encoders on, their odometry is wired for the option
  // motion_prediction: odometry (off unless the scenario sets it).
  if (!Mounts(s, "wheel_encoder").empty()) {
    AddOdometry(b, c, s);
    ConnectOdometryToMatcher(b);
  }
  s.position = Signal(kLaserLocalization, "position");
  s.yaw = Signal(kLaserLocalization, "yaw");
  s.velocity = Signal(kLaserLocalization, "velocity");
  s.yaw_rate = Signal(kLaserLocalization, "yaw_rate");
}

const ProviderRegistrar kLocalizationLaser(ProviderRole::kLocalization, "laser", LocalizationLaser);

}  // namespace
}  // namespace linesim::loader::assembly
