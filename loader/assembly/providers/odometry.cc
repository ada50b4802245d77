// The pose from dead reckoning alone.
// A provider (loader/assembly/providers.h): it registers itself.
#include "loader/assembly/providers.h"

namespace linesim::loader::assembly {
namespace {

// Dead reckoning alone (rectified by Eq. 3).
void LocalizationOdometry(SystemBuilder& b, const ProviderContext& c, Signals& s) {
  if (!Require(b, c, s, "wheel_encoder", "odometry")) return;
  AddOdometry(b, c, s);
  s.position = Signal(kOdometry, "position");
  s.yaw = Signal(kOdometry, "yaw");
  s.velocity = Signal(kOdometry, "velocity");
  s.yaw_rate = Signal(kOdometry, "yaw_rate");
}

const ProviderRegistrar kLocalizationOdometry(ProviderRole::kLocalization, "odometry",
                                              LocalizationOdometry);

}  // namespace
}  // namespace linesim::loader::assembly
