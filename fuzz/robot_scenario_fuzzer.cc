// Robot scenarios with robots, workers and safety fields, loaded and run:
// the input is a scenario file's text (seeded with worker_crossing.yaml
// and fleet_line.yaml), its lines "#set PATH=VALUE" passed as --set
// arguments. What this adds to fuzz_scenario, which only loads: the units
// run, so that a value the loader lets through (a time that overflows its
// conversion, a worker inside a robot, a degenerate field) shows as the
// crash, sanitizer report or exception it causes at run time. Its
// contract: loading throws only config::ScenarioError; a run's failures
// are RunErrors in its result, nothing escapes.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "config/scenario_error.h"
#include "cosim/master.h"
#include "fuzz/fuzz_support.h"
#include "loader/scenario.h"

namespace {

// Bounds on one input's work (the harness runs under a 30 s timeout with
// ASan): a short run of at most kMaxSteps base steps, and none for a
// system of more than kMaxUnits units (loading it is checked all the same;
// a larger fleet runs the same code).
constexpr const char* kDuration = "duration_s=0.1";
constexpr int kMaxSteps = 50;
constexpr std::size_t kMaxUnits = 300;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string file = linesim::fuzz::TempDir() + "/robots.yaml";
  linesim::fuzz::WriteFile(file, data, size);
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> sets = linesim::fuzz::SetArgs(text);
  sets.emplace_back(kDuration);
  linesim::loader::Scenario s;
  try {
    s = linesim::loader::LoadScenario(file, sets);
  } catch (const linesim::config::ScenarioError&) {
    return 0;
  }
  if (!s.robot || s.system->unit_count() > kMaxUnits) return 0;
  s.master->Start();
  for (int k = 0; k < kMaxSteps && s.master->Step(); ++k) {
  }
  (void)s.master->Finish();
  return 0;
}
