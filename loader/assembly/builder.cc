#include "loader/assembly/builder.h"

#include "cosim/variable_table.h"
#include "loader/scenario.h"

namespace linesim::loader::assembly {

std::string Port::Name() const {
  std::string name = unit + "." + variable;
  if (element) name += "[" + std::to_string(*element) + "]";
  return name;
}

Port Signal(const std::string& unit, const std::string& variable) {
  return {unit, variable, std::nullopt};
}

Port Element(const std::string& unit, const std::string& variable, std::size_t k) {
  return {unit, variable, k};
}

YAML::Node Num(double x) { return YAML::Node(cosim::FormatValue(x)); }

YAML::Node List(const std::vector<double>& values) {
  YAML::Node list(YAML::NodeType::Sequence);
  list.SetStyle(YAML::EmitterStyle::Flow);
  for (double v : values) list.push_back(Num(v));
  return list;
}

std::vector<std::int64_t> IntList(const std::vector<int>& values) {
  return {values.begin(), values.end()};
}

YAML::Node PointList(const std::vector<std::array<double, 2>>& points) {
  YAML::Node list(YAML::NodeType::Sequence);
  list.SetStyle(YAML::EmitterStyle::Flow);
  for (const auto& p : points) list.push_back(List({p[0], p[1]}));
  return list;
}

UnitSpec& SystemBuilder::Unit(const std::string& name, const std::string& type) {
  UnitSpec* unit = spec_.FindUnit(name);
  if (!unit) {
    unit = &spec_.units.emplace_back();
    unit->name = name;
  }
  unit->type = type;
  return *unit;
}

bool SystemBuilder::HasUnit(const std::string& name) const { return spec_.FindUnit(name); }

Parameters& SystemBuilder::Params(const std::string& name) {
  UnitSpec* unit = spec_.FindUnit(name);
  if (!unit) {
    unit = &spec_.units.emplace_back();
    unit->name = name;
  }
  return unit->parameters;
}

void SystemBuilder::SetStep(const std::string& name, cosim::TimeNs step) {
  UnitSpec* unit = spec_.FindUnit(name);
  if (!unit) {
    unit = &spec_.units.emplace_back();
    unit->name = name;
  }
  unit->step = step;
}

void SystemBuilder::Connect(const Port& from, const Port& to) {
  spec_.connections.push_back({from.Name(), to.Name(), YAML::Node()});
}

void SystemBuilder::Metric(const std::string& name, const Port& of, cosim::Reduction reduce) {
  spec_.metrics.push_back({name, of.Name(), reduce, YAML::Node()});
}

void SystemBuilder::Derived(const std::string& expanded, const YAML::Node& parent,
                            const std::string& path, const std::string& key) {
  const YAML::Node node = Child(parent, key);
  spec_.origins[expanded] = {node.IsDefined() ? node : parent, JoinPath(path, key), ""};
}

void SystemBuilder::Origin(const std::string& expanded, loader::Origin origin) {
  spec_.origins[expanded] = std::move(origin);
}

void SystemBuilder::MergeSettings(const std::string& unit, const YAML::Node& settings,
                                  const std::string& file, const std::string& section) {
  Parameters& params = Params(unit);
  const std::string prefix = JoinPath(JoinPath("units", unit), "parameters");
  if (settings.IsMap()) {
    for (const auto& kv : settings) {
      const std::string key = kv.first.Scalar();
      // What the assembly derives (geometry, feedforwards, counts) has one
      // source; a second one here would silently lose or win.
      if (params.Has(key)) {
        r_.Error(file, kv.second, JoinPath(section, key),
                 "the assembly derives " + unit + "'s '" + key +
                     "' from the robot's description (body, wheels, motor groups): leave it out "
                     "here");
        continue;
      }
      params[key] = ParameterValue(kv.second);
      spec_.origins[JoinPath(prefix, key)] = {kv.second, JoinPath(section, key), file};
    }
  }
}

void SystemBuilder::RequireParameters(const std::string& unit, const YAML::Node& settings,
                                      const std::string& file, const std::string& section) {
  const UnitSpec* spec = spec_.FindUnit(unit);
  const config::UnitType* unit_type = spec ? FindUnitType(spec->type) : nullptr;
  if (!unit_type) return;
  const auto defaults = CreateDefaultUnit(*unit_type);
  for (const auto& info : defaults->variables().infos()) {
    if (info.causality != cosim::Causality::kParameter || !info.rule.required()) continue;
    if (spec->parameters.Has(info.name)) continue;
    r_.Error(file, settings.IsMap() && settings.size() > 0 ? settings.begin()->second : YAML::Node(),
             JoinPath(section, info.name),
             "missing required key: the " + unit_type->name + " parameter '" + info.name +
                 "' has no default (robot-specific)" +
                 (info.description.empty() ? "" : ": " + info.description));
  }
}

YAML::Node SystemBuilder::Section(const YAML::Node& parent, const std::string& path,
                                  const std::string& key, const std::vector<std::string>& keys) {
  const YAML::Node node = Child(parent, key);
  const std::string full = JoinPath(path, key);
  if (!node.IsDefined() || node.IsNull()) return YAML::Node(YAML::NodeType::Map);
  if (!r_.ExpectMap(node, full)) return YAML::Node(YAML::NodeType::Map);
  r_.CheckKeys(node, full, keys);
  return node;
}

cosim::TimeNs SystemBuilder::ControlPeriod() const {
  YamlReader quiet(r_.file());
  const YAML::Node control = Child(root_, "control");
  if (!control.IsMap()) return kControlPeriod;
  return quiet.Time(control, "control", "period_s", cosim::NsToSeconds(kControlPeriod),
                    {0.0, 10.0, true});
}

cosim::TimeNs SystemBuilder::MasterStep() const {
  YamlReader quiet(r_.file());
  return ReadMasterStep(quiet, Child(root_, "master"));
}

}  // namespace linesim::loader::assembly
