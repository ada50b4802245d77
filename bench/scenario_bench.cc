// Real-time factor of whole shipped scenarios: load, build and run through
// the master as `linesim run` does, without writing files.
#include <benchmark/benchmark.h>

#include <string>

#include "cosim/observers.h"
#include "loader/scenario.h"

namespace {

void BM_Scenario(benchmark::State& state, const std::string& file) {
  double simulated_s = 0;
  double unit_share_max = 0;
  for (auto _ : state) {
    state.PauseTiming();
    linesim::loader::Scenario s = linesim::loader::LoadScenario(file);
    linesim::cosim::MetricsObserver metrics(s.metrics);
    s.master->AddObserver(&metrics);
    state.ResumeTiming();
    const auto result = s.master->Run();
    if (!result.ok) {
      state.SkipWithError(result.errors.front().c_str());
      break;
    }
    simulated_s += linesim::cosim::NsToSeconds(result.end_time);
    for (double w : s.master->unit_wall_seconds()) {
      unit_share_max = std::max(unit_share_max, w / s.master->total_wall_seconds());
    }
  }
  // Simulated seconds per wall second (a rate over the timed loop).
  state.counters["rtf"] = benchmark::Counter(simulated_s, benchmark::Counter::kIsRate);
  state.counters["top_unit_share"] = unit_share_max;
}

BENCHMARK_CAPTURE(BM_Scenario, motor_step,
                  std::string(LINESIM_SOURCE_DIR "/scenarios/motor_step.yaml"))
    ->Unit(benchmark::kMillisecond);

}  // namespace
