#pragma once

#include <atomic>
#include <functional>
#include <vector>

#include "sweep/run_one.h"
#include "sweep/run_plan.h"
#include "sweep/sweep_spec.h"

namespace linesim::sweep {

/// Called once per finished run (never for an interrupted one), one call at
/// a time, in completion order.
using OnRunDone = std::function<void(const RunSpec&, const RunOutcome&)>;

/// Runs `runs` on `jobs` threads, each taking the next run when it is free.
/// Runs share nothing mutable: each builds its own system from the files.
/// Once `stop` is set no run starts and running ones stop at their next
/// master step. If `on_done` throws, the remaining runs are stopped and the
/// exception is rethrown here.
void RunOnThreads(const SweepSpec& spec, const std::vector<RunSpec>& runs, int jobs,
                  std::atomic<bool>& stop, const OnRunDone& on_done);

}  // namespace linesim::sweep
