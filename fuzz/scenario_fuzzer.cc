// The scenario loader with --set: the input is a scenario file's text; its
// lines "#set PATH=VALUE" (YAML comments) are passed as --set arguments.
// LoadScenario reads, checks and builds the whole system (robot, scene,
// sensors, every unit) but does not run it. Its contract: a problem is a
// config::ScenarioError, nothing else escapes.
#include <cstddef>
#include <cstdint>
#include <string>

#include "config/scenario_error.h"
#include "fuzz/fuzz_support.h"
#include "loader/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Beside the shipped scenarios' folder layout: relative model paths
  // resolve against the temporary folder.
  const std::string file = linesim::fuzz::TempDir() + "/scenario.yaml";
  linesim::fuzz::WriteFile(file, data, size);
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    linesim::loader::Scenario s = linesim::loader::LoadScenario(file, linesim::fuzz::SetArgs(text));
  } catch (const linesim::config::ScenarioError&) {
  }
  return 0;
}
