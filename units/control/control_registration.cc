// Registers the control family's unit types (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/control/diff_drive_controller_unit.h"
#include "units/control/path_follower_unit.h"
#include "units/control/wheel_controller_unit.h"

namespace linesim::control {
namespace {

using config::ReadPoints;
using config::UnitBuildContext;

std::unique_ptr<cosim::Unit> MakeWheelController(const UnitBuildContext& c) {
  const auto wheels = c.reader.Integer(c.parameters, c.path, "wheel_count", 4, 1, 16);
  return std::make_unique<control::WheelControllerUnit>(c.name, static_cast<int>(wheels));
}

std::unique_ptr<cosim::Unit> MakeDiffDriveController(const UnitBuildContext& c) {
  return std::make_unique<control::DiffDriveControllerUnit>(c.name);
}

std::unique_ptr<cosim::Unit> MakePathFollower(const UnitBuildContext& c) {
  const std::string mode = c.reader.String(c.parameters, c.path, "mode", "path", {"path", "hold"});
  const std::string base = c.reader.String(c.parameters, c.path, "base", "omnidirectional",
                                           {"omnidirectional", "differential"});
  std::vector<std::array<double, 2>> waypoints = ReadPoints(c, "waypoints", 1);
  if (!c.parameters.IsDefined() || c.parameters.IsNull()) waypoints = {{0.0, 0.0}, {1.0, 0.0}};
  return std::make_unique<control::PathFollowerUnit>(
      c.name,
      mode == "hold" ? control::PathFollowerUnit::Mode::kHold
                     : control::PathFollowerUnit::Mode::kPath,
      std::move(waypoints),
      base == "differential" ? control::PathFollowerUnit::Base::kDifferential
                             : control::PathFollowerUnit::Base::kOmnidirectional);
}

const config::UnitTypeRegistrar kWheelController(
    {control::WheelControllerUnit::kTypeName,
     "swerve wheel controller (Rob@Work 3, paper 1 Sec. III): Eq. 1, Algorithm 1 (surface "
     "compensation), flip rule, steering and drive PD to motor voltages; robot-specific "
     "parameters have no default",
     "",
     {{"wheel_count", "number of steer+drive modules (default 4)"}},
     MakeWheelController});

const config::UnitTypeRegistrar kDiffDriveController(
    {control::DiffDriveControllerUnit::kTypeName,
     "differential / skid-steer drive controller: body command to left and right wheel rates "
     "with an effective track, PI with back-EMF and acceleration feedforward to the 2 drive "
     "motor voltages; every parameter robot-specific (no default)",
     "",
     {},
     MakeDiffDriveController});

const config::UnitTypeRegistrar kPathFollower(
    {control::PathFollowerUnit::kTypeName,
     "follows a polyline at a cruise speed, or holds a point; outputs a body velocity and yaw "
     "rate command (omnidirectional: keeping a heading; differential: steering the heading "
     "onto the path, turning in place at sharp corners)",
     "",
     {{"mode", "path (follow the waypoints, stop at the last) or hold (hold the first)"},
      {"base",
       "omnidirectional (default: translates keeping `heading`) or differential "
       "(drives along its heading only)"},
      {"waypoints", "list of points [x, y] (m) in the map frame"}},
     MakePathFollower});

}  // namespace
}  // namespace linesim::control
