#include "cosim/run_error.h"

namespace linesim::cosim {

std::string_view ToString(RunPhase phase) {
  switch (phase) {
    case RunPhase::kSetup:
      return "setup";
    case RunPhase::kInitialize:
      return "initialize";
    case RunPhase::kStep:
      return "step";
    case RunPhase::kUpdateOutputs:
      return "update_outputs";
    case RunPhase::kRetry:
      return "retry";
    case RunPhase::kTerminate:
      return "terminate";
    case RunPhase::kObserver:
      return "observer";
    case RunPhase::kRecording:
      return "recording";
    case RunPhase::kMetric:
      return "metric";
    case RunPhase::kScenario:
      return "scenario";
  }
  return "?";
}

RunError MakeUnitRunError(std::string unit, std::string unit_type, TimeNs time, RunPhase phase,
                          std::string_view phase_text, std::string cause, std::string variable) {
  RunError e;
  // Units name themselves in their messages, so that a unit used on its
  // own reports clearly; here the unit is named once, in front.
  const std::string who = "unit '" + unit + "' (" + unit_type + ")";
  const std::string prefix = who + ": ";
  if (cause.starts_with(prefix)) cause.erase(0, prefix.size());
  e.message = who + " at t = " + FormatSeconds(time) + " s: " +
              (phase_text.empty() ? "" : std::string(phase_text) + ": ") + cause;
  e.unit = std::move(unit);
  e.unit_type = std::move(unit_type);
  e.time = time;
  e.phase = phase;
  e.variable = std::move(variable);
  e.cause = std::move(cause);
  return e;
}

RunError MakeRunError(std::optional<TimeNs> time, RunPhase phase, std::string_view what,
                      std::string cause, std::string variable) {
  RunError e;
  e.message = std::string(what) + (time ? " at t = " + FormatSeconds(*time) + " s" : "") + ": " +
              cause;
  e.time = time;
  e.phase = phase;
  e.variable = std::move(variable);
  e.cause = std::move(cause);
  return e;
}

}  // namespace linesim::cosim
