// The sweep file reader: the input is a sweep file's text, in a folder
// `sweeps/` beside links to the shipped scenarios (as scenarios/sweeps/ sits
// beside them), so `scenario: ../cross_line.yaml` loads the real base
// scenario. LoadSweepSpec's contract: a problem is a config::ScenarioError.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "config/scenario_error.h"
#include "fuzz/fuzz_support.h"
#include "sweep/run_plan.h"
#include "sweep/sweep_spec.h"

namespace fs = std::filesystem;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const fs::path dir = linesim::fuzz::TempDir();
  fs::create_directories(dir / "sweeps");
  for (const auto& e : fs::directory_iterator(fs::path(LINESIM_SOURCE_DIR) / "scenarios")) {
    if (e.path().extension() == ".yaml") fs::create_symlink(e.path(), dir / e.path().filename());
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string file = linesim::fuzz::TempDir() + "/sweeps/sweep.yaml";
  linesim::fuzz::WriteFile(file, data, size);
  try {
    const linesim::sweep::SweepSpec spec = linesim::sweep::LoadSweepSpec(file);
    // What a sweep does next with a spec it accepted: plan the runs.
    const std::int64_t n = linesim::sweep::RunCount(spec);
    for (std::int64_t id = 0; id < n && id < 4; ++id) (void)linesim::sweep::PlanRun(spec, id);
  } catch (const linesim::config::ScenarioError&) {
  }
  return 0;
}
