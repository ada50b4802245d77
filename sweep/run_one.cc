#include "sweep/run_one.h"

#include <chrono>
#include <limits>

#include "cosim/observers.h"
#include "loader/scenario.h"

namespace linesim::sweep {

namespace {

std::string OneLine(std::string text) {
  // A row is one line: the issues of a refused scenario go side by side.
  for (std::size_t at = text.find('\n'); at != std::string::npos; at = text.find('\n', at)) {
    text.replace(at, 1, "; ");
  }
  return text;
}

}  // namespace

RunOutcome ExecuteRun(const SweepSpec& spec, const RunSpec& run, const std::atomic<bool>* stop) {
  RunOutcome out;
  out.id = run.id;
  out.seed = run.seed;
  out.metrics.assign(spec.metrics.size(), std::numeric_limits<double>::quiet_NaN());
  const auto wall0 = std::chrono::steady_clock::now();
  const auto finish = [&](RunStatus status, std::string error) {
    out.status = status;
    out.error = OneLine(std::move(error));
    out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    return out;
  };
  try {
    loader::Scenario s = loader::LoadScenario(spec.scenario, RunOverrides(spec, run));
    out.seed = s.seed;
    std::vector<cosim::MetricSpec> wanted;
    for (const auto& name : spec.metrics) {
      for (const auto& m : s.metrics) {
        if (m.name == name) wanted.push_back(m);
      }
    }
    if (wanted.size() != spec.metrics.size()) {
      return finish(RunStatus::kFailed,
                    "the scenario with this run's overrides lacks a metric of the sweep");
    }
    cosim::MetricsObserver metrics(wanted);
    s.master->AddObserver(&metrics);
    s.master->Start();
    bool interrupted = false;
    while (s.master->Step()) {
      if (stop && stop->load(std::memory_order_relaxed)) {
        interrupted = true;
        break;
      }
    }
    const cosim::RunResult result = s.master->Finish();
    if (interrupted) return finish(RunStatus::kInterrupted, "interrupted");
    if (!result.ok) {
      std::string error;
      for (const auto& e : result.errors) error += (error.empty() ? "" : "; ") + e;
      return finish(RunStatus::kFailed, error);
    }
    const auto values = metrics.Results();
    for (std::size_t i = 0; i < values.size(); ++i) out.metrics[i] = values[i].second;
    // A metric that overflowed fails the run, naming the metric.
    std::string overflow;
    for (const auto& e : metrics.NonFiniteResults()) overflow += (overflow.empty() ? "" : "; ") + e;
    if (!overflow.empty()) return finish(RunStatus::kFailed, overflow);
    return finish(RunStatus::kOk, "");
  } catch (const std::exception& e) {
    return finish(RunStatus::kFailed, e.what());
  } catch (...) {
    return finish(RunStatus::kFailed, "an exception that is not a std::exception");
  }
}

}  // namespace linesim::sweep
