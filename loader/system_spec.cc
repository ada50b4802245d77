#include "loader/system_spec.h"

#include <algorithm>
#include <filesystem>
#include <limits>

#include "cosim/system.h"
#include "cosim/variable_table.h"
#include "loader/scenario.h"
#include "loader/scene_file.h"

namespace linesim::loader {

namespace {

YAML::Node Number(double x) { return YAML::Node(cosim::FormatValue(x)); }

template <typename T, typename F>
YAML::Node FlowList(const std::vector<T>& values, F&& item) {
  YAML::Node list(YAML::NodeType::Sequence);
  list.SetStyle(YAML::EmitterStyle::Flow);
  for (const auto& v : values) list.push_back(item(v));
  return list;
}

}  // namespace

std::optional<double> ParameterValue::Number() const {
  if (const auto* x = std::get_if<double>(&value_)) return *x;
  if (const auto* n = std::get_if<std::int64_t>(&value_)) return static_cast<double>(*n);
  if (const auto* node = written()) return YamlReader::DecodeReal(*node);
  return std::nullopt;
}

YAML::Node ParameterValue::ToYaml() const {
  return std::visit(
      [](const auto& v) -> YAML::Node {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, YAML::Node>) {
          return v;
        } else if constexpr (std::is_same_v<T, double>) {
          return loader::Number(v);
        } else if constexpr (std::is_same_v<T, std::vector<double>>) {
          return FlowList(v, [](double x) { return loader::Number(x); });
        } else if constexpr (std::is_same_v<T, std::vector<std::int64_t>>) {
          return FlowList(v, [](std::int64_t x) { return YAML::Node(x); });
        } else if constexpr (std::is_same_v<T, Points>) {
          return FlowList(v, [](const std::array<double, 2>& p) {
            return FlowList(std::vector<double>{p[0], p[1]},
                            [](double x) { return loader::Number(x); });
          });
        } else {
          return YAML::Node(v);
        }
      },
      value_);
}

ParameterValue& Parameters::operator[](const std::string& key) {
  for (auto& [k, v] : items_) {
    if (k == key) return v;
  }
  return items_.emplace_back(key, ParameterValue()).second;
}

const ParameterValue* Parameters::Find(const std::string& key) const {
  for (const auto& [k, v] : items_) {
    if (k == key) return &v;
  }
  return nullptr;
}

YAML::Node Parameters::ToYaml() const {
  if (items_.empty()) return YAML::Node();
  YAML::Node map(YAML::NodeType::Map);
  for (const auto& [k, v] : items_) map[k] = v.ToYaml();
  return map;
}

UnitSpec* SystemSpec::FindUnit(const std::string& name) {
  for (auto& u : units) {
    if (u.name == name) return &u;
  }
  return nullptr;
}

const UnitSpec* SystemSpec::FindUnit(const std::string& name) const {
  return const_cast<SystemSpec*>(this)->FindUnit(name);
}

YAML::Node ToYaml(const SystemSpec& spec) {
  YAML::Node out(YAML::NodeType::Map);
  for (const auto& kv : spec.head) out[kv.first.Scalar()] = kv.second;
  if (spec.scene_node.IsDefined() && !spec.scene_node.IsNull()) out["scene"] = spec.scene_node;
  YAML::Node units(YAML::NodeType::Map);
  for (const auto& u : spec.units) {
    YAML::Node unit(YAML::NodeType::Map);
    unit["type"] = u.type;
    if (u.step) unit["step_s"] = Number(cosim::NsToSeconds(*u.step));
    if (!u.parameters.empty()) unit["parameters"] = u.parameters.ToYaml();
    units[u.name] = unit;
  }
  out["units"] = units;
  if (!spec.metrics.empty()) {
    YAML::Node metrics(YAML::NodeType::Sequence);
    for (const auto& m : spec.metrics) {
      YAML::Node item(YAML::NodeType::Map);
      item["name"] = m.name;
      item["of"] = m.of;
      item["reduce"] = cosim::ToString(m.reduction);
      metrics.push_back(item);
    }
    out["metrics"] = metrics;
  }
  if (spec.recording) {
    YAML::Node rec(YAML::NodeType::Map);
    if (spec.recording->variables) {
      rec["variables"] = FlowList(*spec.recording->variables,
                                  [](const WrittenText& v) { return YAML::Node(v.text); });
    }
    if (spec.recording->interval) {
      rec["interval_s"] = Number(cosim::NsToSeconds(*spec.recording->interval));
    }
    out["recording"] = rec;
  }
  if (!spec.connections.empty()) {
    YAML::Node list(YAML::NodeType::Sequence);
    for (const auto& c : spec.connections) {
      YAML::Node item(YAML::NodeType::Map);
      item.SetStyle(YAML::EmitterStyle::Flow);
      item["from"] = c.from;
      item["to"] = c.to;
      list.push_back(item);
    }
    out["connections"] = list;
  }
  return out;
}

void ReadSystemHead(const YAML::Node& root, YamlReader& r, SystemSpec& spec) {
  spec.root = root;
  for (const char* key : {"name", "description", "duration_s", "seed", "master", "reference"}) {
    if (Child(root, key).IsDefined()) spec.head[key] = Child(root, key);
  }
  spec.name = r.String(root, "", "name", std::filesystem::path(r.file()).stem().string());
  spec.description = r.String(root, "", "description", "");
  cosim::MasterOptions& options = spec.master;
  options.start = 0;
  options.stop = r.Time(root, "", "duration_s", std::nullopt, {0.0, 1e7, true});
  spec.seed = static_cast<std::uint64_t>(
      r.Integer(root, "", "seed", 1, 0, std::numeric_limits<std::int64_t>::max()));

  const std::size_t issues_before_master = r.issues().size();
  const YAML::Node master = Child(root, "master");
  if (master.IsDefined() && !master.IsNull() && r.ExpectMap(master, "master")) {
    r.CheckKeys(master, "master", {"algorithm", "step_s", "threads", "retry"});
  }
  const YAML::Node master_map = master.IsMap() ? master : YAML::Node(YAML::NodeType::Map);
  const std::string algorithm = r.String(
      master_map, "master", "algorithm",
      std::string(cosim::ToString(cosim::Algorithm::kGaussSeidel)), cosim::AlgorithmNames());
  cosim::ParseAlgorithm(algorithm, &options.algorithm);
  options.base_step = ReadMasterStep(r, master_map);
  options.threads = static_cast<int>(r.Integer(master_map, "master", "threads", 1, 1, 256));
  options.retry = ReadMasterRetry(r, master_map, options.base_step);
  if (options.base_step > 0 && options.stop > 0 && options.stop % options.base_step != 0) {
    r.Error(Child(root, "duration_s"), "duration_s",
            "duration " + cosim::FormatSeconds(options.stop) +
                " s is not a whole number of master steps (master.step_s = " +
                cosim::FormatSeconds(options.base_step) + " s)");
  }
  spec.master_ok = r.issues().size() == issues_before_master;
  spec.reference = ReadReference(Child(root, "reference"), r);
}

void ReadUnits(const YAML::Node& units, YamlReader& r, SystemSpec& spec, bool units_required) {
  if (!units.IsDefined() || units.IsNull()) {
    if (units_required) {
      r.Error(YAML::Node(), "units", "missing required key: a map of unit name -> {type, ...}");
      spec.units_ok = false;
    }
    return;
  }
  const std::size_t issues_before = r.issues().size();
  struct Tally {
    YamlReader& r;
    SystemSpec& spec;
    std::size_t before;
    ~Tally() { spec.units_ok = spec.units_ok && r.issues().size() == before; }
  } tally{r, spec, issues_before};
  if (!r.ExpectMap(units, "units")) return;
  if (units_required && units.size() == 0) r.Error(units, "units", "expected at least one unit");
  for (const auto& kv : units) {
    const std::string name = kv.first.Scalar();
    const std::string path = JoinPath("units", name);
    if (!cosim::IsUnitName(name)) {
      r.Error(kv.first, path,
              "unit name '" + name +
                  "' is not valid: expected letters, digits and _ (a fleet's robot scopes its "
                  "units' names: robot.unit)");
      continue;
    }
    const YAML::Node& item = kv.second;
    if (!r.ExpectMap(item, path)) continue;
    r.CheckKeys(item, path, {"type", "step_s", "parameters"});
    UnitSpec* existing = spec.FindUnit(name);
    UnitSpec unit;
    UnitSpec& target = existing ? *existing : unit;
    target.name = name;
    target.node = item;
    // What the file sets here is no longer derived from robot-level keys.
    const auto written = [&](const std::string& key) {
      const std::string w = JoinPath(path, key);
      std::erase_if(spec.origins,
                    [&](const auto& o) { return o.first == w || o.first.starts_with(w + "."); });
    };
    if (!existing || Child(item, "type").IsDefined()) {
      target.type = r.String(item, path, "type", std::nullopt);
      written("type");
      if (target.type.empty()) continue;
      if (!FindUnitType(target.type)) {
        r.Error(Child(item, "type"), JoinPath(path, "type"), UnknownTypeMessage(target.type));
        continue;
      }
    }
    if (Child(item, "step_s").IsDefined()) {
      // 0: the master step.
      target.step = r.Time(item, path, "step_s", 0.0, {0.0, 1e6, true});
      written("step_s");
    }
    const YAML::Node params = Child(item, "parameters");
    const std::string params_path = JoinPath(path, "parameters");
    if (params.IsDefined() && !params.IsNull()) {
      if (!r.ExpectMap(params, params_path)) continue;
      for (const auto& p : params) {
        target.parameters[p.first.Scalar()] = ParameterValue(p.second);
        written(JoinPath("parameters", p.first.Scalar()));
      }
    }
    if (!existing) spec.units.push_back(std::move(unit));
  }
}

void ReadConnections(const YAML::Node& list, YamlReader& r, SystemSpec& spec) {
  if (!list.IsDefined() || list.IsNull()) return;
  if (!r.ExpectSequence(list, "connections")) return;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string path = "connections." + std::to_string(i);
    const YAML::Node item = list[i];
    // Kept, also when bad, so that each keeps its index in the file.
    ConnectionSpec c;
    c.node = item;
    if (r.ExpectMap(item, path)) {
      r.CheckKeys(item, path, {"from", "to"});
      c.from = r.String(item, path, "from", std::nullopt);
      c.to = r.String(item, path, "to", std::nullopt);
    }
    spec.connections.push_back(std::move(c));
  }
}

void ReadRecording(const YAML::Node& rec, YamlReader& r, SystemSpec& spec) {
  if (!rec.IsDefined() || rec.IsNull()) return;
  RecordingSpec recording;
  if (!r.ExpectMap(rec, "recording")) return;
  r.CheckKeys(rec, "recording", {"variables", "interval_s"});
  const cosim::TimeNs step = spec.master.base_step;
  if (Child(rec, "interval_s").IsDefined()) {
    recording.interval =
        r.Time(rec, "recording", "interval_s", cosim::NsToSeconds(step), {0.0, 1e7, true});
    if (step > 0 && *recording.interval % step != 0) {
      r.Error(Child(rec, "interval_s"), "recording.interval_s",
              "expected a whole multiple of master.step_s (" + cosim::FormatSeconds(step) + " s)");
    }
  }
  const YAML::Node vars = Child(rec, "variables");
  if (vars.IsDefined() && r.ExpectSequence(vars, "recording.variables")) {
    recording.variables.emplace();
    for (std::size_t i = 0; i < vars.size(); ++i) {
      if (auto v = r.AsString(vars[i], "recording.variables." + std::to_string(i))) {
        recording.variables->push_back({*v, vars[i]});
      }
    }
  }
  spec.recording = std::move(recording);
}

void ReadMetrics(const YAML::Node& list, YamlReader& r, SystemSpec& spec) {
  if (!list.IsDefined() || list.IsNull()) return;
  if (!r.ExpectSequence(list, "metrics")) return;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string path = "metrics." + std::to_string(i);
    const YAML::Node item = list[i];
    if (!r.ExpectMap(item, path)) continue;
    r.CheckKeys(item, path, {"name", "of", "reduce"});
    MetricDefinition m;
    m.node = item;
    m.name = r.String(item, path, "name", std::nullopt);
    m.of = r.String(item, path, "of", std::nullopt);
    const std::string reduce = r.String(item, path, "reduce", "final", cosim::ReductionNames());
    cosim::ParseReduction(reduce, &m.reduction);
    spec.metrics.push_back(std::move(m));
  }
}

SystemSpec ReadSystemFile(const YAML::Node& root, YamlReader& r) {
  SystemSpec spec;
  if (!r.ExpectMap(root, "(top)")) {
    spec.scene_ok = false;
    return spec;
  }
  r.CheckKeys(root, "",
              {"name", "description", "duration_s", "seed", "master", "units", "connections",
               "recording", "metrics", "scene", "reference"});
  ReadSystemHead(root, r, spec);
  // The scene first: units that need geometry build from it.
  const std::size_t issues_before_scene = r.issues().size();
  spec.scene_node = Child(root, "scene");
  spec.scene = ReadScenarioScene(r, spec.scene_node, r.file());
  spec.scene_ok = r.issues().size() == issues_before_scene;
  if (!spec.scene_ok) return spec;
  ReadUnits(Child(root, "units"), r, spec, true);
  ReadConnections(Child(root, "connections"), r, spec);
  ReadRecording(Child(root, "recording"), r, spec);
  ReadMetrics(Child(root, "metrics"), r, spec);
  return spec;
}

}  // namespace linesim::loader
