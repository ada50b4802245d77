// The surface velocity from the PX4Flow (paper 1 Sec. IV-A).
// A provider (loader/assembly/providers.h): it registers itself.
#include <optional>

#include "loader/assembly/providers.h"

namespace linesim::loader::assembly {
namespace {

// Paper 1 Sec. IV-A: the PX4Flow at the corners, made absolute with
// the localization's velocity (Eq. 2), filtered by the steady-state
// Kalman filter, assigned to the wheels the line map puts on a belt.
void SurfacePx4flow(SystemBuilder& b, const ProviderContext& c, Signals& s) {
  if (!Require(b, c, s, "px4flow", "px4flow")) return;
  const auto flows = Mounts(s, "px4flow");
  const models::RobotDescription& robot = c.file.robot;
  b.Unit(kSurfaceEstimator, "surface_velocity_estimator");
  Parameters& p = b.Params(kSurfaceEstimator);
  ConnectFlowSensors(b, flows, robot, kSurfaceEstimator, p);
  // The filter's sample is the sensors' message period, when their
  // settings or model file say (else both units' default, 10 Hz).
  std::optional<double> rate;
  for (const auto* m : flows) {
    const auto r = DeviceNumbers(b, c, *m).Get("publish_rate");
    if (!r) continue;
    if (rate && *rate != *r) {
      b.reader().Error(c.at, c.path,
                       "the PX4Flow publish at different rates (" + Num(*rate).Scalar() + " and " +
                           Num(*r).Scalar() +
                           " Hz): the surface estimator needs one message period");
    }
    rate = r;
  }
  if (rate && *rate > 0.0) p["sample_period"] = 1.0 / *rate;
  SetWheelPositions(p, robot);
  // The encoders' check of each message (a dark image passes the
  // firmware's quality test with noise matches): with the wheel
  // encoders on, their wheel velocities, and a gate of 3 measurement
  // sigmas (0.09 m/s with paper 1's 3 cm/s). The wheels' encoder
  // velocities: those over the sensor's surface say how the robot
  // moves relative to it.
  if (s.odometry.empty() && !Mounts(s, "wheel_encoder").empty()) AddOdometry(b, c, s);
  if (!s.odometry.empty()) {
    b.Connect(Signal(s.odometry, "wheel_velocity"),
              Signal(kSurfaceEstimator, "odometry_wheel_velocity"));
    p["odometry_gate"] = 3;
    s.recorded.push_back(Signal(kSurfaceEstimator, "implausible_count"));
  }
  b.Connect(s.position, Signal(kSurfaceEstimator, "position"));
  b.Connect(s.yaw, Signal(kSurfaceEstimator, "yaw"));
  b.Connect(s.velocity, Signal(kSurfaceEstimator, "velocity"));
  b.Connect(s.yaw_rate, Signal(kSurfaceEstimator, "yaw_rate"));
  SetStep(b, kSurfaceEstimator);
  s.surface_velocity = Signal(kSurfaceEstimator, "wheel_surface_velocity");
  s.surface_estimate = Signal(kSurfaceEstimator, "filtered_surface_velocity");
  s.recorded.push_back(Signal(kSurfaceEstimator, "wheel_source"));
  s.recorded.push_back(Signal(kSurfaceEstimator, "sensor_status"));
  s.recorded.push_back(Signal(kSurfaceEstimator, "switch_count"));
}

const ProviderRegistrar kSurfacePx4flow(ProviderRole::kSurfaceVelocity, "px4flow", SurfacePx4flow);

}  // namespace
}  // namespace linesim::loader::assembly
