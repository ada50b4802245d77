// Registers the evaluation family's unit types (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/evaluation/clearance.h"
#include "units/evaluation/end_peak.h"
#include "units/evaluation/path_deviation.h"
#include "units/evaluation/pose_error.h"
#include "units/evaluation/robot_clearance.h"
#include "units/evaluation/surface_velocity_error.h"

namespace linesim::evaluation {
namespace {

using config::ReadPoints;
using config::UnitBuildContext;

std::unique_ptr<cosim::Unit> MakePathDeviation(const UnitBuildContext& c) {
  return std::make_unique<evaluation::PathDeviationUnit>(c.name, ReadPoints(c, "path", 1));
}

std::unique_ptr<cosim::Unit> MakeRobotClearance(const UnitBuildContext& c) {
  const auto bodies = c.reader.Integer(c.parameters, c.path, "bodies", 2, 2, 10000);
  return std::make_unique<RobotClearanceUnit>(c.name, static_cast<int>(bodies));
}

const config::UnitTypeRegistrar kRobotClearance(
    {RobotClearanceUnit::kTypeName,
     "distance of a robot's body from the other robots' bodies in a fleet, and robot-robot "
     "contacts counted as collisions (per pair)",
     "",
     {{"bodies", "number of robots in the fleet, this one included (the input `bodies` holds 10 "
                 "numbers each; default 2)"}},
     MakeRobotClearance});

const config::UnitTypeRegistrar kPathDeviation(
    {evaluation::PathDeviationUnit::kTypeName,
     "ground-truth distance of the robot centre from its desired path or held point",
     "",
     {{"path", "list of points [x, y] (m): a polyline, or one point for a hold"}},
     MakePathDeviation});

std::unique_ptr<cosim::Unit> MakeEndPeak(const UnitBuildContext& c) {
  const auto count = c.reader.Integer(c.parameters, c.path, "count", 1, 1, 1024);
  return std::make_unique<EndPeakUnit>(c.name, static_cast<int>(count));
}

const config::UnitTypeRegistrar kEndPeak(
    {EndPeakUnit::kTypeName,
     "largest absolute value of a set of signals (a robot's drive currents) over the last "
     "`window` metres of its path",
     "",
     {{"count", "number of signals in the input `values` (default 1)"}},
     MakeEndPeak});

std::unique_ptr<cosim::Unit> MakeSurfaceVelocityError(const UnitBuildContext& c) {
  const auto sensors = c.reader.Integer(c.parameters, c.path, "sensors", 1, 1, 64);
  if (c.scene.belts.empty()) {
    c.reader.Error(c.parameters, c.path,
                   "the scene has no belts: the unit compares optic flow with a belt's "
                   "ground-truth speed (scene.belts)");
    return nullptr;
  }
  const auto belt = c.reader.Integer(c.parameters, c.path, "belt", 0, 0,
                                     static_cast<std::int64_t>(c.scene.belts.size()) - 1);
  const bool estimated = c.reader.Boolean(c.parameters, c.path, "estimated", false);
  return std::make_unique<evaluation::SurfaceVelocityErrorUnit>(
      c.name, static_cast<int>(sensors), c.scene.belts[static_cast<std::size_t>(belt)],
      estimated);
}

const config::UnitTypeRegistrar kSurfaceVelocityError(
    {evaluation::SurfaceVelocityErrorUnit::kTypeName,
     "raw optic-flow surface velocity (paper 1 Eq. 2 with the true robot motion) against a "
     "belt's ground-truth speed, for the sensors over that belt; running RMSE",
     "",
     {{"sensors", "number of sensors compared (default 1)"},
      {"belt", "index of the scene belt the reference measures (default 0)"},
      {"estimated", "also compare an estimator's absolute velocity per sensor (default false)"}},
     MakeSurfaceVelocityError});

std::unique_ptr<cosim::Unit> MakePoseError(const UnitBuildContext& c) {
  return std::make_unique<evaluation::PoseErrorUnit>(c.name);
}

const config::UnitTypeRegistrar kPoseError(
    {evaluation::PoseErrorUnit::kTypeName,
     "a localization's estimate against the true pose: position and yaw error, their maxima and "
     "root mean squares",
     "",
     {},
     MakePoseError});

std::unique_ptr<cosim::Unit> MakeClearance(const UnitBuildContext& c) {
  for (std::size_t k = 0; k < c.scene.carried.size(); ++k) {
    const int belt = c.scene.carried[k].belt;
    if (belt < 0 || static_cast<std::size_t>(belt) >= c.scene.belts.size()) {
      c.reader.Error(c.parameters, c.path,
                     "scene carried object '" + c.scene.carried[k].name + "' is on belt " +
                         std::to_string(belt) + ", not one of the scene's " +
                         std::to_string(c.scene.belts.size()) + " belts");
      return nullptr;
    }
  }
  return std::make_unique<evaluation::ClearanceUnit>(c.name, c.scene);
}

const config::UnitTypeRegistrar kClearance(
    {evaluation::ClearanceUnit::kTypeName,
     "ground-truth minimum distance of the robot's body box from the scene's obstacles and "
     "carried objects (FCL), and its collisions",
     "",
     {},
     MakeClearance});

}  // namespace
}  // namespace linesim::evaluation
