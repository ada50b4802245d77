#include "loader/assembly/builder.h"

#include "cosim/variable_table.h"
#include "loader/scenario.h"

namespace linesim::loader::assembly {

std::string Signal(const std::string& unit, const std::string& variable) {
  return unit + "." + variable;
}

std::string Element(const std::string& unit, const std::string& variable, std::size_t k) {
  return Signal(unit, variable) + "[" + std::to_string(k) + "]";
}

YAML::Node Num(double x) { return YAML::Node(cosim::FormatValue(x)); }

YAML::Node List(const std::vector<double>& values) {
  YAML::Node list(YAML::NodeType::Sequence);
  list.SetStyle(YAML::EmitterStyle::Flow);
  for (double v : values) list.push_back(Num(v));
  return list;
}

YAML::Node IntList(const std::vector<int>& values) {
  YAML::Node list(YAML::NodeType::Sequence);
  list.SetStyle(YAML::EmitterStyle::Flow);
  for (int v : values) list.push_back(v);
  return list;
}

YAML::Node PointList(const std::vector<std::array<double, 2>>& points) {
  YAML::Node list(YAML::NodeType::Sequence);
  list.SetStyle(YAML::EmitterStyle::Flow);
  for (const auto& p : points) list.push_back(List({p[0], p[1]}));
  return list;
}

void MergeInto(YAML::Node to, const YAML::Node& from) {
  if (!from.IsMap()) return;
  for (const auto& kv : from) to[kv.first.Scalar()] = kv.second;
}

void AddMetric(YAML::Node metrics, const std::string& name, const std::string& of,
               const char* reduce) {
  YAML::Node m;
  m["name"] = name;
  m["of"] = of;
  m["reduce"] = reduce;
  metrics.push_back(m);
}

YAML::Node SystemBuilder::Unit(const std::string& name, const std::string& type) {
  YAML::Node unit = out_["units"][name];
  unit["type"] = type;
  return unit;
}

bool SystemBuilder::HasUnit(const std::string& name) const {
  const YAML::Node units = Child(out_, "units");
  return Child(units, name).IsDefined();
}

YAML::Node SystemBuilder::Params(const std::string& name) {
  return out_["units"][name]["parameters"];
}

void SystemBuilder::SetStep(const std::string& name, cosim::TimeNs step) {
  out_["units"][name]["step_s"] = Num(cosim::NsToSeconds(step));
}

void SystemBuilder::Connect(const std::string& from, const std::string& to) {
  YAML::Node c;
  c.SetStyle(YAML::EmitterStyle::Flow);
  c["from"] = from;
  c["to"] = to;
  connections_.push_back(c);
}

void SystemBuilder::Derived(const std::string& expanded, const YAML::Node& parent,
                            const std::string& path, const std::string& key) {
  const YAML::Node node = Child(parent, key);
  origins_[expanded] = {node.IsDefined() ? node : parent, JoinPath(path, key), ""};
}

void SystemBuilder::Origin(const std::string& expanded, loader::Origin origin) {
  origins_[expanded] = std::move(origin);
}

void SystemBuilder::MergeSettings(const std::string& unit, const YAML::Node& settings,
                                  const std::string& file, const std::string& section) {
  YAML::Node params = Params(unit);
  const std::string prefix = JoinPath(JoinPath("units", unit), "parameters");
  if (settings.IsMap()) {
    for (const auto& kv : settings) {
      const std::string key = kv.first.Scalar();
      // What the assembly derives (geometry, feedforwards, counts) has one
      // source; a second one here would silently lose or win.
      if (Child(params, key).IsDefined()) {
        r_.Error(file, kv.second, JoinPath(section, key),
                 "the assembly derives " + unit + "'s '" + key +
                     "' from the robot's description (body, wheels, motor groups): leave it out "
                     "here");
        continue;
      }
      params[key] = kv.second;
      origins_[JoinPath(prefix, key)] = {kv.second, JoinPath(section, key), file};
    }
  }
}

void SystemBuilder::RequireParameters(const std::string& unit, const YAML::Node& settings,
                                      const std::string& file, const std::string& section) {
  const YAML::Node params = Params(unit);
  const YAML::Node type = Child(Child(Child(out_, "units"), unit), "type");
  const config::UnitType* unit_type = type.IsScalar() ? FindUnitType(type.Scalar()) : nullptr;
  if (!unit_type) return;
  const auto defaults = CreateDefaultUnit(*unit_type);
  for (const auto& info : defaults->variables().infos()) {
    if (info.causality != cosim::Causality::kParameter || !info.rule.required()) continue;
    if (Child(params, info.name).IsDefined()) continue;
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
