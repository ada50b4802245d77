// The surface velocity from the laser localization, the encoders and the
// PX4Flow in one filter per belt (paper 1 Sec. VI-D's future work).
// A provider (loader/assembly/providers.h): it registers itself.
// filter. See loader/assembly/providers.h.
#include "loader/assembly/providers.h"

namespace linesim::loader::assembly {
namespace {

// Paper 1's future work (Sec. VI-D): each belt's velocity from the
// laser localization's velocity minus the wheel encoders, and the
// PX4Flow with the encoders as the robot's motion, in one Kalman
// filter per belt (units/estimation/surface_fusion_unit.h).
void SurfaceFusedFlow(SystemBuilder& b, const ProviderContext& c, Signals& s) {
  constexpr const char* kFusion = "surface_fusion";
  const bool flows_on = Require(b, c, s, "px4flow", "fused_flow");
  const bool encoders_on = Require(b, c, s, "wheel_encoder", "fused_flow");
  if (!flows_on || !encoders_on) return;
  if (!b.HasUnit(kLaserLocalization)) {
    b.reader().Error(c.at, c.path,
                     "'fused_flow' needs the laser localization's velocity: "
                     "localization.source laser or fused");
    return;
  }
  const auto flows = Mounts(s, "px4flow");
  const models::RobotDescription& robot = c.file.robot;
  b.Unit(kFusion, "surface_fusion");
  Parameters& p = b.Params(kFusion);
  ConnectFlowSensors(b, flows, robot, kFusion, p);
  SetWheelPositions(p, robot);
  if (s.odometry.empty()) AddOdometry(b, c, s);
  b.Connect(Signal(s.odometry, "wheel_velocity"), Signal(kFusion, "wheel_velocity"));
  b.Connect(Signal(kLaserLocalization, "position"), Signal(kFusion, "laser_position"));
  b.Connect(Signal(kLaserLocalization, "match_time"), Signal(kFusion, "match_time"));
  b.Connect(Signal(kLaserLocalization, "match_count"), Signal(kFusion, "match_count"));
  b.Connect(s.position, Signal(kFusion, "position"));
  b.Connect(s.yaw, Signal(kFusion, "yaw"));
  SetStep(b, kFusion);
  // The accelerometer feels the belt carry the robot at once
  // (surface_fusion_unit.h): the first IMU, at its rate.
  if (const auto imus = Mounts(s, "imu"); !imus.empty()) {
    const std::string& imu = imus.front()->name;
    p["imu"] = true;
    p["imu_yaw"] = imus.front()->yaw_rad;
    b.Connect(Signal(imu, "linear_acceleration"), Signal(kFusion, "imu_acceleration"));
    const UnitSpec* imu_unit = b.spec().FindUnit(imu);
    if (imu_unit && imu_unit->step) b.SetStep(kFusion, *imu_unit->step);
  }
  s.surface_velocity = Signal(kFusion, "wheel_surface_velocity");
  s.surface_estimate = Signal(kFusion, "sensor_surface_velocity");
  s.recorded.push_back(Signal(kFusion, "belt_velocity"));
  s.recorded.push_back(Signal(kFusion, "switch_count"));
}

const ProviderRegistrar kSurfaceFusedFlow(ProviderRole::kSurfaceVelocity, "fused_flow",
                                          SurfaceFusedFlow);

}  // namespace
}  // namespace linesim::loader::assembly
