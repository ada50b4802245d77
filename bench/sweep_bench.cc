// Sweep throughput on this machine: the shipped belt-speed x compensation
// sweep (cross_line, 10 points x 2 repeats of 20 s) run through the sweep
// executor with 1 and 2 jobs, as `linesim sweep --jobs N` runs it, without
// writing files.
//
// Counters: runs_per_s = finished runs per wall second; rtf = simulated
// seconds of all runs per wall second (the sweep's aggregate real-time
// factor). The speed-up of 2 jobs is the ratio of their runs_per_s.
#include <benchmark/benchmark.h>

#include <atomic>
#include <string>
#include <vector>

#include "loader/scenario.h"
#include "sweep/executor.h"
#include "sweep/run_plan.h"
#include "sweep/sweep_spec.h"

namespace {

void BM_Sweep(benchmark::State& state) {
  const linesim::sweep::SweepSpec spec = linesim::sweep::LoadSweepSpec(
      LINESIM_SOURCE_DIR "/scenarios/sweeps/belt_speed_compensation.yaml");
  std::vector<std::int64_t> ids;
  for (std::int64_t id = 0; id < linesim::sweep::RunCount(spec); ++id) {
    ids.push_back(id);
  }
  // Every run simulates the base scenario's duration (no parameter changes it).
  const double duration_s =
      linesim::loader::LoadScenario(spec.scenario, linesim::sweep::FixedOverrides(spec)).duration_s;
  const int jobs = static_cast<int>(state.range(0));
  std::int64_t finished = 0, failed = 0;
  for (auto _ : state) {
    std::atomic<bool> stop{false};
    linesim::sweep::RunOnThreads(
        spec, ids, jobs, stop,
        [&](const linesim::sweep::RunSpec&, const linesim::sweep::RunOutcome& outcome) {
          ++finished;
          if (outcome.status != linesim::sweep::RunStatus::kOk) ++failed;
        });
  }
  if (failed > 0) state.SkipWithError("a run of the sweep failed");
  state.counters["runs_per_s"] =
      benchmark::Counter(static_cast<double>(finished), benchmark::Counter::kIsRate);
  state.counters["rtf"] =
      benchmark::Counter(duration_s * static_cast<double>(finished), benchmark::Counter::kIsRate);
}

BENCHMARK(BM_Sweep)
    ->ArgName("jobs")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(3);

}  // namespace
