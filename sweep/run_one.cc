#include "sweep/run_one.h"

#include <chrono>
#include <limits>

#include "config/input_files.h"
#include "session/session.h"

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
  const config::InputFileRecord inputs;
  const auto finish = [&](RunStatus status, std::string error,
                          cosim::RunError failure = cosim::RunError{}) {
    out.inputs = inputs.files();
    out.status = status;
    out.error = OneLine(std::move(error));
    failure.cause = OneLine(std::move(failure.cause));
    failure.message = out.error;
    out.failure = std::move(failure);
    out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    return out;
  };
  try {
    session::Session session(spec.scenario, RunOverrides(spec, run));
    out.seed = session.scenario().seed;
    if (!session.Measure(spec.metrics)) {
      const std::string text = "the scenario with this run's overrides lacks a metric of the sweep";
      return finish(RunStatus::kFailed, text,
                    cosim::MakeRunError(std::nullopt, cosim::RunPhase::kScenario, "", text));
    }
    const session::RunReport report = session.Run(stop);
    if (report.interrupted) return finish(RunStatus::kInterrupted, "interrupted");
    if (!report.result.ok) {
      return finish(RunStatus::kFailed, report.result.ErrorText(),
                    report.errors.empty() ? cosim::RunError{} : report.errors.front());
    }
    for (std::size_t i = 0; i < report.metrics.size(); ++i)
      out.metrics[i] = report.metrics[i].second;
    // A metric that overflowed fails the run, naming the metric.
    if (!report.errors.empty()) {
      std::string text;
      for (const auto& e : report.errors) text += (text.empty() ? "" : "; ") + e.message;
      return finish(RunStatus::kFailed, text, report.errors.front());
    }
    return finish(RunStatus::kOk, "");
  } catch (const std::exception& e) {
    // The scenario with this run's overrides was refused (or could not be
    // built): no unit ran.
    return finish(RunStatus::kFailed, e.what(),
                  cosim::MakeRunError(std::nullopt, cosim::RunPhase::kScenario, "", e.what()));
  } catch (...) {
    const std::string text = "an exception that is not a std::exception";
    return finish(RunStatus::kFailed, text,
                  cosim::MakeRunError(std::nullopt, cosim::RunPhase::kScenario, "", text));
  }
}

}  // namespace linesim::sweep
