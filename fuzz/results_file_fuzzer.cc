// The results.csv reader of `linesim sweep --resume` (sweep/results_file.*):
// the input is the results file's text, resumed against the shipped
// scenarios/sweeps/master_step.yaml (12 runs). ResultsFile::Resume's
// contract: rows that do not match the plan are dropped, a header that is not
// this sweep's is a std::runtime_error; nothing else escapes.
//
// LINESIM_FUZZ_SEED_DIR=DIR: writes a seed results.csv (the header, rows as
// FormatRow writes them, a failed row, a line cut off by a kill) into DIR
// and exits; tools/fuzz.sh makes the seed corpus with it.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>

#include "fuzz/fuzz_support.h"
#include "sweep/results_file.h"
#include "sweep/run_plan.h"
#include "sweep/sweep_spec.h"

namespace {

const linesim::sweep::SweepSpec& Spec() {
  static const linesim::sweep::SweepSpec spec = linesim::sweep::LoadSweepSpec(
      std::string(LINESIM_SOURCE_DIR) + "/scenarios/sweeps/master_step.yaml");
  return spec;
}

void WriteSeed(const std::string& dir) {
  using namespace linesim::sweep;
  const SweepSpec& spec = Spec();
  std::string text = JoinCsvLine(ResultsHeader(spec)) + "\n";
  for (std::int64_t id = 0; id < 4; ++id) {
    const RunSpec run = PlanRun(spec, id);
    RunOutcome o;
    o.id = id;
    o.seed = run.seed;
    o.status = id == 2 ? RunStatus::kFailed : RunStatus::kOk;
    o.metrics.assign(spec.metrics.size(),
                     id == 2 ? std::numeric_limits<double>::quiet_NaN() : 0.001 * (id + 1));
    if (id == 2) o.error = "chassis: \"constraint\" violated, at t = 1.5 s";
    o.wall_s = 0.25 * (id + 1);
    text += FormatRow(run, o);
  }
  text += "4,0.0005,gauss_sei";  // cut off by a kill
  std::ofstream(dir + "/results.csv", std::ios::binary) << text;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* seed_dir = std::getenv("LINESIM_FUZZ_SEED_DIR")) {
    WriteSeed(seed_dir);
    std::exit(0);
  }
  (void)Spec();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string file = linesim::fuzz::TempDir() + "/results.csv";
  linesim::fuzz::WriteFile(file, data, size);
  try {
    linesim::sweep::ResultsFile f = linesim::sweep::ResultsFile::Resume(file, Spec());
    // What a resumed sweep does with it at the end.
    f.SortByRunId();
    (void)f.Table(Spec());
  } catch (const std::runtime_error&) {
  }
  return 0;
}
