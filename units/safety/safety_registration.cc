// Registers the safety family's unit types (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "models/polygon.h"
#include "units/safety/safety_field_unit.h"

namespace linesim::safety {
namespace {

using config::Child;
using config::JoinPath;

// A polygon [[x, y], ...] at `key` of `item` (empty when absent).
std::vector<std::array<double, 2>> ReadPolygon(config::YamlReader& r, const YAML::Node& item,
                                               const std::string& item_path,
                                               const std::string& key, bool required) {
  std::vector<std::array<double, 2>> corners;
  const YAML::Node list = Child(item, key);
  const std::string path = JoinPath(item_path, key);
  if (!list.IsDefined() || list.IsNull()) {
    if (required) r.Error(item, path, "missing required key: a polygon [[x, y], ...] (m, scanner frame)");
    return corners;
  }
  if (!r.ExpectSequence(list, path)) return corners;
  if (list.size() < 3) {
    r.Error(list, path, "a field needs at least 3 corners [x, y] (m)");
    return corners;
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (auto p = r.AsPoint(list[i], JoinPath(path, std::to_string(i)))) corners.push_back(*p);
  }
  if (corners.size() != list.size()) return {};
  // A degenerate polygon holds no point: a field that never stops.
  if (const auto problem = models::PolygonProblem(corners)) {
    r.Error(list, path, "the field " + *problem);
    return {};
  }
  return corners;
}

std::unique_ptr<cosim::Unit> MakeSafetyField(const config::UnitBuildContext& c) {
  config::YamlReader& r = c.reader;
  const bool inspect = !c.parameters.IsDefined() || c.parameters.IsNull();
  const std::size_t issues_before = r.issues().size();
  // `linesim inspect`: one beam keeps the table readable.
  const auto beams = r.Integer(c.parameters, c.path, "beam_count", inspect ? 1 : 541, 1, 100000);
  std::vector<SafetyFieldUnit::FieldSet> sets;
  if (inspect) {
    sets.push_back({1e9, {{0.0, -0.4}, {0.6, -0.4}, {0.6, 0.4}}, {}});
  } else {
    const YAML::Node list = Child(c.parameters, "field_sets");
    const std::string path = JoinPath(c.path, "field_sets");
    if (!list.IsDefined()) {
      r.Error(c.parameters, path, "missing required key: a list of {max_speed_mps, protective, warning}");
    } else if (r.ExpectSequence(list, path)) {
      for (std::size_t i = 0; i < list.size(); ++i) {
        const YAML::Node item = list[i];
        const std::string item_path = JoinPath(path, std::to_string(i));
        if (!r.ExpectMap(item, item_path)) continue;
        r.CheckKeys(item, item_path, {"max_speed_mps", "protective", "warning"});
        SafetyFieldUnit::FieldSet set;
        set.max_speed_mps = r.Real(item, item_path, "max_speed_mps", std::nullopt, {0.0, 100.0});
        set.protective = ReadPolygon(r, item, item_path, "protective", true);
        set.warning = ReadPolygon(r, item, item_path, "warning", false);
        sets.push_back(std::move(set));
      }
      if (list.size() == 0) r.Error(list, path, "expected at least one field set");
    }
  }
  if (r.issues().size() != issues_before) return nullptr;
  return std::make_unique<SafetyFieldUnit>(c.name, static_cast<int>(beams), std::move(sets));
}

const config::UnitTypeRegistrar kSafetyField(
    {SafetyFieldUnit::kTypeName,
     "S300 field sets (protective, warning; switched by speed) on a scanner's ranges, with "
     "multiple sampling, and the robot's safety function: safe stop, reduced speed, resume",
     "",
     {{"beam_count", "beams per scan (the size of `ranges`; default 541, the S300)"},
      {"field_sets",
       "list of {max_speed_mps, protective: [[x, y], ...], warning: [[x, y], ...]} (m, scanner "
       "frame): the first set whose max_speed_mps is at least the commanded speed is active"}},
     MakeSafetyField});

}  // namespace
}  // namespace linesim::safety
