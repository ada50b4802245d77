#include "loader/scenario.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "loader/config_names.h"
#include "loader/scene_file.h"
#include "loader/yaml_files.h"
#include "models/dc_motor_params.h"
#include "scenario_test.h"

namespace linesim::loader {
namespace {

using testing::Has;
using testing::Issues;
using testing::kValidScenario;
using testing::WriteScenario;
namespace fs = std::filesystem;

// Guards the shipped example: it must load, with its units, connections and
// master settings as written in the file.
TEST(LoadScenario, ShippedMotorStepLoads) {
  const Scenario s = LoadScenario(LINESIM_SOURCE_DIR "/scenarios/motor_step.yaml");
  EXPECT_EQ(s.name, "motor_step");
  ASSERT_EQ(s.system->unit_count(), 3u);
  EXPECT_EQ(s.system->connections().size(), 2u);
  EXPECT_EQ(s.master->options().base_step, 1'000'000);
  EXPECT_EQ(s.master->options().stop, 1'500'000'000);
  EXPECT_EQ(s.metrics.size(), 6u);
  // The model file sets the datasheet resistance (maxon RE 40: 0.299 Ohm);
  // the scenario's own gear ratios override the model's.
  const auto& motors = s.system->unit(*s.system->FindUnit("motors")).variables();
  EXPECT_EQ(motors.GetRealElement(*motors.Find("resistance"), 1), 0.299);
  EXPECT_EQ(motors.GetRealElement(*motors.Find("gear_ratio"), 1), 21.0);
}

// Guards the --set contract: values, list items and new leaf keys.
TEST(LoadScenario, OverridesChangeValues) {
  const std::string f = WriteScenario("ov.yaml", kValidScenario);
  const Scenario s = LoadScenario(
      f, {"master.step_s=0.002", "master.algorithm=gauss_seidel",
          "units.motor.parameters.resistance=0.5", "units.supply.parameters.steps.0.value=6"});
  EXPECT_EQ(s.master->options().base_step, 2'000'000);
  EXPECT_EQ(s.master->options().algorithm, cosim::Algorithm::kGaussSeidel);
  const auto& m = s.system->unit(*s.system->FindUnit("motor")).variables();
  EXPECT_EQ(m.GetRealElement(*m.Find("resistance"), 0), 0.5);
  // The supply's one step (at 2 ms, 12 V in the file) now gives 6 V.
  ASSERT_TRUE(s.master->Run().ok);
  const auto& supply = s.system->unit(*s.system->FindUnit("supply")).variables();
  EXPECT_EQ(supply.GetRealElement(*supply.Find("value"), 0), 6.0);
}

// Guards master.retry: off by default; its keys read back (from --set as
// from a file); bad values refused at their keys.
TEST(LoadScenario, MasterRetryOptions) {
  const std::string f = WriteScenario("retry.yaml", kValidScenario);
  EXPECT_FALSE(LoadScenario(f, {}).master->options().retry.enabled);
  // The file has no master.retry map: --set gives the whole value.
  const Scenario s = LoadScenario(
      f, {"master.retry={enabled: true, min_step_s: 0.0001, shrink: 0.25, grow: 4}"});
  const cosim::RetryOptions& r = s.master->options().retry;
  EXPECT_TRUE(r.enabled);
  EXPECT_EQ(r.min_step, 100'000);
  EXPECT_EQ(r.shrink, 0.25);
  EXPECT_EQ(r.grow, 4.0);
  ASSERT_TRUE(s.master->Run().ok);
  const std::string bad = Issues(
      f, {"master.retry={enabled: true, shrink: 1, grow: 0.5, min_step_s: 0.01, tries: 3}"});
  EXPECT_TRUE(Has(bad, "master.retry.shrink")) << bad;
  EXPECT_TRUE(Has(bad, "must be below 1 (a retried step is smaller), got 1")) << bad;
  EXPECT_TRUE(Has(bad, "master.retry.grow")) << bad;
  EXPECT_TRUE(Has(bad, "min_step_s 0.01 s is above the master step 0.001 s")) << bad;
  EXPECT_TRUE(Has(bad, "master.retry.tries")) << bad;
}

// Guards against a typo in --set going unnoticed: it names the closest path.
TEST(LoadScenario, UnknownOverridePathNamesClosest) {
  const std::string f = WriteScenario("ov2.yaml", kValidScenario);
  const std::string a = Issues(f, {"master.stepp_s=0.1"});
  EXPECT_TRUE(Has(a, "master.stepp_s")) << a;
  EXPECT_TRUE(Has(a, "closest: master.step_s")) << a;
  EXPECT_TRUE(Has(a, "set on the command line")) << a;
  const std::string b = Issues(f, {"units.motorz.parameters.resistance=1"});
  EXPECT_TRUE(Has(b, "closest: units.motor")) << b;
  const std::string c = Issues(f, {"units.motor.parameters.resistanse=1"});
  EXPECT_TRUE(Has(c, "units.motor.parameters.resistance")) << c;
  const std::string d = Issues(f, {"connections.5.from=x.y"});
  EXPECT_TRUE(Has(d, "has 1 items")) << d;
  const std::string e = Issues(f, {"no_equals_sign"});
  EXPECT_TRUE(Has(e, "dotted.path=value")) << e;
}

// Guards the "every problem at once, with line and key path" contract.
TEST(LoadScenario, ReportsEveryProblemWithLineAndPath) {
  const std::string f = WriteScenario("many.yaml", R"(name: bad
duration_s: -1
colour: blue
master: {algorithm: simplex, step_s: 0.001}
units:
  supply:
    type: step_signal
    parameters: {count: 1, unit: V}
  motor:
    type: dc_motr
connections:
  - {from: supply.value, to: motor.voltage}
)");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all, f + ":2: duration_s: value -1 is out of range")) << all;
  EXPECT_TRUE(Has(all, f + ":3: colour: unknown key")) << all;
  EXPECT_TRUE(Has(all,
                  "master.algorithm: 'simplex' is not allowed: expected one of jacobi, "
                  "gauss_seidel"))
      << all;
  EXPECT_TRUE(Has(all, f + ":10: units.motor.type: unknown unit type 'dc_motr' (closest: "
                           "dc_motor)"))
      << all;
}

// Guards: a missing required key and a wrong type each name their key path.
TEST(LoadScenario, MissingKeyAndWrongTypeNameTheKey) {
  const std::string f = WriteScenario("missing.yaml", R"(units:
  motor:
    type: dc_motor
    parameters: {count: two, resistance: [1, 2, 3]}
)");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all, "duration_s: missing required key")) << all;
  EXPECT_TRUE(Has(all, "units.motor.parameters.count: expected an integer, got 'two'")) << all;
}

// Guards against a time that cannot be held in int64 nanoseconds escaping
// as an exception instead of an issue at its key.
TEST(LoadScenario, StepTimeBeyondRangeIsAnIssueAtItsKey) {
  const std::string f = WriteScenario("far.yaml", R"(duration_s: 0.01
units:
  supply:
    type: step_signal
    parameters: {steps: [{time_s: 1.0e300, value: 1}]}
)");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all, "units.supply.parameters.steps.0.time_s: value 1.0e300 is out of range"))
      << all;
}

// Guards against times below the 1 ns resolution silently becoming 0 (a
// unit step of 0 is "the master step"; a step time of 0 is the start): every
// time key of a system scenario refuses them at its key.
TEST(LoadScenario, TimesBelowOneNanosecondAreRefusedAtTheirKeys) {
  const std::string f = WriteScenario("tiny_times.yaml", R"(duration_s: 0.01
master: {step_s: 1.0e-12}
units:
  supply:
    type: step_signal
    step_s: 1.0e-10
    parameters: {steps: [{time_s: 5.0e-10, value: 1}]}
recording: {interval_s: 2.0e-10}
)");
  const std::string all = Issues(f);
  // The recording's interval is read with the rest of the file, before any
  // unit is built: all four at once.
  for (const char* key :
       {":2: master.step_s", ":6: units.supply.step_s",
        ":7: units.supply.parameters.steps.0.time_s", ":8: recording.interval_s"}) {
    EXPECT_TRUE(Has(all, f + std::string(key) + ": value ")) << key << "\n" << all;
  }
  EXPECT_EQ(std::count(all.begin(), all.end(), '\n') + 1, 4) << all;
  EXPECT_TRUE(Has(all, "below one nanosecond")) << all;
  // Alone, too.
  const std::vector<std::string> good = {"master.step_s=0.001", "units.supply.step_s=0.001",
                                         "units.supply.parameters.steps.0.time_s=0"};
  const std::string rec = Issues(f, good);
  EXPECT_TRUE(Has(rec, f + ":8: recording.interval_s: value 2.0e-10 is below one nanosecond"))
      << rec;
  std::vector<std::string> sets = good;
  sets.push_back("duration_s=1.0e-10");
  const std::string d = Issues(f, sets);
  EXPECT_TRUE(Has(d, "duration_s (set on the command line): value 1.0e-10 is below one nanosecond"))
      << d;
}

// Guards the parameter path: a value of the wrong shape or an unknown name
// is refused with what was expected.
TEST(LoadScenario, ParameterValuesAreChecked) {
  const std::string f = WriteScenario("params.yaml", R"(duration_s: 0.01
units:
  motor:
    type: dc_motor
    parameters: {count: 2, resistance: [1, 2, 3], inductanse: 1, gear_ratio: fast}
)");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all,
                  "units.motor.parameters.resistance: expected a number (for every "
                  "element) or a list of 2 numbers, got a list of 3"))
      << all;
  EXPECT_TRUE(Has(all,
                  "units.motor.parameters.inductanse: unknown parameter of a dc_motor unit; "
                  "closest: units.motor.parameters.inductance"))
      << all;
  EXPECT_TRUE(Has(all, "units.motor.parameters.gear_ratio: expected a number (for every element)"))
      << all;
}

// Guards the unit named in a refused array value: a dimensionless one ("1")
// is not shown as "(1)"; one with a unit still shows it.
TEST(LoadScenario, DimensionlessArrayParameterNamesNoUnit) {
  const std::string f = WriteScenario("dimensionless.yaml", R"(duration_s: 0.01
units:
  motor:
    type: dc_motor
    parameters: {count: 2, gear_ratio: fast, resistance: slow}
)");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all,
                  "units.motor.parameters.gear_ratio: expected a number (for every element) or a "
                  "list of 2 numbers, got 'fast'"))
      << all;
  EXPECT_TRUE(Has(all,
                  "units.motor.parameters.resistance: expected a number (for every element) or a "
                  "list of 2 numbers (Ohm), got 'slow'"))
      << all;
}

// Guards parameters against NaN: it is no number, for a Real parameter
// (the standard message), for a whole array and for one element of it.
TEST(LoadScenario, NanParameterIsRefused) {
  const std::string f = WriteScenario("nan.yaml", kValidScenario);
  const std::string all = Issues(
      f, {"units.motor.parameters.resistance=.nan", "units.motor.parameters.inductance=[.nan]"});
  EXPECT_TRUE(Has(all,
                  "units.motor.parameters.resistance (set on the command line): expected a "
                  "number (for every element) or a list of 1 numbers (Ohm), got '.nan'"))
      << all;
  EXPECT_TRUE(Has(all,
                  "units.motor.parameters.inductance.0 (set on the command line): expected a "
                  "number, got '.nan'"))
      << all;
  // A Real (not array) parameter: the chassis's brake torque, in a robot scenario.
  std::ifstream in(LINESIM_SOURCE_DIR "/scenarios/cross_line.yaml");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string g = WriteScenario(
      "nan_robot.yaml", text + "units:\n  chassis:\n    parameters: {brake_torque: 20}\n");
  const std::string robot = Issues(g, {"units.chassis.parameters.brake_torque=.nan"});
  EXPECT_TRUE(Has(robot,
                  "units.chassis.parameters.brake_torque (set on the command line): expected a "
                  "number, got '.nan'"))
      << robot;
}

// Guards unit names: they are the first part of every connection path, so
// a dot or a dash in one is refused at its line.
TEST(LoadScenario, InvalidUnitNameIsRefused) {
  const std::string f = WriteScenario("name.yaml", R"(duration_s: 0.01
units:
  left-motor:
    type: dc_motor
)");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all, f + ":3: units.left-motor: unit name 'left-motor' is not valid")) << all;
}

// Guards master checks through the loader: a unit step that is not a
// multiple of the master step points at that unit's step_s line.
TEST(LoadScenario, UnitStepProblemPointsAtItsLine) {
  const std::string f = WriteScenario("step.yaml", R"(duration_s: 0.01
units:
  motor:
    type: dc_motor
    step_s: 0.0015
)");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all, f + ":5: units.motor.step_s: unit 'motor' step 0.0015 s is not an integer "
                           "multiple of the master step 0.001 s"))
      << all;
}

// Guards: a duration that is not a whole number of master steps is refused
// at duration_s (the run could not end exactly at the requested time).
TEST(LoadScenario, DurationOffTheMasterStepsIsRefused) {
  const std::string f = WriteScenario("dur.yaml", R"(duration_s: 0.0105
units:
  motor:
    type: dc_motor
)");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all, f + ":1: duration_s: duration 0.0105 s is not a whole number of master "
                           "steps (master.step_s = 0.001 s)"))
      << all;
}

// Guards the range check before time zero: the unit's own parameter check
// (a resistance must be positive) reaches the user with the key path.
TEST(LoadScenario, OutOfRangeParameterIsRefusedBeforeTimeZero) {
  const std::string f = WriteScenario("range.yaml", R"(duration_s: 0.01
units:
  motor:
    type: dc_motor
    parameters: {count: 2, resistance: [0.3, -1]}
)");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all, f + ":5: units.motor.parameters.resistance.1:")) << all;
}

// Guards the connection checks through the loader: the system's problems
// point at the line of the connection.
TEST(LoadScenario, ConnectionProblemsPointAtTheirLine) {
  const std::string f = WriteScenario("conn.yaml", R"(duration_s: 0.01
units:
  supply:
    type: step_signal
    parameters: {count: 3, unit: A}
  motor:
    type: dc_motor
connections:
  - {from: supply.value, to: motor.voltage}
  - {from: supply.valu, to: motor.load_torque}
  - {from: supply, to: motor.voltage}
)");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all, f + ":9: connections.0: connection supply.value -> motor.voltage: "
                           "array size mismatch"))
      << all;
  EXPECT_TRUE(Has(all, "units of measure differ")) << all;
  EXPECT_TRUE(Has(all, f + ":10: connections.1:")) << all;
  EXPECT_TRUE(Has(all, "has no variable 'valu' (closest: value)")) << all;
  EXPECT_TRUE(Has(all, f + ":11: connections.2: 'supply' is not an endpoint")) << all;
}

// Guards model files: an unknown name lists the closest shipped model.
TEST(LoadScenario, UnknownModelFileNamesClosest) {
  const std::string f = WriteScenario("model.yaml", R"(duration_s: 0.01
units:
  motor:
    type: dc_motor
    parameters: {model: maxon_re40_14887}
)");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all, "units.motor.parameters.model: no model file")) << all;
  EXPECT_TRUE(Has(all, "closest: maxon_re40_148877")) << all;
  // A path that is a folder is an issue at the key, not a crash.
  const std::string g = WriteScenario("model_dir.yaml", R"(duration_s: 0.01
units:
  motor:
    type: dc_motor
    parameters: {model: ./}
)");
  EXPECT_TRUE(Has(Issues(g), "units.motor.parameters.model: cannot read model file")) << Issues(g);
}

// Guards model files' own problems: named at the model file's line and key
// (not the scenario's), also when the unit's check refuses a value.
TEST(LoadScenario, ModelFileProblemsNameTheModelFile) {
  const std::string model = WriteScenario("bad_motor.yaml", R"(description: broken motor
resistance: -1
inductanse: 1
gear_ratio: .nan
)");
  const std::string f = WriteScenario("uses_bad_motor.yaml", R"(duration_s: 0.01
units:
  motor:
    type: dc_motor
    parameters: {model: )" + fs::path(model).filename().string() +
                                                                 "}\n");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all, model + ":3: inductanse: unknown parameter of a dc_motor unit")) << all;
  EXPECT_TRUE(Has(all, model + ":4: gear_ratio: expected a number")) << all;
  EXPECT_TRUE(Has(all, model + ":2: resistance.0:")) << all;
  EXPECT_FALSE(Has(all, "set on the command line")) << all;
}

// Guards the shipped motor model files: each loads in both motor modes (a
// model file describes motor and gearbox, never the load, so it has no
// full-mode-only keys).
TEST(LoadScenario, ModelFilesLoadInBothModes) {
  for (const char* model : {"maxon_re40_148877", "husky_drive"}) {
    for (const char* mode : {"full", "current_only"}) {
      const std::string f = WriteScenario("models.yaml", std::string(R"(duration_s: 0.01
units:
  motor:
    type: dc_motor
    parameters: {model: )") + model + ", mode: " + mode + "}\n");
      EXPECT_NO_THROW(LoadScenario(f)) << model << " " << mode << ": " << Issues(f);
    }
  }
}

// Guards the bare-motor model file against drifting from the unit's
// defaults: both transcribe the same datasheet (maxon RE 40 148877).
TEST(LoadScenario, BareMotorModelFileIsTheDefaultDatasheet) {
  const std::string f = WriteScenario("re40.yaml", R"(duration_s: 0.01
units:
  motor:
    type: dc_motor
    parameters: {model: maxon_re40_148877}
)");
  const Scenario s = LoadScenario(f);
  const auto& v = s.system->unit(*s.system->FindUnit("motor")).variables();
  const auto first = [&](const char* name) { return v.GetRealElement(*v.Find(name), 0); };
  const models::DcMotorParams p;
  EXPECT_DOUBLE_EQ(first("resistance"), p.resistance_ohm);
  EXPECT_DOUBLE_EQ(first("inductance"), p.inductance_h);
  EXPECT_DOUBLE_EQ(first("torque_constant"), p.torque_constant_nm_per_a);
  EXPECT_DOUBLE_EQ(first("rotor_inertia"), p.rotor_inertia_kgm2);
  EXPECT_NEAR(first("viscous_friction"), p.viscous_friction_nms_per_rad,
              1e-4 * p.viscous_friction_nms_per_rad);
  EXPECT_EQ(first("gear_ratio"), 1.0);
}

// Guards YAML that parses but would mean something else: a key written
// twice in one map (a lookup finds the first, the second would be ignored),
// a second document after "---" and content after a "..." end marker (a
// single-document read drops it). Each is refused at its line. An alias
// used twice is one node, not a duplicate; a file ending in "..." is fine.
// Fuzz finding (fuzz_description, tools/fuzz.sh): a line that starts with
// ',' outside any flow collection made the loader hang, its memory growing
// without bound: yaml-cpp 0.7's LoadAll yields an empty document for it
// forever. The file is refused at once, as a scene file (the fuzzer's input
// as it was found, a NUL byte and all) and as a scenario. Without the fix
// this test does not end (ctest's timeout fails it).
TEST(LoadScenario, TextOutsideAnyDocumentIsRefusedNotAHang) {
  const std::string found =
      std::string(LINESIM_SOURCE_DIR) + "/tests/loader/fuzz_findings/description_leading_comma_hang.yaml";
  try {
    (void)LoadSceneFile(found);
    ADD_FAILURE() << "the scene file was accepted";
  } catch (const ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("text outside any document"), std::string::npos)
        << e.what();
  }
  const std::string comma = WriteScenario("leading_comma.yaml", ", x\nname: t\n");
  EXPECT_TRUE(Has(Issues(comma), comma + ":") && Has(Issues(comma), "not valid YAML: a second YAML document"))
      << Issues(comma);
}

TEST(LoadScenario, DuplicateKeysAndSecondDocumentsAreRefused) {
  const std::string twice =
      WriteScenario("twice.yaml", "name: t\nduration_s: 1\nunits: {}\nduration_s: 2\n");
  const std::string a = Issues(twice);
  EXPECT_TRUE(Has(a, twice + ":4: not valid YAML: key 'duration_s' appears twice in one map "
                             "(first at line 2)"))
      << a;
  const std::string nested = WriteScenario(
      "nested_twice.yaml",
      "name: t\nduration_s: 1\nunits:\n  m: {type: dc_motor, parameters: {resistance: 1, "
      "resistance: 2}}\n");
  EXPECT_TRUE(Has(Issues(nested), "key 'resistance' appears twice")) << Issues(nested);
  const std::string second =
      WriteScenario("second.yaml", "name: t\nduration_s: 1\nunits: {}\n---\nseed: 3\n");
  EXPECT_TRUE(Has(Issues(second), second + ":5: not valid YAML: a second YAML document"))
      << Issues(second);
  const std::string ended =
      WriteScenario("ended.yaml", "name: t\nduration_s: 1\nunits: {}\n...\nseed: 3\n");
  EXPECT_TRUE(Has(Issues(ended), "a second YAML document")) << Issues(ended);
  const std::string fine = WriteScenario(
      "aliases.yaml",
      "name: t\nduration_s: 1\nunits:\n  a: {type: dc_motor, parameters: &p {resistance: 1}}\n"
      "  b: {type: dc_motor, parameters: *p}\n...\n");
  EXPECT_EQ(Issues(fine), "(no error)");
}

// Guards required texts left empty, which would make their item silently
// disappear: a unit type, a connection's end and a metric's signal are each
// refused at their key.
TEST(LoadScenario, EmptyRequiredTextsAreRefusedAtTheirKeys) {
  const std::string type =
      WriteScenario("empty_type.yaml", "name: t\nduration_s: 1\nunits:\n  m: {type: \"\"}\n");
  EXPECT_TRUE(Has(Issues(type), "units.m.type: is empty")) << Issues(type);
  const std::string base =
      "name: t\nduration_s: 0.01\nunits:\n  supply: {type: step_signal, parameters: {unit: V, "
      "steps: [{time_s: 0.002, value: 12}]}}\n  motor: {type: dc_motor}\n";
  const std::string connection = WriteScenario(
      "empty_connection.yaml", base + "connections:\n  - {from: \"\", to: motor.voltage}\n");
  EXPECT_TRUE(Has(Issues(connection), "connections.0.from: is empty")) << Issues(connection);
  const std::string metric =
      WriteScenario("empty_metric.yaml", base + "metrics:\n  - {name: m, of: \"\", reduce: max}\n");
  EXPECT_TRUE(Has(Issues(metric), "metrics.0.of: is empty")) << Issues(metric);
}

// Guards --set through a YAML alias: the anchored value and its alias are
// one node, so setting it through either path would change both; refused
// at the path, naming the anchor's line. A value outside the alias is set
// as written.
TEST(LoadScenario, SetThroughAnAliasIsRefused) {
  const std::string f = WriteScenario("aliased.yaml",
                                      "name: t\nduration_s: 0.01\nunits:\n"
                                      "  a: {type: dc_motor, parameters: &p {resistance: 1.0}}\n"
                                      "  b: {type: dc_motor, parameters: *p}\n");
  const std::string via_alias = Issues(f, {"units.b.parameters.resistance=2"});
  EXPECT_TRUE(Has(via_alias,
                  "units.b.parameters' is a value the file uses again through a YAML "
                  "alias (its anchor at line 4)"))
      << via_alias;
  const std::string via_anchor = Issues(f, {"units.a.parameters.resistance=2"});
  EXPECT_TRUE(Has(via_anchor, "through a YAML alias")) << via_anchor;
  EXPECT_EQ(Issues(f, {"duration_s=0.02"}), "(no error)");
}

// Guards text the outputs cannot carry: a name or description that is not
// valid UTF-8 (here a lone 0xFF byte, and 0xE9, Latin-1's e-acute, without
// its UTF-8 continuation) is refused at its key; real UTF-8 (U+00E9 as
// 0xC3 0xA9) is accepted.
TEST(LoadScenario, TextThatIsNotUtf8IsRefusedAtItsKey) {
  const std::string rest = "duration_s: 0.01\nunits:\n  s: {type: step_signal}\n";
  const std::string bad =
      WriteScenario("latin1.yaml", "name: \"caf\xe9\"\ndescription: \"bad \xff\"\n" + rest);
  const std::string e = Issues(bad);
  EXPECT_TRUE(Has(e, bad + ":1: name: is not valid UTF-8 text")) << e;
  EXPECT_TRUE(Has(e, bad + ":2: description: is not valid UTF-8 text")) << e;
  const std::string good = WriteScenario("utf8.yaml", "name: \"caf\xc3\xa9\"\n" + rest);
  EXPECT_EQ(Issues(good), "(no error)");
}

// Guards file-level failures: a missing file and malformed YAML.
TEST(LoadScenario, UnreadableAndMalformedFiles) {
  EXPECT_TRUE(Has(Issues("/nonexistent/x.yaml"), "cannot read the file"));
  EXPECT_TRUE(Has(Issues(::testing::TempDir()), "is not a file (a folder?)"));
  const std::string f = WriteScenario("broken.yaml", "units: {motor: [1, 2\nduration_s: 1\n");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all, "not valid YAML")) << all;
  EXPECT_TRUE(Has(all, f + ":")) << all;
}

// Guards recording and metrics validation.
TEST(LoadScenario, RecordingAndMetricsAreChecked) {
  const std::string f = WriteScenario("rec.yaml", std::string(kValidScenario) + R"(recording:
  interval_s: 0.0015
  variables: [motor.current, motor.currnt]
metrics:
  - {name: m, of: motor.current, reduce: median}
)");
  const std::string all = Issues(f);
  EXPECT_TRUE(Has(all, "recording.interval_s: expected a whole multiple of master.step_s")) << all;
  EXPECT_TRUE(Has(all, "recording.variables.1:")) << all;
  EXPECT_TRUE(Has(all, "(closest: current)")) << all;
  EXPECT_TRUE(Has(all, "metrics.0.reduce: 'median' is not allowed")) << all;
}

// Guards the providers' registry (loader/assembly/providers.h): each
// provider registers itself from its own file; every one is linked in and
// an unknown name is refused naming them.
TEST(LoadScenario, UnknownProviderIsRefusedNamingTheRegisteredOnes) {
  const std::string cross = LINESIM_SOURCE_DIR "/scenarios/cross_line.yaml";
  std::string e = Issues(cross, {"localization.source=hector"});
  EXPECT_TRUE(Has(e, "expected one of fused, ground_truth, laser, odometry, perfect_match")) << e;
  e = Issues(cross, {"sensing.surface_velocity=optical"});
  EXPECT_TRUE(Has(e, "expected one of fused_flow, ground_truth, none, px4flow")) << e;
}

// Guards `inspect TYPE`: every registered type builds with its defaults.
// Guards issue 24: `--set sensing.surface_velocity=` (no value) ran with the
// default (ground truth) and exit 0, since the override wrote null and the
// reader took it as absent. LoadScenario tells the reader which keys came
// without a value; it refuses them naming the allowed values, whether the
// key is a robot scenario's or a system scenario's, and blanks count as
// nothing; a key no typed reader reads is refused too.
TEST(LoadScenario, SetWithoutValueIsRefusedNamingWhatTheKeyTakes) {
  const std::string cross = LINESIM_SOURCE_DIR "/scenarios/cross_line.yaml";
  std::string e = Issues(cross, {"sensing.surface_velocity="});
  EXPECT_TRUE(Has(e, "sensing.surface_velocity (set on the command line): no value given (--set "
                     "sensing.surface_velocity=): expected one of fused_flow, ground_truth, none, px4flow"))
      << e;
  e = Issues(cross, {"sensing.surface_velocity= "});
  EXPECT_TRUE(Has(e, "sensing.surface_velocity (set on the command line): no value given")) << e;
  const std::string f = WriteScenario("no_value.yaml", kValidScenario);
  e = Issues(f, {"master.step_s="});
  EXPECT_TRUE(Has(e, "master.step_s (set on the command line): no value given (--set "
                     "master.step_s=): expected a time in seconds > 0 and <= 10"))
      << e;
  EXPECT_EQ(Issues(cross, {"sensing.surface_velocity=px4flow"}), "(no error)");
  // A key no typed reader reads (a section, whose null means all its
  // defaults) is refused by LoadScenario itself; an explicit null is not
  // empty.
  e = Issues(cross, {"control="});
  EXPECT_TRUE(Has(e, "control (set on the command line): no value given (--set control=): an "
                     "empty value does not mean the default"))
      << e;
  EXPECT_EQ(Issues(cross, {"control=null"}), "(no error)");
}

TEST(UnitTypes, EveryTypeBuildsWithDefaults) {
  for (const auto& name : UnitTypeNames()) {
    const auto unit = CreateDefaultUnit(name);
    ASSERT_TRUE(unit) << name;
    EXPECT_EQ(unit->type_name(), name);
    EXPECT_GT(unit->variables().size(), 0u);
  }
  EXPECT_THROW(CreateDefaultUnit("dc_motorr"), ScenarioError);
}

// Guards the whole-archive link of the families' registrations: a program
// that links only the loader knows every type, in the names' order.
TEST(UnitTypes, EveryFamilyRegistersItsTypes) {
  for (const char* name : {"belt", "chassis", "dc_motor", "diff_drive_controller", "path_deviation",
                           "path_follower", "step_signal", "wheel_controller"}) {
    EXPECT_NE(FindUnitType(name), nullptr) << name;
  }
  const std::vector<std::string> names = UnitTypeNames();
  EXPECT_TRUE(std::is_sorted(names.begin(), names.end()));
}

// Guards issue 24: a 40 MB scenario made yaml-cpp exhaust 2 GB and report
// std::bad_alloc. A file above kMaxYamlBytes (4 MiB) is refused before it
// is parsed, naming the file and the limit; one byte less is parsed (here:
// YAML comments, so the error is the missing keys, not the size).
TEST(LoadScenario, AFileAboveTheSizeLimitIsRefusedBeforeParsing) {
  const auto file_of = [](const std::string& name, std::uintmax_t bytes) {
    std::string text(bytes, 'x');
    for (std::size_t i = 0; i < text.size(); i += 64) text[i] = '\n';
    text[1] = '#';
    for (std::size_t i = 0; i + 1 < text.size(); ++i) {
      if (text[i] == '\n') text[i + 1] = '#';
    }
    return WriteScenario(name, text);
  };
  const std::string big = file_of("big.yaml", kMaxYamlBytes + 1);
  const std::string e = Issues(big);
  EXPECT_NE(e.find(big), std::string::npos) << e.substr(0, 300);
  EXPECT_NE(e.find("more than the 4 MiB linesim reads from a YAML file"), std::string::npos)
      << e.substr(0, 300);
  const std::string e2 = Issues(file_of("limit.yaml", kMaxYamlBytes));
  EXPECT_EQ(e2.find("MiB"), std::string::npos) << e2.substr(0, 300);
  std::remove(big.c_str());
}

}  // namespace
}  // namespace linesim::loader
