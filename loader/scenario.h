#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cosim/master.h"
#include "cosim/observers.h"
#include "cosim/system.h"
#include "loader/config_names.h"
#include "loader/overrides.h"
#include "loader/reference.h"
#include "loader/robot_scenario.h"
#include "models/scene.h"

namespace linesim::loader {

/// A scenario file read, checked and built into a system and a master,
/// ready to run. Everything that can be wrong with the file has been found
/// by the time this exists.
struct Scenario {
  std::string file;
  std::string name;
  std::string description;
  std::uint64_t seed = 1;
  double duration_s = 0;
  /// SHA-256 of the scenario as built: its YAML tree after the `--set`
  /// overrides (a robot scenario's expansion, which carries the robot file's
  /// values), for provenance.
  std::string sha256;
  std::vector<Override> overrides;
  /// The scene every unit that needs geometry builds from (`scene:`);
  /// models::OpenFloor() when the scenario names none.
  models::Scene scene = models::OpenFloor();

  std::unique_ptr<cosim::System> system;  // declared before master: outlives it
  std::unique_ptr<cosim::Master> master;

  std::vector<cosim::Probe> recorded;
  cosim::TimeNs record_interval = 0;
  std::vector<cosim::MetricSpec> metrics;
  /// Published figures repeated runs print beside their own (`reference:`).
  Reference reference;

  /// Robot scenarios only: the system description they expanded into, as a
  /// system-level file (ToYaml of loader/system_spec.h: what
  /// `linesim inspect` prints) and the geometry for the plots.
  std::optional<RobotInfo> robot;
  YAML::Node expanded;
};

/// Reads `file`, applies the `--set` overrides ("dotted.path=value"), checks
/// everything and builds the system. Throws ScenarioError listing every
/// problem (file, line, key path, bad value, what was expected).
Scenario LoadScenario(const std::string& file, const std::vector<std::string>& set_args = {});

/// The same, with units of the description given another type before it
/// is built (unit name -> type: a controller written in Python in place of
/// the shipped one). The unit keeps the parameters the new type declares
/// and its connections; a unit or type that does not exist is refused.
Scenario LoadScenario(const std::string& file, const std::vector<std::string>& set_args,
                      const std::map<std::string, std::string>& unit_types);

/// A scenario given as data rather than as a file (the Python package's
/// dicts): `tree` is what the file would hold, `label` names it where a
/// file's path would be ("<dict>": issues then carry the key path and no
/// line), and a relative path in it is relative to the current folder.
Scenario LoadScenarioTree(YAML::Node tree, const std::string& label,
                          const std::vector<std::string>& set_args = {},
                          const std::map<std::string, std::string>& unit_types = {});

/// `master.step_s` of the map `master` as every loader reads it: within
/// (0, 10] s, 1 ms when absent. A bad value is reported through `r` and
/// reads as 1 ms.
cosim::TimeNs ReadMasterStep(YamlReader& r, const YAML::Node& master);
/// master.retry: {enabled, min_step_s, shrink, grow} (cosim::RetryOptions);
/// the defaults (off) when absent.
cosim::RetryOptions ReadMasterRetry(YamlReader& r, const YAML::Node& master,
                                    cosim::TimeNs base_step);

/// A unit of a registered type with default structural parameters, named
/// after its type (for `linesim inspect TYPE`); throws ScenarioError with the
/// closest type names when the type is unknown.
std::unique_ptr<cosim::Unit> CreateDefaultUnit(const std::string& type);
/// The same for a type already looked up (FindUnitType).
std::unique_ptr<cosim::Unit> CreateDefaultUnit(const UnitType& type);

}  // namespace linesim::loader
