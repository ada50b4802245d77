#pragma once

// Units written in Python (linesim.Unit subclasses), and what a run started
// from Python shares with them: the stop token and an exception that must
// reach the caller (KeyboardInterrupt, SystemExit).
#include <pybind11/pybind11.h>

#include <atomic>
#include <chrono>
#include <optional>
#include <string>

#include "cosim/master.h"

namespace linesim::python {

/// One run started from Python. Its units written in Python and its signal
/// check stop it through `stop` and leave the exception to raise in
/// `pending` (set and read holding the GIL).
struct PythonRun {
  std::atomic<bool> stop{false};
  std::optional<pybind11::error_already_set> pending;

  /// Stops the run at its next communication point; the first exception
  /// is the one raised.
  void Interrupt(pybind11::error_already_set error);
};

/// While it exists, the Python units created on this thread belong to
/// `run` (the scenario's units are created while it loads).
class BuildingRun {
 public:
  explicit BuildingRun(PythonRun* run);
  ~BuildingRun();
  BuildingRun(const BuildingRun&) = delete;
  BuildingRun& operator=(const BuildingRun&) = delete;

 private:
  PythonRun* saved_;
};

/// Ctrl-C during a run: between master steps, at most every
/// kSignalCheckInterval of wall time, runs Python's signal handlers
/// (PyErr_CheckSignals, in the main thread); what they raise
/// (KeyboardInterrupt) stops the run. Not every step: taking the GIL while
/// another Python thread holds it waits for that thread's switch interval.
class SignalCheck : public cosim::Observer {
 public:
  static constexpr std::chrono::milliseconds kSignalCheckInterval{20};

  explicit SignalCheck(PythonRun& run) : run_(run) {}
  void OnSample(cosim::TimeNs t, const cosim::System& system) override;
  /// The check itself, for callers that are not a run's observer (a sweep
  /// waiting for its runs); true when the run was interrupted.
  bool CheckNow();

 private:
  PythonRun& run_;
  std::chrono::steady_clock::time_point last_{};
};

/// Registers the class `cls` as unit type `type` (once per type name);
/// ValueError when the name is taken.
void RegisterPythonUnit(const std::string& type, pybind11::object cls);

}  // namespace linesim::python
