#include "loader/scenario.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

#include "cosim/closest_names.h"
#include "cosim/seed.h"
#include "loader/config_names.h"
#include "loader/scene_file.h"
#include "loader/system_spec.h"
#include "loader/yaml_files.h"
#include "platform/sha256.h"

namespace linesim::loader {

namespace fs = std::filesystem;

namespace {

// Whether `text` is valid UTF-8 (no overlong forms, surrogates or code
// points above U+10FFFF): the scenario's path goes into summary.json and
// results, which are UTF-8 text.
bool IsUtf8(const std::string& text) {
  std::size_t i = 0;
  while (i < text.size()) {
    const auto c = static_cast<unsigned char>(text[i]);
    std::size_t n = 0;
    std::uint32_t cp = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if (c >= 0xC2 && c <= 0xDF) {
      n = 1;
      cp = c & 0x1Fu;
    } else if (c >= 0xE0 && c <= 0xEF) {
      n = 2;
      cp = c & 0x0Fu;
    } else if (c >= 0xF0 && c <= 0xF4) {
      n = 3;
      cp = c & 0x07u;
    } else {
      return false;
    }
    if (i + n >= text.size()) return false;  // cut short
    for (std::size_t k = 1; k <= n; ++k) {
      const auto d = static_cast<unsigned char>(text[i + k]);
      if ((d & 0xC0u) != 0x80u) return false;
      cp = (cp << 6) | (d & 0x3Fu);
    }
    if ((n == 2 && cp < 0x800) || (n == 3 && cp < 0x10000) || cp > 0x10FFFF ||
        (cp >= 0xD800 && cp <= 0xDFFF)) {
      return false;
    }
    i += n + 1;
  }
  return true;
}

// `text` with every byte outside printable ASCII as \xNN, for a message
// about a name that is not UTF-8.
std::string Escaped(const std::string& text) {
  static const char* kHex = "0123456789abcdef";
  std::string out;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c < 0x7F) {
      out += ch;
    } else {
      out += std::string("\\x") + kHex[c >> 4] + kHex[c & 0xF];
    }
  }
  return out;
}

// Where a parameter's value came from, to point at it if the unit refuses it.
struct ParameterOrigin {
  std::string file;
  YAML::Node node;
  std::string path;
};

// Converts a YAML value to the declared type of a unit variable and sets it;
// a value that does not convert is reported at `path`.
void ApplyParameter(cosim::Unit& unit, const cosim::VariableInfo& info, const YAML::Node& node,
                    const std::string& path, YamlReader& r) {
  constexpr auto kAny = std::numeric_limits<std::int64_t>::max();
  std::optional<cosim::Value> value;
  switch (info.type) {
    case cosim::VarType::kReal:
      if (const auto v = r.AsReal(node, path)) value = *v;
      break;
    case cosim::VarType::kInteger:
      if (const auto v = r.AsInteger(node, path, -kAny - 1, kAny)) value = *v;
      break;
    case cosim::VarType::kBoolean:
      if (const auto v = r.AsBoolean(node, path)) value = *v;
      break;
    case cosim::VarType::kString:
      if (const auto v = r.AsString(node, path)) value = *v;
      break;
    case cosim::VarType::kRealArray: {
      const std::string expected =
          "a number (for every element) or a list of " + std::to_string(info.size) + " numbers";
      if (node.IsSequence() && node.size() == info.size) {
        std::vector<double> list(info.size);
        bool ok = true;
        for (std::size_t i = 0; i < info.size; ++i) {
          const auto v = r.AsReal(node[i], JoinPath(path, std::to_string(i)));
          ok = ok && v.has_value();
          list[i] = v.value_or(0.0);
        }
        if (ok) value = std::move(list);
      } else if (node.IsSequence()) {
        r.Error(node, path,
                "expected " + expected + ", got a list of " + std::to_string(node.size()));
      } else if (const auto v = YamlReader::DecodeReal(node)) {
        value = *v;
      } else {
        // A dimensionless value ("1") has no unit to name.
        const bool has_unit = !info.unit.empty() && info.unit != "1";
        r.Error(node, path,
                "expected " + expected + (has_unit ? " (" + info.unit + ")" : "") + ", got " +
                    Describe(node));
      }
      break;
    }
  }
  if (!value) return;
  try {
    unit.variables().SetValue(info.ref, *value);
  } catch (const std::exception& e) {
    r.Error(node, path, e.what());
  }
}

// Applies every key of `map` to the unit's parameters, skipping `skip`.
void ApplyParameters(cosim::Unit& unit, const YAML::Node& map, const std::string& path,
                     const std::vector<std::string>& skip, YamlReader& r,
                     std::map<std::string, ParameterOrigin>& origins) {
  std::vector<std::string> parameter_names;
  for (const auto& info : unit.variables().infos()) {
    if (info.causality == cosim::Causality::kParameter) parameter_names.push_back(info.name);
  }
  std::vector<std::string> allowed = parameter_names;
  allowed.insert(allowed.end(), skip.begin(), skip.end());
  for (const auto& kv : map) {
    const std::string key = kv.first.Scalar();
    if (std::find(skip.begin(), skip.end(), key) != skip.end()) continue;
    const std::string key_path = JoinPath(path, key);
    const auto ref = unit.variables().Find(key);
    if (!ref || unit.variables().info(*ref).causality != cosim::Causality::kParameter) {
      r.UnknownPath(kv.first, key_path,
                    "unknown parameter of a " + unit.type_name() + " unit" +
                        ClosestPathsHint(path, key, allowed) + " (linesim inspect " +
                        unit.type_name() + " lists them)");
      continue;
    }
    ApplyParameter(unit, unit.variables().info(*ref), kv.second, key_path, r);
    origins[key] = {r.file(), kv.second, key_path};
  }
}

// Sets a typed value the assembly derived when it is of the variable's
// type; true if done. Anything else goes through the YAML conversion, which
// names what was expected.
bool ApplyTyped(cosim::Unit& unit, const cosim::VariableInfo& info, const ParameterValue& value,
                const std::string& path, YamlReader& r) {
  std::optional<cosim::Value> v;
  const auto& typed = value.value();
  switch (info.type) {
    case cosim::VarType::kReal:
      if (const auto* x = std::get_if<double>(&typed)) v = *x;
      if (const auto* n = std::get_if<std::int64_t>(&typed)) v = static_cast<double>(*n);
      break;
    case cosim::VarType::kInteger:
      if (const auto* n = std::get_if<std::int64_t>(&typed)) v = *n;
      break;
    case cosim::VarType::kBoolean:
      if (const auto* b = std::get_if<bool>(&typed)) v = *b;
      break;
    case cosim::VarType::kString:
      if (const auto* t = std::get_if<std::string>(&typed)) v = *t;
      break;
    case cosim::VarType::kRealArray:
      if (const auto* list = std::get_if<std::vector<double>>(&typed);
          list && list->size() == info.size) {
        v = *list;
      }
      break;
  }
  if (!v) return false;
  try {
    unit.variables().SetValue(info.ref, *v);
  } catch (const std::exception& e) {
    r.Error(YAML::Node(), path, e.what());
  }
  return true;
}

// Applies a description's parameters (typed, or as a file wrote them) to the
// unit, skipping `skip`.
void ApplyParameters(cosim::Unit& unit, const Parameters& params, const std::string& path,
                     const std::vector<std::string>& skip, YamlReader& r,
                     std::map<std::string, ParameterOrigin>& origins) {
  std::vector<std::string> allowed = skip;
  for (const auto& info : unit.variables().infos()) {
    if (info.causality == cosim::Causality::kParameter) allowed.push_back(info.name);
  }
  for (const auto& [key, value] : params) {
    if (std::find(skip.begin(), skip.end(), key) != skip.end()) continue;
    const std::string key_path = JoinPath(path, key);
    const YAML::Node* written = value.written();
    const YAML::Node node = written ? *written : YAML::Node();
    const auto ref = unit.variables().Find(key);
    if (!ref || unit.variables().info(*ref).causality != cosim::Causality::kParameter) {
      r.UnknownPath(node, key_path,
                    "unknown parameter of a " + unit.type_name() + " unit" +
                        ClosestPathsHint(path, key, allowed) + " (linesim inspect " +
                        unit.type_name() + " lists them)");
      continue;
    }
    const cosim::VariableInfo& info = unit.variables().info(*ref);
    if (written || !ApplyTyped(unit, info, value, key_path, r)) {
      ApplyParameter(unit, info, written ? node : value.ToYaml(), key_path, r);
    }
    origins[key] = {r.file(), node, key_path};
  }
}

// Builds the system a description describes: creates and parameterizes its
// units, connects them, makes the master and resolves what is recorded and
// measured. Problems are reported where the description says its values
// came from.
class Builder {
 public:
  Builder(Scenario& s, YamlReader& r) : s_(s), r_(r) {}

  void Build(const SystemSpec& spec) {
    s_.name = spec.name;
    s_.description = spec.description;
    s_.seed = spec.seed;
    s_.duration_s = cosim::NsToSeconds(spec.master.stop);
    s_.scene = spec.scene;
    s_.reference = spec.reference;
    // A scene problem would only echo as problems of the units built on it.
    if (!spec.scene_ok) return;
    if (!spec.origins.empty()) r_.SetOrigins(spec.origins);

    s_.system = std::make_unique<cosim::System>();
    const std::size_t issues_before_units = r_.issues().size();
    for (const auto& unit : spec.units) BuildUnit(unit);
    const bool units_ok = spec.units_ok && r_.issues().size() == issues_before_units;
    const auto connections = BuildConnections(spec.connections);
    // With a unit missing, every connection to it would be reported again.
    if (!units_ok) return;

    try {
      s_.system->Build();
      // Bad master settings were reported when read; the master would only
      // report them again.
      if (!spec.master_ok) return;
      s_.master = std::make_unique<cosim::Master>(*s_.system, spec.master);
    } catch (const cosim::ConfigError& e) {
      for (const auto& p : e.problems()) {
        if (p.connection && *p.connection < connections.size()) {
          const std::size_t index = connections[*p.connection];
          r_.Error(spec.connections[index].node, "connections." + std::to_string(index), p.message);
        } else if (p.unit && *p.unit < built_.size()) {
          // At its step where one is given (the assembly's is derived from
          // control.period_s, say), else at the unit.
          const UnitSpec& unit = *built_[*p.unit];
          const YAML::Node step = Child(unit.node, "step_s");
          const std::string unit_path = JoinPath("units", unit.name);
          r_.Error(step.IsDefined() ? step : unit.node,
                   unit.step ? JoinPath(unit_path, "step_s") : unit_path, p.message);
        } else {
          r_.Error(spec.root, "", p.message);
        }
      }
      return;
    }
    BuildRecording(spec);
    BuildMetrics(spec.metrics);
    std::vector<std::string> names;
    for (const auto& m : s_.metrics) names.push_back(m.name);
    CheckReferenceMetrics(s_.reference, names, spec.root, "of this scenario", r_);
  }

 private:
  void BuildUnit(const UnitSpec& spec) {
    const std::string path = JoinPath("units", spec.name);
    const UnitType* type = FindUnitType(spec.type);
    if (!type) {
      r_.Error(Child(spec.node, "type"), JoinPath(path, "type"), UnknownTypeMessage(spec.type));
      return;
    }
    const YAML::Node params = spec.parameters.ToYaml();
    const std::string params_path = JoinPath(path, "parameters");

    const std::size_t issues_before = r_.issues().size();
    // The model file (`parameters.model`) is read before the unit is made:
    // its structural keys (a laser's beam count) shape the variable table.
    YAML::Node model;
    std::string model_file;
    if (spec.parameters.Has("model") && !type->model_folder.empty()) {
      const std::string model_path = JoinPath(params_path, "model");
      if (const auto value = r_.AsString(Child(params, "model"), model_path)) {
        model = LoadModel(r_, Child(params, "model"), model_path, "model", *value,
                          type->model_folder, s_.file, &model_file);
        if (model.IsDefined()) {
          const YamlReader::InFile in_model(r_, model_file);
          if (!r_.ExpectMap(model, "")) model = YAML::Node();
        }
      }
      if (r_.issues().size() != issues_before) return;
    }
    std::unique_ptr<cosim::Unit> unit;
    try {
      unit = type->create({spec.name, cosim::DeriveSeed(s_.seed, spec.name), r_, params,
                           params_path, s_.scene, model, model_file});
    } catch (const std::exception& e) {
      r_.Error(spec.node, path, std::string("cannot create the unit: ") + e.what());
      return;
    }
    if (!unit || r_.issues().size() != issues_before) return;

    std::vector<std::string> structural;
    for (const auto& k : type->structural_keys) structural.push_back(k.name);
    std::map<std::string, ParameterOrigin> origins;

    // Model file first, then the description's own values on top. The
    // model's structural keys were the factory's.
    if (model.IsMap()) {
      const YamlReader::InFile in_model(r_, model_file);
      std::vector<std::string> skipped = structural;
      skipped.insert(skipped.end(), {"source", "description"});
      ApplyParameters(*unit, model, "", skipped, r_, origins);
    }
    ApplyParameters(*unit, spec.parameters, params_path, structural, r_, origins);

    for (const auto& p : unit->CheckParameters()) {
      const std::string suffix = p.index ? "." + std::to_string(*p.index) : "";
      if (auto it = origins.find(p.variable); it != origins.end()) {
        const ParameterOrigin& origin = it->second;
        r_.Error(origin.file, origin.node, origin.path + suffix, p.message);
      } else {
        r_.Error(params.IsDefined() ? params : spec.node,
                 JoinPath(params_path, p.variable) + suffix, p.message);
      }
    }
    if (r_.issues().size() == issues_before) {
      s_.system->Add(std::move(unit), spec.step.value_or(0));
      built_.push_back(&spec);
    }
  }

  // The index in `list` of each connection added to the system.
  std::vector<std::size_t> BuildConnections(const std::vector<ConnectionSpec>& list) {
    std::vector<std::size_t> added;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const ConnectionSpec& c = list[i];
      if (c.from.empty() || c.to.empty()) continue;
      try {
        s_.system->Connect(cosim::Endpoint::Parse(c.from), cosim::Endpoint::Parse(c.to));
        added.push_back(i);
      } catch (const std::invalid_argument& e) {
        r_.Error(c.node, "connections." + std::to_string(i), e.what());
      }
    }
    return added;
  }

  void BuildRecording(const SystemSpec& spec) {
    std::vector<cosim::Probe> probes;
    s_.record_interval = spec.master.base_step;
    if (spec.recording && spec.recording->interval) s_.record_interval = *spec.recording->interval;
    if (!spec.recording || !spec.recording->variables) {
      // Without a list: every output of every unit (docs/scenarios.md).
      std::vector<std::string> names;
      for (const auto& n : s_.system->UnitNames()) names.push_back(n + ".*");
      probes = cosim::ResolveProbes(*s_.system, names);
    } else {
      // A column is recorded once, however many items cover it.
      std::set<std::string> labels;
      const auto& vars = *spec.recording->variables;
      for (std::size_t i = 0; i < vars.size(); ++i) {
        try {
          for (auto& p : cosim::ResolveProbes(*s_.system, {vars[i].text})) {
            if (labels.insert(p.label).second) probes.push_back(std::move(p));
          }
        } catch (const cosim::ConfigError& e) {
          r_.Error(vars[i].node, "recording.variables." + std::to_string(i), e.what());
        }
      }
    }
    if (r_.ok()) s_.recorded = std::move(probes);
  }

  void BuildMetrics(const std::vector<MetricDefinition>& list) {
    std::map<std::string, std::size_t> seen;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const MetricDefinition& m = list[i];
      const std::string path = "metrics." + std::to_string(i);
      if (const auto [it, fresh] = seen.emplace(m.name, i); !fresh) {
        // A robot scenario's own metric that its expansion gives too (a
        // worker's, a robot's): reported at the one the file wrote, the
        // derived one has no key of the user's.
        const MetricDefinition& first = list[it->second];
        const bool derived = !m.node.IsMap() && first.node.IsMap();
        r_.Error(Child(derived ? first.node : m.node, "name"),
                 JoinPath("metrics." + std::to_string(derived ? it->second : i), "name"),
                 derived ? "metric '" + m.name + "' is also one the robot scenario gives (of " +
                               m.of + "): give yours another name"
                         : "metric '" + m.name + "' defined twice");
      }
      if (m.of.empty()) continue;
      cosim::MetricSpec spec;
      spec.name = m.name;
      spec.reduction = m.reduction;
      try {
        const auto probes = cosim::ResolveProbes(*s_.system, {m.of});
        if (probes.size() != 1) {
          r_.Error(Child(m.node, "of"), JoinPath(path, "of"),
                   "'" + m.of + "' is " + std::to_string(probes.size()) +
                       " values: expected one, e.g. " + probes.front().label);
          continue;
        }
        spec.probe = probes.front();
        s_.metrics.push_back(spec);
      } catch (const cosim::ConfigError& e) {
        r_.Error(Child(m.node, "of"), JoinPath(path, "of"), e.what());
      }
    }
  }

  Scenario& s_;
  YamlReader& r_;
  // The description of each unit added to the system, in system order.
  std::vector<const UnitSpec*> built_;
};

}  // namespace

// The tree as unambiguous text for its hash: every scalar with its length
// (no quoting rules to apply; YAML::Emitter took 30 M instructions, a third of
// a short run's start, measured with callgrind), maps in file order.
static void AppendCanonical(const YAML::Node& node, std::string& out) {
  switch (node.Type()) {
    case YAML::NodeType::Scalar:
      out += 's' + std::to_string(node.Scalar().size()) + ':' + node.Scalar();
      break;
    case YAML::NodeType::Sequence:
      out += "[" + std::to_string(node.size());
      for (const auto& item : node) AppendCanonical(item, out);
      out += ']';
      break;
    case YAML::NodeType::Map:
      out += "{" + std::to_string(node.size());
      for (const auto& kv : node) {
        AppendCanonical(kv.first, out);
        AppendCanonical(kv.second, out);
      }
      out += '}';
      break;
    default:  // null, undefined
      out += '~';
  }
}

Scenario LoadScenario(const std::string& file, const std::vector<std::string>& set_args) {
  return LoadScenario(file, set_args, {});
}

// Gives the units of `unit_types` their new types, keeping the parameters
// each new type declares (the others were derived for the type replaced).
static void ReplaceUnitTypes(SystemSpec& spec, const std::map<std::string, std::string>& unit_types,
                             YamlReader& r) {
  for (const auto& [name, type] : unit_types) {
    UnitSpec* unit = spec.FindUnit(name);
    const UnitType* found = FindUnitType(type);
    if (unit == nullptr) {
      r.Error(YAML::Node(), JoinPath("units", name),
              "no unit '" + name + "' to give the type '" + type + "'");
      continue;
    }
    if (found == nullptr) {
      r.Error(YAML::Node(), JoinPath(JoinPath("units", name), "type"), UnknownTypeMessage(type));
      continue;
    }
    std::unique_ptr<cosim::Unit> declared;
    try {
      declared = CreateDefaultUnit(*found);
    } catch (const std::exception& e) {
      r.Error(YAML::Node(), JoinPath("units", name),
              std::string("cannot create the unit: ") + e.what());
      continue;
    }
    Parameters kept;
    for (const auto& [key, value] : unit->parameters) {
      const auto ref = declared->variables().Find(key);
      if (ref && declared->variables().info(*ref).causality == cosim::Causality::kParameter) {
        kept[key] = value;
      }
    }
    unit->type = type;
    unit->parameters = std::move(kept);
  }
}

static std::vector<Issue> ParseOverrides(const std::vector<std::string>& set_args,
                                         const std::string& file,
                                         std::vector<Override>& overrides) {
  std::vector<Issue> issues;
  for (const auto& arg : set_args) {
    try {
      overrides.push_back(ParseOverride(arg));
    } catch (const ScenarioError& e) {
      for (auto i : e.issues()) {
        i.file = file;
        issues.push_back(i);
      }
    }
  }
  return issues;
}

// The scenario `tree` (of `file`, as messages name it) with the overrides,
// checked and built.
static Scenario BuildScenario(YAML::Node tree, const std::string& file,
                              std::vector<Override> overrides, std::vector<Issue> issues,
                              const std::map<std::string, std::string>& unit_types) {
  Scenario s;
  s.file = file;
  s.overrides = std::move(overrides);
  RefuseOverridesThroughAliases(tree, s.overrides, file, issues);
  ExposeSceneModelToOverrides(tree, s.overrides, file);
  ApplyOverrides(tree, s.overrides, file, issues);
  std::set<std::string> overridden, without_value;
  for (const auto& o : s.overrides) {
    overridden.insert(o.path);
    // `--set key=` (or only blanks): null in the tree, which must not read
    // as the default.
    if (o.value.find_first_not_of(" \t") == std::string::npos) without_value.insert(o.path);
  }
  YamlReader reader(file, overridden);
  reader.SetGivenWithoutValue(without_value);
  reader.Add(issues);
  // A key given without a value that no typed reader refused (naming what
  // it takes) is one whose null would silently mean its default too (a
  // section such as control=): refused here.
  const auto refuse_unread_without_value = [&] {
    for (const std::string& path : without_value) {
      const auto& all = reader.issues();
      if (std::any_of(all.begin(), all.end(),
                      [&](const Issue& i) { return i.key_path == path; })) {
        continue;
      }
      reader.Error(YAML::Node(), path,
                   "no value given (--set " + path +
                       "=): an empty value does not mean the default; give a value, or leave "
                       "the --set out for the default (" + path + "=null is an explicit null)");
    }
  };
  SystemSpec spec;
  if (IsRobotScenario(tree)) {
    RobotInfo info;
    spec = ExpandRobotScenario(tree, reader, info);
    // A robot-level problem would only echo as problems of the expansion.
    if (!reader.ok()) {
      refuse_unread_without_value();
      throw ScenarioError(reader.issues());
    }
    s.robot = std::move(info);
    s.expanded = ToYaml(spec);
    tree = s.expanded;
  } else {
    spec = ReadSystemFile(tree, reader);
  }
  if (!unit_types.empty()) {
    ReplaceUnitTypes(spec, unit_types, reader);
    // The hash (provenance) is of what is built.
    tree = ToYaml(spec);
    if (s.robot) s.expanded = tree;
  }
  Builder(s, reader).Build(spec);
  refuse_unread_without_value();
  if (!reader.ok()) throw ScenarioError(reader.issues());
  std::string canonical;
  AppendCanonical(tree, canonical);
  s.sha256 = platform::Sha256Hex(canonical);
  return s;
}

Scenario LoadScenario(const std::string& file, const std::vector<std::string>& set_args,
                      const std::map<std::string, std::string>& unit_types) {
  // Refused before anything is read or written (no --out folder).
  if (!IsUtf8(file)) {
    Issue issue;
    issue.file = Escaped(file);
    issue.message =
        "the scenario file's path is not valid UTF-8 (summary.json and the results name it): "
        "expected a UTF-8 path; rename the file";
    throw ScenarioError({issue});
  }
  // The overrides' own problems are found before the file is read.
  std::vector<Override> overrides;
  std::vector<Issue> issues = ParseOverrides(set_args, file, overrides);
  YAML::Node tree = LoadYamlOrThrow(file);
  return BuildScenario(tree, file, std::move(overrides), std::move(issues), unit_types);
}

Scenario LoadScenarioTree(YAML::Node tree, const std::string& label,
                          const std::vector<std::string>& set_args,
                          const std::map<std::string, std::string>& unit_types) {
  std::vector<Override> overrides;
  std::vector<Issue> issues = ParseOverrides(set_args, label, overrides);
  return BuildScenario(tree, label, std::move(overrides), std::move(issues), unit_types);
}

cosim::TimeNs ReadMasterStep(YamlReader& r, const YAML::Node& master) {
  return r.Time(master, "master", "step_s", 0.001, {0.0, 10.0, true});
}

cosim::RetryOptions ReadMasterRetry(YamlReader& r, const YAML::Node& master,
                                    cosim::TimeNs base_step) {
  cosim::RetryOptions retry;
  const YAML::Node node = Child(master, "retry");
  if (!node.IsDefined() || node.IsNull() || !r.ExpectMap(node, "master.retry")) return retry;
  r.CheckKeys(node, "master.retry", {"enabled", "min_step_s", "shrink", "grow"});
  const std::string path = "master.retry";
  retry.enabled = r.Boolean(node, path, "enabled", false);
  retry.min_step =
      r.Time(node, path, "min_step_s", cosim::NsToSeconds(retry.min_step), {0.0, 10.0, true});
  retry.shrink = r.Real(node, path, "shrink", retry.shrink, {0.0, 1.0, true});
  retry.grow = r.Real(node, path, "grow", retry.grow, {1.0, 1e6});
  if (retry.shrink >= 1.0) {
    r.Error(Child(node, "shrink"), path + ".shrink",
            "must be below 1 (a retried step is smaller), got " + cosim::FormatValue(retry.shrink));
  }
  if (base_step > 0 && retry.min_step > base_step) {
    r.Error(Child(node, "min_step_s"), path + ".min_step_s",
            "min_step_s " + cosim::FormatSeconds(retry.min_step) + " s is above the master step " +
                cosim::FormatSeconds(base_step) + " s");
  }
  return retry;
}

std::unique_ptr<cosim::Unit> CreateDefaultUnit(const std::string& type_name) {
  const UnitType* type = FindUnitType(type_name);
  if (!type) throw ScenarioError({{"", 0, "", UnknownTypeMessage(type_name)}});
  return CreateDefaultUnit(*type);
}

std::unique_ptr<cosim::Unit> CreateDefaultUnit(const UnitType& type) {
  YamlReader reader("(defaults)");
  const YAML::Node none;
  const std::string path = "parameters";
  // Units that take geometry from the scene show their variables for an
  // open floor with one belt: 10 m x 2 m along x at paper 1's typical
  // 0.1 m/s, +-10 %.
  models::Scene scene = models::OpenFloor();
  models::Belt belt;
  belt.name = "line";
  belt.area = {0.0, 0.0, 10.0, 2.0, 0.0};
  belt.nominal_speed_mps = 0.1;
  belt.speed_variation = 0.1;
  belt.variation_period_s = 20.0;
  belt.acceleration_mps2 = 0.5;
  scene.belts.push_back(belt);
  auto unit = type.create({type.name, 1, reader, none, path, scene, none, ""});
  if (!reader.ok() || !unit) throw ScenarioError(reader.issues());
  return unit;
}

}  // namespace linesim::loader
