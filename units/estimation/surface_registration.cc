// Registers the surface_velocity_estimator of the estimation family (see
// config/unit_registry.h).
#include <string>

#include "config/unit_registry.h"
#include "units/estimation/surface_velocity_estimator.h"

namespace linesim::estimation {
namespace {

using config::UnitBuildContext;

// The per-sensor and per-wheel lists must hold one value per sensor or
// wheel: a list of another length is reported here, at its key, with the
// structural count it must match (a single number sets every element).
bool CheckListSize(const UnitBuildContext& c, const std::string& key, std::int64_t count,
                   const std::string& structural) {
  if (!c.parameters.IsMap()) return true;
  const YAML::Node list = config::Child(c.parameters, key);
  if (!list.IsDefined() || !list.IsSequence()) return true;
  if (static_cast<std::int64_t>(list.size()) == count) return true;
  c.reader.Error(list, config::JoinPath(c.path, key),
                 "has " + std::to_string(list.size()) + " values, expected one per " +
                     structural.substr(0, structural.size() - 1) + " (" + structural + ": " +
                     std::to_string(count) + ")");
  return false;
}

std::unique_ptr<cosim::Unit> MakeSurfaceVelocityEstimator(const UnitBuildContext& c) {
  // `linesim inspect TYPE` builds one without parameters: the Rob@Work 3's
  // four corner sensors and four wheels.
  const bool inspect = !c.parameters.IsDefined() || c.parameters.IsNull();
  const auto fallback = inspect ? std::optional<std::int64_t>(4) : std::nullopt;
  const std::size_t issues_before = c.reader.issues().size();
  const std::int64_t sensors = c.reader.Integer(c.parameters, c.path, "sensors", fallback, 1, 64);
  const std::int64_t wheels = c.reader.Integer(c.parameters, c.path, "wheels", fallback, 1, 64);
  if (c.reader.issues().size() != issues_before) return nullptr;
  bool ok = true;
  for (const char* key : {"sensor_x", "sensor_y", "sensor_yaw"}) {
    ok = CheckListSize(c, key, sensors, "sensors") && ok;
  }
  for (const char* key : {"wheel_x", "wheel_y"}) {
    ok = CheckListSize(c, key, wheels, "wheels") && ok;
  }
  if (!ok) return nullptr;
  return std::make_unique<SurfaceVelocityEstimator>(c.name, static_cast<int>(sensors),
                                                    static_cast<int>(wheels), c.scene);
}

const config::UnitTypeRegistrar kSurfaceVelocityEstimator(
    {SurfaceVelocityEstimator::kTypeName,
     "paper 1 Sec. IV-A: the absolute surface velocity under each PX4Flow (Eq. 2), a "
     "steady-state Kalman filter per sensor, and per wheel the velocity of the belt the map "
     "puts it over (mean of the sensors over that belt), with hold and staleness fallbacks",
     "",
     {{"sensors", "number of PX4Flow sensors N (>= 1): the size of the per-sensor lists"},
      {"wheels", "number of wheels W (>= 1): the size of the per-wheel lists"}},
     MakeSurfaceVelocityEstimator});

}  // namespace
}  // namespace linesim::estimation
