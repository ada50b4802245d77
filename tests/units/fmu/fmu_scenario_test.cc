// The `fmu` unit type through the loader (path relative to the scenario
// file, FMU parameters set from the file, connections checked with file and
// line) and `linesim inspect X.fmu`.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "config/input_files.h"
#include "config/scenario_error.h"
#include "loader/scenario.h"
#include "tests/units/fmu/fmu_test_support.h"

namespace linesim::fmu {
namespace {

namespace fs = std::filesystem;
using test::Scratch;

std::string Scenario(const std::string& fmu_path, const std::string& rate_unit) {
  return "name: fmu_plant\n"
         "duration_s: 1\n"
         "master: {step_s: 0.01}\n"
         "units:\n"
         "  rate:\n"
         "    type: step_signal\n"
         "    parameters: {unit: " +
         rate_unit +
         ", steps: [{time_s: 0, value: 0.3}]}\n"
         "  plant:\n"
         "    type: fmu\n"
         "    parameters: {path: " +
         fmu_path +
         ", k: 2.0, x0: 0.5}\n"
         "connections:\n"
         "  - {from: \"rate.value[0]\", to: plant.u}\n";
}

// The path is relative to the scenario file; k and x0 are the FMU's
// parameters, set like any unit's. The run follows x' = -k x + u's closed
// form x(t) = u/k + (x0 - u/k) e^{-k t}.
TEST(FmuScenario, LoadsAndRunsWithThePathRelativeToTheFile) {
  Scratch s("scenario");
  fs::create_directories(s.path() / "fmus");
  fs::copy_file(test::Fmu("dahlquist"), s / "fmus/dahlquist.fmu");
  std::ofstream(s / "plant.yaml") << Scenario("fmus/dahlquist.fmu", "m/s");
  loader::Scenario sc = loader::LoadScenario(s / "plant.yaml");
  const auto result = sc.master->Run();
  ASSERT_TRUE(result.ok) << result.ErrorText();
  const auto& plant = sc.system->unit(*sc.system->FindUnit("plant"));
  const double exact = 0.3 / 2.0 + (0.5 - 0.3 / 2.0) * std::exp(-2.0);
  EXPECT_NEAR(plant.variables().GetReal(*plant.variables().Find("x")), exact, 1e-14);
}

// Guards a sweep's fingerprint (issue 37): the FMU a scenario names is a
// file its results depend on, recorded by content where it is read, beside
// the scenario file.
TEST(FmuScenario, TheFmuIsRecordedAsAnInputByContent) {
  Scratch s("scenario_inputs");
  fs::create_directories(s.path() / "fmus");
  fs::copy_file(test::Fmu("dahlquist"), s / "fmus/dahlquist.fmu");
  std::ofstream(s / "plant.yaml") << Scenario("fmus/dahlquist.fmu", "m/s");
  const config::InputFileRecord record;
  (void)loader::LoadScenario(s / "plant.yaml");
  const std::string fmu = (s.path() / "fmus/dahlquist.fmu").lexically_normal().string();
  ASSERT_EQ(record.files().count(fmu), 1u);
  EXPECT_EQ(record.files().at(fmu), config::InputDigestNow(fmu));
  EXPECT_EQ(record.files().at(fmu).size(), 64u);
  EXPECT_EQ(record.files().count((s.path() / "plant.yaml").lexically_normal().string()), 1u);
}

TEST(FmuScenario, RefusesAMismatchedUnitAndAMissingFile) {
  Scratch s("scenario_bad");
  fs::create_directories(s.path() / "fmus");
  fs::copy_file(test::Fmu("dahlquist"), s / "fmus/dahlquist.fmu");
  std::ofstream(s / "volts.yaml") << Scenario("fmus/dahlquist.fmu", "V");
  try {
    (void)loader::LoadScenario(s / "volts.yaml");
    FAIL() << "loaded a V output into an m/s input";
  } catch (const config::ScenarioError& e) {
    const std::string all = e.what();
    EXPECT_NE(all.find("units of measure differ: rate.value[0] is in 'V', plant.u is in 'm/s'"),
              std::string::npos)
        << all;
  }
  std::ofstream(s / "missing.yaml") << Scenario("fmus/none.fmu", "m/s");
  try {
    (void)loader::LoadScenario(s / "missing.yaml");
    FAIL() << "loaded a missing FMU";
  } catch (const config::ScenarioError& e) {
    const std::string all = e.what();
    EXPECT_NE(all.find("units.plant.parameters.path"), std::string::npos) << all;
    EXPECT_NE(all.find("fmus/none.fmu: no such FMU file"), std::string::npos) << all;
  }
}

std::string RunCommand(const std::string& command) {
  std::string out;
  FILE* p = ::popen(command.c_str(), "r");
  if (!p) return out;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), p)) out += buffer.data();
  ::pclose(p);
  return out;
}

// `linesim inspect X.fmu`: FMI version, generation tool, capabilities,
// default experiment and the variable table with units.
TEST(FmuScenario, InspectPrintsTheFmu) {
  const std::string out =
      RunCommand(std::string(LINESIM_CLI) + " inspect " + test::Fmu("dahlquist") + " 2>&1");
  EXPECT_NE(out.find("FMI 2.0 co-simulation, model 'dahlquist'"), std::string::npos) << out;
  EXPECT_NE(out.find("generation tool:  linesim tests (hand-written C)"), std::string::npos) << out;
  EXPECT_NE(out.find("canSerializeFMUstate yes"), std::string::npos) << out;
  EXPECT_NE(out.find("default experiment: start 0 s, stop 2 s, step 0.01 s"), std::string::npos)
      << out;
  EXPECT_NE(out.find("der_x_"), std::string::npos) << out;
  EXPECT_NE(out.find("left out"), std::string::npos) << out;
  const std::string bad = RunCommand(std::string(LINESIM_CLI) + " inspect /nonexistent/x.fmu 2>&1");
  EXPECT_NE(bad.find("no such FMU file"), std::string::npos) << bad;
}

// Guards issue 24: an FMU that asks to end the simulation (terminate2:
// fmi2Discard with fmi2Terminated at t_end = 0.355 s) stopped the run as a
// failure. Through the command line: status ok, exit 0, the time reached
// (the end of the master step [0.35, 0.36] s), the reason in summary.json's
// ended_by, and its last value recorded (x = t_end, in the row at 0.36 s).
TEST(FmuScenario, AnFmuThatAsksToTerminateEndsTheRunOk) {
  Scratch dir("terminate");
  const std::string file = dir / "end.yaml";
  std::ofstream(file) << "name: fmu_end\n"
                         "duration_s: 1\n"
                         "master: {step_s: 0.01}\n"
                         "units:\n"
                         "  end:\n"
                         "    type: fmu\n"
                         "    parameters: {path: " +
                             test::Fmu("terminate2") +
                             "}\n"
                             "recording: {interval_s: 0.01, variables: [end.x]}\n";
  const std::string out_dir = dir / "out";
  const std::string out = RunCommand(std::string(LINESIM_CLI) + " run " + file + " --out " +
                                     out_dir + " 2>&1; echo exit=$?");
  EXPECT_NE(out.find("exit=0"), std::string::npos) << out;
  std::ifstream summary_file(out_dir + "/summary.json");
  const std::string summary((std::istreambuf_iterator<char>(summary_file)),
                            std::istreambuf_iterator<char>());
  EXPECT_NE(summary.find("\"status\": \"ok\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"ended_by\": \"unit 'end' (fmu): fmi2DoStep returned fmi2Discard with "
                         "fmi2Terminated = true"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("\"simulated_s\": 0.36"), std::string::npos) << summary;
  std::ifstream csv(out_dir + "/signals.csv");
  std::string line, last;
  while (std::getline(csv, line)) last = line;
  EXPECT_EQ(last, "0.36,0.355") << last;
}

}  // namespace
}  // namespace linesim::fmu
