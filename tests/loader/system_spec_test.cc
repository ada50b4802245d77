// The typed system description (loader/system_spec.h): what a system file
// and a robot scenario become before anything is built.
#include "loader/system_spec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "models/angle.h"
#include "tests/loader/scenario_test.h"

namespace linesim::loader::testing {
namespace {

std::string Cross() { return std::string(LINESIM_SOURCE_DIR) + "/scenarios/cross_line.yaml"; }

SystemSpec Expand(const std::string& file, RobotInfo& info) {
  YamlReader reader(file);
  const SystemSpec spec = ExpandRobotScenario(YAML::LoadFile(file), reader, info);
  EXPECT_TRUE(reader.ok());
  return spec;
}

// Guards the typed values: what the assembly derives reaches the
// description as numbers, not text, and a file's values stay as it wrote
// them (with their lines), for the unit to convert.
TEST(SystemSpec, TheAssemblyDerivesTypedValues) {
  RobotInfo info;
  const SystemSpec spec = Expand(Cross(), info);
  const UnitSpec* chassis = spec.FindUnit("chassis");
  ASSERT_NE(chassis, nullptr);
  EXPECT_EQ(chassis->type, "chassis");
  // cross_line.yaml: robot.pose.yaw_deg 90, converted once (no text).
  const ParameterValue* yaw = chassis->parameters.Find("initial_yaw");
  ASSERT_NE(yaw, nullptr);
  ASSERT_TRUE(std::holds_alternative<double>(yaw->value()));
  EXPECT_EQ(std::get<double>(yaw->value()), 90.0 * models::kDegToRad);
  // The Rob@Work 3's four wheels (models/robots/raw3.yaml) as a typed list.
  const ParameterValue* wheel_x = chassis->parameters.Find("wheel_x");
  ASSERT_NE(wheel_x, nullptr);
  ASSERT_TRUE(std::holds_alternative<std::vector<double>>(wheel_x->value()));
  EXPECT_EQ(std::get<std::vector<double>>(wheel_x->value()).size(), 4u);
  // The robot file's settings are as the file wrote them.
  const ParameterValue* damping = chassis->parameters.Find("contact_damping");
  ASSERT_NE(damping, nullptr);
  ASSERT_NE(damping->written(), nullptr);
  EXPECT_GT(damping->written()->Mark().line, 0);
  // Where a derived value came from: the key the user wrote.
  const auto origin = spec.origins.find("units.chassis.parameters.initial_x");
  ASSERT_NE(origin, spec.origins.end());
  EXPECT_EQ(origin->second.path, "robot.pose.x_m");
  // The controllers step at the control period (derived from control).
  const UnitSpec* controller = spec.FindUnit("wheel_controller");
  ASSERT_NE(controller, nullptr);
  ASSERT_TRUE(controller->step.has_value());
  EXPECT_EQ(*controller->step, cosim::kNsPerSecond / 50);
  // The scene is read once, by the assembly, and handed on.
  EXPECT_EQ(spec.scene.belts.size(), 1u);
  EXPECT_TRUE(spec.scene_ok);
}

// Guards the round trip `linesim inspect` promises: the description printed
// as a system file reads back into the same description.
TEST(SystemSpec, PrintedDescriptionReadsBackTheSame) {
  RobotInfo info;
  const SystemSpec spec = Expand(Cross(), info);
  const YAML::Node printed = ToYaml(spec);
  YamlReader reader("printed.yaml");
  const SystemSpec again = ReadSystemFile(YAML::Load(YAML::Dump(printed)), reader);
  ASSERT_TRUE(reader.ok());
  ASSERT_EQ(again.units.size(), spec.units.size());
  for (std::size_t i = 0; i < spec.units.size(); ++i) {
    const UnitSpec& a = spec.units[i];
    const UnitSpec& b = again.units[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.type, b.type);
    EXPECT_EQ(a.step, b.step) << a.name;
    for (const auto& [key, value] : a.parameters) {
      const ParameterValue* read = b.parameters.Find(key);
      ASSERT_NE(read, nullptr) << a.name << "." << key;
      // Numbers print as the shortest text that reads back to them.
      if (const auto x = value.Number()) {
        EXPECT_EQ(read->Number(), x) << a.name << "." << key;
      }
    }
  }
  EXPECT_EQ(again.connections.size(), spec.connections.size());
  EXPECT_EQ(again.metrics.size(), spec.metrics.size());
  ASSERT_TRUE(again.recording && again.recording->interval && spec.recording);
  EXPECT_EQ(*again.recording->interval, *spec.recording->interval);
  EXPECT_EQ(again.master.base_step, spec.master.base_step);
  EXPECT_EQ(again.master.stop, spec.master.stop);
}

// Guards the split: what only the file tells is found when it is read,
// before any unit is built (an unknown unit type, a bad connection entry,
// a recording interval that is no multiple of the master step).
TEST(SystemSpec, FileProblemsAreFoundWhenRead) {
  YamlReader reader("bad.yaml");
  const SystemSpec spec = ReadSystemFile(YAML::Load(R"(duration_s: 1
master: {step_s: 0.002}
units:
  a: {type: no_such_type}
  b: {type: step_signal, step_s: 0.004}
connections: [{from: b.output}]
recording: {interval_s: 0.003}
)"),
                                         reader);
  std::string all;
  for (const auto& i : reader.issues()) all += i.key_path + ": " + i.message + "\n";
  EXPECT_NE(all.find("units.a.type: unknown unit type 'no_such_type'"), std::string::npos) << all;
  EXPECT_NE(all.find("connections.0"), std::string::npos) << all;
  EXPECT_NE(all.find("recording.interval_s: expected a whole multiple"), std::string::npos) << all;
  EXPECT_FALSE(spec.units_ok);
  ASSERT_NE(spec.FindUnit("b"), nullptr);
  EXPECT_EQ(spec.FindUnit("b")->step, cosim::kNsPerSecond / 250);
}

// Guards the recording without a list: every output of every unit at the
// interval given (docs/scenarios.md: "default: every output of every
// unit"), not the time column alone.
TEST(SystemSpec, RecordingWithoutAListRecordsEveryOutput) {
  const std::string f = WriteScenario("interval_only.yaml", R"(duration_s: 0.01
units:
  m: {type: dc_motor}
recording: {interval_s: 0.002}
)");
  const Scenario s = LoadScenario(f);
  const Scenario all = LoadScenario(f, {"recording=null"});
  EXPECT_EQ(s.record_interval, 2'000'000);
  ASSERT_FALSE(s.recorded.empty());
  ASSERT_EQ(s.recorded.size(), all.recorded.size());
  for (std::size_t i = 0; i < s.recorded.size(); ++i) {
    EXPECT_EQ(s.recorded[i].label, all.recorded[i].label);
  }
}

}  // namespace
}  // namespace linesim::loader::testing
