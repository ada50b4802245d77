#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "sweep/run_one.h"
#include "sweep/run_plan.h"
#include "sweep/sweep_spec.h"

namespace linesim::sweep {

/// Called once per finished run (never for an interrupted one), one call at
/// a time, in completion order.
using OnRunDone = std::function<void(const RunSpec&, const RunOutcome&)>;

/// Runs the runs `ids` (planned one by one as they start, so a sweep of
/// millions holds only their ids) on `jobs` threads, each taking the next
/// run when it is free.
/// Runs share nothing mutable: each builds its own system from the files.
/// Once `stop` is set no run starts and running ones stop at their next
/// master step. If `on_done` throws, the remaining runs are stopped and the
/// exception is rethrown here.
void RunOnThreads(const SweepSpec& spec, const std::vector<std::int64_t>& ids, int jobs,
                  std::atomic<bool>& stop, const OnRunDone& on_done);

}  // namespace linesim::sweep
