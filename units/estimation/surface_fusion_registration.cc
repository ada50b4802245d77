// Registers the surface_fusion unit of the estimation family (see
// config/unit_registry.h).
#include <string>

#include "config/unit_registry.h"
#include "units/estimation/surface_fusion_unit.h"

namespace linesim::estimation {
namespace {

using config::UnitBuildContext;

// A per-sensor or per-wheel list of another length is reported at its key
// with the structural count it must match.
bool CheckListSize(const UnitBuildContext& c, const std::string& key, std::int64_t count,
                   const std::string& what) {
  if (!c.parameters.IsMap()) return true;
  const YAML::Node list = config::Child(c.parameters, key);
  if (!list.IsDefined() || !list.IsSequence()) return true;
  if (static_cast<std::int64_t>(list.size()) == count) return true;
  c.reader.Error(list, config::JoinPath(c.path, key),
                 "has " + std::to_string(list.size()) + " values, expected one per " + what +
                     " (" + what + "s: " + std::to_string(count) + ")");
  return false;
}

std::unique_ptr<cosim::Unit> MakeSurfaceFusion(const UnitBuildContext& c) {
  // `linesim inspect TYPE` builds one without parameters: the Rob@Work 3's
  // four corner sensors and four wheels.
  const bool inspect = !c.parameters.IsDefined() || c.parameters.IsNull();
  const auto fallback = inspect ? std::optional<std::int64_t>(4) : std::nullopt;
  const std::size_t issues_before = c.reader.issues().size();
  const std::int64_t sensors = c.reader.Integer(c.parameters, c.path, "sensors", fallback, 0, 64);
  const std::int64_t wheels = c.reader.Integer(c.parameters, c.path, "wheels", fallback, 2, 64);
  const bool imu = c.reader.Boolean(c.parameters, c.path, "imu", false);
  if (c.reader.issues().size() != issues_before) return nullptr;
  bool ok = true;
  for (const char* key : {"sensor_x", "sensor_y", "sensor_yaw"}) {
    ok = CheckListSize(c, key, sensors, "sensor") && ok;
  }
  for (const char* key : {"wheel_x", "wheel_y"}) ok = CheckListSize(c, key, wheels, "wheel") && ok;
  if (!ok) return nullptr;
  return std::make_unique<SurfaceFusionUnit>(c.name, static_cast<int>(sensors),
                                             static_cast<int>(wheels), c.scene, imu);
}

const config::UnitTypeRegistrar kSurfaceFusion(
    {SurfaceFusionUnit::kTypeName,
     "paper 1's future work (Sec. VI-D): each scene belt's velocity by a Kalman filter of the "
     "laser localization's velocity minus the wheel encoders (per wheel over the belt) and the "
     "PX4Flow messages with the encoders as the robot's motion (and, with imu, the "
     "accelerometer's), with switch detection; per "
     "wheel the estimate of the belt under it",
     "",
     {{"sensors", "number of PX4Flow sensors N (>= 0): the size of the per-sensor lists"},
      {"wheels", "number of wheels W (>= 2): the size of the per-wheel lists"},
      {"imu", "true: the IMU's acceleration is fused too (input imu_acceleration, state b and "
              "the accelerometer bias; default false)"}},
     MakeSurfaceFusion});

}  // namespace
}  // namespace linesim::estimation
