// The pose from the odometry and hector's scan matches in an EKF.
// A provider (loader/assembly/providers.h): it registers itself.
#include "loader/assembly/providers.h"

namespace linesim::loader::assembly {
namespace {

// Odometry between scans, scan matches as corrections (an EKF).
void LocalizationFused(SystemBuilder& b, const ProviderContext& c, Signals& s) {
  const bool lasers = Require(b, c, s, "laser_scanner", "fused");
  const bool encoders = Require(b, c, s, "wheel_encoder", "fused");
  if (!lasers || !encoders) return;
  AddLaserLocalization(b, c, s);
  AddOdometry(b, c, s);
  // The matcher starts each match from its last pose moved by the
  // odometry since then (hector alone has no motion model): through
  // a blackout of both lasers it follows the odometry, so the first
  // scans after it are within the matcher's reach.
  b.Params(kLaserLocalization)["motion_prediction"] = "odometry";
  ConnectOdometryToMatcher(b);
  AddPoseFusion(b, c, s, kLaserLocalization);
}

const ProviderRegistrar kLocalizationFused(ProviderRole::kLocalization, "fused", LocalizationFused);

}  // namespace
}  // namespace linesim::loader::assembly
