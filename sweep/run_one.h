#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "cosim/run_error.h"
#include "sweep/run_plan.h"
#include "sweep/sweep_spec.h"

namespace linesim::sweep {

enum class RunStatus {
  kOk,
  kFailed,       // refused override or numerical failure: a row with its error
  kInterrupted,  // stopped from outside: no row, a resumed sweep runs it again
};

/// What one run gave: the sweep's metrics in its order (NaN when it failed),
/// the error text (every message, one line) and the first error as data,
/// the scenario seed and the wall time.
struct RunOutcome {
  std::int64_t id = 0;
  std::uint64_t seed = 0;
  RunStatus status = RunStatus::kFailed;
  std::vector<double> metrics;
  std::string error;
  /// The first failure's fields (unit, time, phase, variable, cause); its
  /// message is `error`. Default (phase step, all empty) when ok.
  cosim::RunError failure;
  double wall_s = 0;
  /// Every file the run read (config/input_files.h): absolute path ->
  /// SHA-256 of the bytes it read. A refused scenario's too: its refusal
  /// is as much the files' doing as a result is.
  std::map<std::string, std::string> inputs;
};

/// Builds the base scenario with the run's overrides and runs it to the
/// end, without recording signals. Never throws: every problem becomes a
/// failed outcome with its message. `stop` is polled between master steps.
RunOutcome ExecuteRun(const SweepSpec& spec, const RunSpec& run,
                      const std::atomic<bool>* stop = nullptr);

}  // namespace linesim::sweep
