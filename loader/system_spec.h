#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "cosim/master.h"
#include "cosim/observers.h"
#include "loader/config_names.h"
#include "loader/reference.h"
#include "models/scene.h"

/// The typed system description: units with their parameters, connections,
/// recording and metrics, the master's settings and the scene, with where
/// each value came from. A system file is read into one (ReadSystemFile),
/// the robot assembly produces one (ExpandRobotScenario), the scenario
/// builder only consumes it (LoadScenario) and `linesim inspect` prints it
/// (ToYaml).
namespace linesim::loader {

/// A unit parameter's value. The assembly derives typed values; a file's
/// are kept as written (a YAML node with its line), for the unit's variable
/// table, which knows their type, to convert and refuse.
class ParameterValue {
 public:
  using Points = std::vector<std::array<double, 2>>;
  using Variant = std::variant<YAML::Node, double, std::int64_t, bool, std::string,
                               std::vector<double>, std::vector<std::int64_t>, Points>;

  ParameterValue() = default;
  ParameterValue(double x) : value_(x) {}
  ParameterValue(int x) : value_(static_cast<std::int64_t>(x)) {}
  ParameterValue(std::int64_t x) : value_(x) {}
  ParameterValue(std::size_t x) : value_(static_cast<std::int64_t>(x)) {}
  ParameterValue(bool x) : value_(x) {}
  ParameterValue(std::string x) : value_(std::move(x)) {}
  ParameterValue(const char* x) : value_(std::string(x)) {}
  ParameterValue(std::vector<double> x) : value_(std::move(x)) {}
  ParameterValue(std::vector<std::int64_t> x) : value_(std::move(x)) {}
  ParameterValue(Points x) : value_(std::move(x)) {}
  /// As a file wrote it, or a structured value the assembly made (a list
  /// of maps): explicit, so that a number is never passed as text.
  explicit ParameterValue(YAML::Node x) : value_(std::move(x)) {}

  const Variant& value() const { return value_; }
  /// As written in a file (nullptr for a typed value).
  const YAML::Node* written() const { return std::get_if<YAML::Node>(&value_); }
  /// The number it holds (a typed number, or a written one that reads as
  /// one); nullopt otherwise.
  std::optional<double> Number() const;
  /// As YAML: numbers as the shortest text that reads back to them, so that
  /// `linesim inspect` shows 0.9 rather than 0.90000000000000002.
  YAML::Node ToYaml() const;

 private:
  Variant value_;
};

/// A unit's parameters in the order they were set.
class Parameters {
 public:
  /// The value of `key`, added (empty) when absent.
  ParameterValue& operator[](const std::string& key);
  const ParameterValue* Find(const std::string& key) const;
  bool Has(const std::string& key) const { return Find(key) != nullptr; }
  bool empty() const { return items_.empty(); }
  auto begin() const { return items_.begin(); }
  auto end() const { return items_.end(); }
  /// As a YAML map (undefined when empty: a unit given no parameters).
  YAML::Node ToYaml() const;

 private:
  std::vector<std::pair<std::string, ParameterValue>> items_;
};

struct UnitSpec {
  std::string name, type;
  /// Its step (0: the master step); nullopt when none is given.
  std::optional<cosim::TimeNs> step;
  Parameters parameters;
  /// Where a file wrote it (its map), for errors; null for the assembly's.
  YAML::Node node;
};

struct ConnectionSpec {
  std::string from, to;
  YAML::Node node;  // as above
};

/// Text a file wrote (a recording pattern) with its node, for errors.
struct WrittenText {
  std::string text;
  YAML::Node node;
};

struct RecordingSpec {
  /// "unit.variable", "unit.variable[i]", "unit.*"; nullopt (no list
  /// given): every output of every unit.
  std::optional<std::vector<WrittenText>> variables;
  /// nullopt: every master step.
  std::optional<cosim::TimeNs> interval;
};

struct MetricDefinition {
  std::string name, of;
  cosim::Reduction reduction = cosim::Reduction::kFinal;
  YAML::Node node;
};

struct SystemSpec {
  std::string name, description;
  std::uint64_t seed = 1;
  /// Algorithm, step, threads, retry; stop is the duration.
  cosim::MasterOptions master;
  /// Whether the master's settings read without a problem (else the system
  /// is built to find the units' problems too, and no master is made).
  bool master_ok = true;

  models::Scene scene = models::OpenFloor();
  /// Whether the scene read without a problem (else nothing is built on it:
  /// its units' problems would only echo the scene's).
  bool scene_ok = true;

  /// A deque: a unit's parameters stay where they are while units are added.
  std::deque<UnitSpec> units;
  /// Whether every unit read without a problem (else the system is not
  /// built: every connection to a bad unit would be reported again).
  bool units_ok = true;
  std::vector<ConnectionSpec> connections;
  /// nullopt: the file gives no `recording:` (everything is recorded).
  std::optional<RecordingSpec> recording;
  std::vector<MetricDefinition> metrics;
  Reference reference;

  /// Where the values the assembly derived came from: key path in this
  /// description (units.chassis.parameters.initial_x) -> the key the user
  /// wrote (robot.pose.x_m), for errors found when the units are built.
  std::map<std::string, Origin> origins;

  /// The top-level keys as the file wrote them (name, description,
  /// duration_s, seed, master, reference) and the scene as read, for
  /// ToYaml; the file's top-level map, for errors at it.
  YAML::Node head{YAML::NodeType::Map};
  YAML::Node scene_node;
  YAML::Node root;

  UnitSpec* FindUnit(const std::string& name);
  const UnitSpec* FindUnit(const std::string& name) const;
};

/// The system description as a system file (`linesim inspect` prints it; it
/// loads and runs as it is).
YAML::Node ToYaml(const SystemSpec& spec);

/// Reads name, description, duration_s, seed, master and reference of a
/// file's top-level map `root` into `spec` (and its `head`).
void ReadSystemHead(const YAML::Node& root, YamlReader& r, SystemSpec& spec);

/// A system file's `units:` map, `connections:` list, `recording:` and
/// `metrics:` into `spec` (appended), problems reported through `r`.
/// `units_required`: a system file must have units; a robot scenario's
/// `units:` only adds to its robot's.
void ReadUnits(const YAML::Node& units, YamlReader& r, SystemSpec& spec, bool units_required);
void ReadConnections(const YAML::Node& list, YamlReader& r, SystemSpec& spec);
void ReadRecording(const YAML::Node& recording, YamlReader& r, SystemSpec& spec);
void ReadMetrics(const YAML::Node& list, YamlReader& r, SystemSpec& spec);

/// A system-level file (`units:`, `connections:`, ...) read and checked
/// into a description; what only the built units can tell is checked by
/// the builder.
SystemSpec ReadSystemFile(const YAML::Node& root, YamlReader& r);

}  // namespace linesim::loader
