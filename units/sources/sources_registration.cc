// Registers the sources family's unit types (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/sources/step_signal.h"

namespace linesim::sources {
namespace {

using config::Child;
using config::JoinPath;
using config::UnitBuildContext;
using config::YamlReader;

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

const config::UnitTypeRegistrar kStepSignal(
    {sources::StepSignalUnit::kTypeName,
     "piecewise-constant signal: commands and disturbances as steps in time",
     "",
     {{"count", "number of channels (default 1)"},
      {"unit", "unit of measure of the output, e.g. V or N.m (default 1)"},
      {"steps", "list of {time_s, value}: value (one number, or one per channel) from time_s on"}},
     MakeStepSignal});

}  // namespace
}  // namespace linesim::sources
