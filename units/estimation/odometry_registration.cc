// Registers the estimation family's wheel odometry and pose fusion unit
// types (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/estimation/pose_fusion_unit.h"
#include "units/estimation/wheel_odometry_unit.h"

namespace linesim::estimation {
namespace {

using config::UnitBuildContext;

std::unique_ptr<cosim::Unit> MakeWheelOdometry(const UnitBuildContext& c) {
  const std::size_t issues = c.reader.issues().size();
  const std::string kind =
      c.reader.String(c.parameters, c.path, "kind", "swerve", {"swerve", "differential"});
  const auto wheels = c.reader.Integer(c.parameters, c.path, "wheels", 4, 2, 16);
  if (c.reader.issues().size() != issues) return nullptr;  // the reader reported them
  return std::make_unique<WheelOdometryUnit>(c.name,
                                             kind == "differential"
                                                 ? WheelOdometryUnit::Kind::kDifferential
                                                 : WheelOdometryUnit::Kind::kSwerve,
                                             static_cast<int>(wheels));
}

std::unique_ptr<cosim::Unit> MakePoseFusion(const UnitBuildContext& c) {
  return std::make_unique<PoseFusionUnit>(c.name);
}

const config::UnitTypeRegistrar kWheelOdometry(
    {WheelOdometryUnit::kTypeName,
     "wheel odometry from encoder counts (swerve: least squares over the steered wheels; "
     "differential: effective track), paper 1 Eq. 3 rectification by the surface velocity "
     "under each wheel, dead reckoning along exact arcs; robot-specific parameters have no "
     "default",
     "",
     {{"kind",
       "swerve (2W channels: W steering, then W drive joints; default) or "
       "differential (2 channels: left and right drive motor)"},
      {"wheels", "number of wheels W (default 4, at least 2)"}},
     MakeWheelOdometry});

const config::UnitTypeRegistrar kPoseFusion(
    {PoseFusionUnit::kTypeName,
     "EKF of pose and a map-frame velocity offset of the odometry: predicts with the odometry "
     "(or the IMU's yaw rate), corrects with delayed laser matches at their own time, "
     "Mahalanobis gate, timeout to odometry only",
     "",
     {},
     MakePoseFusion});

}  // namespace
}  // namespace linesim::estimation
