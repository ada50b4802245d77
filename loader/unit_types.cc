#include "loader/unit_types.h"

#include "cosim/closest_names.h"
#include "units/belt/belt_unit.h"
#include "units/chassis/chassis_unit.h"
#include "units/control/diff_drive_controller_unit.h"
#include "units/control/path_follower_unit.h"
#include "units/control/wheel_controller_unit.h"
#include "units/evaluation/path_deviation.h"
#include "units/motors/dc_motor_unit.h"
#include "units/sources/step_signal.h"

namespace linesim::loader {

namespace {

std::unique_ptr<cosim::Unit> MakeDcMotor(const UnitBuildContext& c) {
  const auto count = c.reader.Integer(c.parameters, c.path, "count", 1, 1, 64);
  const std::string mode =
      c.reader.String(c.parameters, c.path, "mode", "full", {"full", "current_only"});
  return std::make_unique<motors::DcMotorUnit>(
      c.name, static_cast<int>(count),
      mode == "full" ? motors::MotorMode::kFull : motors::MotorMode::kCurrentOnly);
}

std::unique_ptr<cosim::Unit> MakeStepSignal(const UnitBuildContext& c) {
  YamlReader& r = c.reader;
  const auto count = r.Integer(c.parameters, c.path, "count", 1, 1, 4096);
  const std::string unit = r.String(c.parameters, c.path, "unit", "1");
  std::vector<sources::StepSignalUnit::Step> steps;
  const YAML::Node& params = c.parameters;
  const YAML::Node list = Child(params, "steps");
  const std::string list_path = JoinPath(c.path, "steps");
  if (list.IsDefined() && !list.IsNull() && r.ExpectSequence(list, list_path)) {
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YAML::Node item = list[i];
      const std::string item_path = JoinPath(list_path, std::to_string(i));
      if (!r.ExpectMap(item, item_path)) continue;
      r.CheckKeys(item, item_path, {"time_s", "value"});
      sources::StepSignalUnit::Step step;
      step.time = r.Time(item, item_path, "time_s", std::nullopt, {0.0, 1e7});
      const YAML::Node value = Child(item, "value");
      const std::string value_path = JoinPath(item_path, "value");
      if (!value.IsDefined()) {
        r.Error(item, value_path, "missing required key");
      } else if (value.IsSequence()) {
        if (value.size() != static_cast<std::size_t>(count)) {
          r.Error(value, value_path,
                  "expected " + std::to_string(count) + " values (count), got " +
                      std::to_string(value.size()));
        }
        for (std::size_t k = 0; k < value.size(); ++k) {
          step.value.push_back(
              r.AsReal(value[k], JoinPath(value_path, std::to_string(k))).value_or(0.0));
        }
      } else {
        step.value.assign(static_cast<std::size_t>(count), r.AsReal(value, value_path).value_or(0));
      }
      step.value.resize(static_cast<std::size_t>(count), 0.0);
      steps.push_back(std::move(step));
    }
  }
  return std::make_unique<sources::StepSignalUnit>(c.name, static_cast<int>(count), unit,
                                                   std::move(steps));
}

// A list of points [x, y] at `key` (at least `min_points` of them).
std::vector<std::array<double, 2>> ReadPoints(const UnitBuildContext& c, const std::string& key,
                                              std::size_t min_points) {
  std::vector<std::array<double, 2>> points;
  const YAML::Node list = Child(c.parameters, key);
  const std::string path = JoinPath(c.path, key);
  if (!list.IsDefined() && (!c.parameters.IsDefined() || c.parameters.IsNull())) {
    return {{0.0, 0.0}};  // `linesim inspect TYPE`: no parameters at all
  }
  if (!list.IsDefined()) {
    c.reader.Error(c.parameters, path, "missing required key: a list of points [x, y] (m)");
    return points;
  }
  if (!c.reader.ExpectSequence(list, path)) return points;
  if (list.size() < min_points) {
    c.reader.Error(list, path, "expected at least " + std::to_string(min_points) + " points");
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (auto p = c.reader.AsPoint(list[i], JoinPath(path, std::to_string(i)))) {
      points.push_back(*p);
    }
  }
  return points;
}

// A per-wheel list of motor indices (`key`) of `wheels` entries, each in
// [min, wheels - 1]; `fallback` when the key is absent.
std::vector<int> ReadMotorList(const UnitBuildContext& c, const std::string& key, int wheels,
                               int min, std::vector<int> fallback) {
  const YAML::Node list = Child(c.parameters, key);
  const std::string path = JoinPath(c.path, key);
  if (!list.IsDefined() || list.IsNull()) return fallback;
  if (!c.reader.ExpectSequence(list, path)) return fallback;
  if (list.size() != static_cast<std::size_t>(wheels)) {
    c.reader.Error(list, path,
                   "expected one motor index per wheel (wheel_count " + std::to_string(wheels) +
                       "), got " + std::to_string(list.size()));
    return fallback;
  }
  std::vector<int> out;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const auto m = c.reader.AsInteger(list[k], JoinPath(path, std::to_string(k)), min, wheels - 1);
    if (!m) return fallback;
    out.push_back(static_cast<int>(*m));
  }
  return out;
}

std::unique_ptr<cosim::Unit> MakeChassis(const UnitBuildContext& c) {
  const int wheels =
      static_cast<int>(c.reader.Integer(c.parameters, c.path, "wheel_count", 4, 1, 16));
  // Without the keys: every wheel with its own steering and drive motor (a
  // generic swerve topology, not a robot).
  std::vector<int> own(static_cast<std::size_t>(wheels));
  for (int k = 0; k < wheels; ++k) own[static_cast<std::size_t>(k)] = k;
  const std::vector<int> steer = ReadMotorList(c, "steer_motor", wheels, -1, own);
  const std::vector<int> drive = ReadMotorList(c, "drive_motor", wheels, 0, own);
  if (const std::string bad = chassis::ChassisUnit::TopologyProblem(steer, drive); !bad.empty()) {
    c.reader.Error(c.parameters, c.path, bad);
    return nullptr;
  }
  return std::make_unique<chassis::ChassisUnit>(c.name, steer, drive, c.scene);
}

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

std::unique_ptr<cosim::Unit> MakePathDeviation(const UnitBuildContext& c) {
  return std::make_unique<evaluation::PathDeviationUnit>(c.name, ReadPoints(c, "path", 1));
}

std::unique_ptr<cosim::Unit> MakeBelt(const UnitBuildContext& c) {
  if (c.scene.belts.empty()) {
    c.reader.Error(c.parameters, c.path,
                   "the scene has no belts: a belt unit drives the belts of the scenario's scene "
                   "(scene.belts)");
    return nullptr;
  }
  return std::make_unique<belt::BeltUnit>(c.name, c.scene.belts, c.seed);
}

}  // namespace

const std::vector<UnitType>& UnitTypes() {
  static const std::vector<UnitType> types = {
      {motors::DcMotorUnit::kTypeName,
       "brushed DC motors with gearbox, integrated together in SUNDIALS CVODE (BDF)",
       "motors",
       {{"count", "number of motors in this unit (default 1)"},
        {"mode",
         "full: current and rotor speed are states, load torque is an input; current_only: "
         "the shaft speed is an input from the physics (default full)"},
        {"model", "model file from models/motors/ (name) or a path relative to the scenario"}},
       MakeDcMotor},
      {sources::StepSignalUnit::kTypeName,
       "piecewise-constant signal: commands and disturbances as steps in time",
       "",
       {{"count", "number of channels (default 1)"},
        {"unit", "unit of measure of the output, e.g. V or N.m (default 1)"},
        {"steps",
         "list of {time_s, value}: value (one number, or one per channel) from time_s on"}},
       MakeStepSignal},
      {belt::BeltUnit::kTypeName,
       "the belts of the scene (scene.belts): on/off schedule, finite acceleration, seeded "
       "+-variation of speed, travelled distance",
       "",
       {},
       MakeBelt},
      {chassis::ChassisUnit::kTypeName,
       "robot body, steered or fixed wheels (coupled per drive motor) and wheel/floor/belt "
       "contact in ODE, the body colliding with the scene's obstacles and carried objects",
       "chassis",
       {{"wheel_count", "number of wheels (default 4)"},
        {"steer_motor",
         "per wheel: index of its steering motor, -1 for a fixed wheel (default: wheel k on "
         "motor k)"},
        {"drive_motor",
         "per wheel: index of its drive motor; wheels with one index are coupled (default: "
         "wheel k on motor k)"},
        {"model", "model file from models/chassis/ (name) or a path relative to the scenario"}},
       MakeChassis},
      {control::WheelControllerUnit::kTypeName,
       "swerve wheel controller (Rob@Work 3, paper 1 Sec. III): Eq. 1, Algorithm 1 (surface "
       "compensation), flip rule, steering and drive PD to motor voltages; robot-specific "
       "parameters have no default",
       "",
       {{"wheel_count", "number of steer+drive modules (default 4)"}},
       MakeWheelController},
      {control::DiffDriveControllerUnit::kTypeName,
       "differential / skid-steer drive controller: body command to left and right wheel rates "
       "with an effective track, PI with back-EMF and acceleration feedforward to the 2 drive "
       "motor voltages; every parameter robot-specific (no default)",
       "",
       {},
       MakeDiffDriveController},
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
       MakePathFollower},
      {evaluation::PathDeviationUnit::kTypeName,
       "ground-truth distance of the robot centre from its desired path or held point",
       "",
       {{"path", "list of points [x, y] (m): a polyline, or one point for a hold"}},
       MakePathDeviation},
  };
  return types;
}

const UnitType* FindUnitType(std::string_view name) {
  for (const auto& t : UnitTypes()) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

std::vector<std::string> UnitTypeNames() {
  std::vector<std::string> names;
  for (const auto& t : UnitTypes()) names.push_back(t.name);
  return names;
}

std::string UnknownTypeMessage(const std::string& name) {
  return "unknown unit type '" + name + "'" + cosim::ClosestHint(name, UnitTypeNames()) +
         "; known types: " + JoinNames(UnitTypeNames());
}

}  // namespace linesim::loader
