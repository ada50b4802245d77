#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "cosim/time.h"

namespace linesim::cosim {

/// What was going on when a run failed.
enum class RunPhase {
  kSetup,          // Unit::Setup
  kInitialize,     // Initialize, initial value propagation, the guard after it
  kStep,           // DoStep (an error, an exception, a discard that could not be retried)
                   // and the NaN/Inf guard on the outputs it produced
  kUpdateOutputs,  // UpdateOutputs at a communication point and the guard after it
  kRetry,          // saving or restoring unit states for master.retry
  kTerminate,      // Unit::Terminate
  kObserver,       // an observer refused the run (a recording interval off the steps)
  kRecording,      // the signals file could not be written
  kMetric,         // a metric's value is not finite
  kScenario,       // the scenario (with a sweep run's overrides) was refused
};
/// "setup", "initialize", "step", "update_outputs", "retry", "terminate",
/// "observer", "recording", "metric", "scenario": the names summaries use.
std::string_view ToString(RunPhase phase);

/// One reason a run failed, as data: who, when, doing what, on which
/// variable, why; and the same as one human sentence.
struct RunError {
  /// The unit's instance name and type; empty when no unit is to blame.
  std::string unit;
  std::string unit_type;
  /// Simulated time of the failing step's start (or of the check); none
  /// when the failure is not at a time (a refused scenario).
  std::optional<TimeNs> time;
  RunPhase phase = RunPhase::kStep;
  /// The variable concerned ("y", "ranges[3]", a parameter, a metric's
  /// name); empty when there is none.
  std::string variable;
  /// Why, without the unit's name and the time (the other fields say them).
  std::string cause;
  /// The whole sentence: "unit 'u' (type) at t = 0.5 s: cause", with the
  /// phase where the master adds it ("initialize failed: ...").
  std::string message;
};

/// A unit's failure. `cause` may start with the unit's own name ("unit 'u'
/// (type): ..." as units say it when used alone): it is taken off, so that
/// the unit is named once. `phase_text` is the phase as the message says
/// it ("initialize failed"), empty for none.
RunError MakeUnitRunError(std::string unit, std::string unit_type, TimeNs time, RunPhase phase,
                          std::string_view phase_text, std::string cause,
                          std::string variable = {});

/// A failure that is no unit's: the message is "<what> at t = ... s: cause"
/// (or "<what>: cause" without a time), e.g. what = "observer".
RunError MakeRunError(std::optional<TimeNs> time, RunPhase phase, std::string_view what,
                      std::string cause, std::string variable = {});

}  // namespace linesim::cosim
