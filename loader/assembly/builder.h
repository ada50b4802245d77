#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "loader/config_names.h"
#include "loader/system_spec.h"

/// The assembly of a robot scenario into a system description: a builder the
/// concerns add units and connections to, and the names of the units the
/// expansion makes (recording, metrics, plots and --set refer to these).
namespace linesim::loader::assembly {

inline constexpr const char* kBelt = "belt";
inline constexpr const char* kChassis = "chassis";
inline constexpr const char* kMotors = "motors";
inline constexpr const char* kWheelController = "wheel_controller";
inline constexpr const char* kPathFollower = "path_follower";
inline constexpr const char* kDeviation = "deviation";
/// The drives' peak current over the path's last metres.
inline constexpr const char* kEndCurrent = "end_current";
inline constexpr const char* kClearance = "clearance";
/// A fleet's robot's distance from the other robots (loader/robot_scenario.cc).
inline constexpr const char* kRobotClearance = "robot_clearance";
/// A fleet's robots' bodies in one array (units/world), the scene's: unscoped.
inline constexpr const char* kMovingBodies = "moving_bodies";
inline constexpr const char* kFlowError = "flow_error";
/// The estimators (units/estimation) and the localization's evaluation.
inline constexpr const char* kSurfaceEstimator = "surface_estimator";
inline constexpr const char* kLaserLocalization = "laser_localization";
inline constexpr const char* kOdometry = "odometry";
inline constexpr const char* kPoseFusion = "pose_fusion";
inline constexpr const char* kLocalizationError = "localization_error";
inline constexpr const char* kPerfectMatch = "perfect_match";
inline constexpr const char* kBeacons = "beacons";
inline constexpr const char* kFinalPose = "final_pose";
/// The Rob@Work 3 control cycle (IPA cob_control configuration): the
/// controllers' period unless control.period_s says otherwise.
inline constexpr cosim::TimeNs kControlPeriod = cosim::kNsPerSecond / 50;
/// Paper 1's encoder wheel on the belt, off the robot.
inline constexpr const char* kBeltGroundTruth = "belt_ground_truth";

/// A variable of a unit the assembly adds, or one element of an array
/// variable: what a role (Signals) holds and a connection, a recorded column
/// or a metric names.
struct Port {
  std::string unit, variable;
  std::optional<std::size_t> element;

  /// "unit.variable" or "unit.variable[k]", as the description writes it.
  std::string Name() const;
  bool empty() const { return unit.empty(); }
  friend bool operator==(const Port&, const Port&) = default;
};

/// unit.variable.
Port Signal(const std::string& unit, const std::string& variable);
/// unit.variable[k].
Port Element(const std::string& unit, const std::string& variable, std::size_t k);

/// YAML for the structured parameters the assembly builds (a route's
/// segments, field sets): numbers as the shortest text that reads back to
/// them, so that `linesim inspect` shows 0.9 rather than 0.90000000000000002.
YAML::Node Num(double x);
YAML::Node List(const std::vector<double>& values);
/// Points [x, y] as a flow list of flow pairs (a path).
YAML::Node PointList(const std::vector<std::array<double, 2>>& points);
/// Integers as a parameter's typed list.
std::vector<std::int64_t> IntList(const std::vector<int>& values);

/// The system description under construction (loader/system_spec.h). Every
/// concern adds its units and connections here; what a unit's value was
/// derived from is recorded so that a problem found in the description is
/// reported at the robot-level key the user wrote.
class SystemBuilder {
 public:
  SystemBuilder(const YAML::Node& root, YamlReader& reader) : root_(root), r_(reader) {}

  const YAML::Node& root() const { return root_; }
  YamlReader& reader() { return r_; }

  /// Adds (or returns) unit `name` of `type`.
  UnitSpec& Unit(const std::string& name, const std::string& type);
  bool HasUnit(const std::string& name) const;
  /// Unit `name`'s parameters (the unit is added, typeless, when absent).
  Parameters& Params(const std::string& name);
  void SetStep(const std::string& name, cosim::TimeNs step);
  void Connect(const Port& from, const Port& to);
  /// Adds the metric {name, of, reduce}.
  void Metric(const std::string& name, const Port& of, cosim::Reduction reduce);

  /// Records that the description's `expanded` path holds a value derived
  /// from the robot-level key `key` of `parent` (at `path`).
  void Derived(const std::string& expanded, const YAML::Node& parent, const std::string& path,
               const std::string& key);
  void Origin(const std::string& expanded, loader::Origin origin);
  /// Merges the robot description's settings for `unit` (its section
  /// `section` of `file`) into the unit's parameters; a problem found in one
  /// of them is reported in that file, at its line and key.
  void MergeSettings(const std::string& unit, const YAML::Node& settings, const std::string& file,
                     const std::string& section);
  /// Reports, as missing from that section of the robot file, every
  /// parameter of `unit`'s type with no default that neither the assembly
  /// nor the section sets.
  void RequireParameters(const std::string& unit, const YAML::Node& settings,
                         const std::string& file, const std::string& section);
  /// A map section of the robot scenario (empty when absent), its keys
  /// checked.
  YAML::Node Section(const YAML::Node& parent, const std::string& path, const std::string& key,
                     const std::vector<std::string>& keys);

  /// The master step as the system loader reads it (its default if absent
  /// or bad: the system loader reports a bad one at master.step_s).
  cosim::TimeNs MasterStep() const;
  /// The controllers' period (control.period_s, 20 ms by default), as
  /// AddControl reads it and reports its problems.
  cosim::TimeNs ControlPeriod() const;

  SystemSpec& spec() { return spec_; }

 private:
  const YAML::Node& root_;
  YamlReader& r_;
  SystemSpec spec_;
};

}  // namespace linesim::loader::assembly
