// No surface velocity (paper 1's nominal system).
// A provider (loader/assembly/providers.h): it registers itself.
#include "loader/assembly/providers.h"

namespace linesim::loader::assembly {
namespace {

// Paper 1's nominal system (Fig. 6): no knowledge of the surface. The
// controllers and the odometry's rectification (Eq. 3) get none, as
// if every floor were still; AddSensing holds the pose fusion's
// surface offset at 0.
void SurfaceNone(SystemBuilder&, const ProviderContext&, Signals&) {}

const ProviderRegistrar kSurfaceNone(ProviderRole::kSurfaceVelocity, "none", SurfaceNone);

}  // namespace
}  // namespace linesim::loader::assembly
