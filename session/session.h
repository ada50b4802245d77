#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "cosim/master.h"
#include "cosim/observers.h"
#include "loader/scenario.h"
#include "plots/robot_plots.h"

/// One run of a scenario, for every caller: `linesim run`, a sweep's runs,
/// the benches (and a Python face to come). A session loads and checks the
/// scenario with its overrides, runs it with the observers the caller adds
/// and a stop token, and says what the run gave: status, metrics, errors,
/// the summary and the plots. The command line is a thin layer over it.
namespace linesim::session {

/// What one run gave.
struct RunReport {
  /// The master's result (its errors are also in `errors`).
  cosim::RunResult result;
  /// Stopped through the stop token before the end.
  bool interrupted = false;
  double wall_s = 0.0;
  /// The metrics, in the scenario's order (or the order Session::Measure
  /// asked for).
  std::vector<std::pair<std::string, double>> metrics;
  /// Every failure: the master's, a metric that overflowed, and any the
  /// caller adds (AddFailure: an output that could not be written).
  std::vector<cosim::RunError> errors;
  /// What the units warned of (cosim::Unit::Warn: a contact the model does
  /// not resolve), each "unit 'name' (type) at t = T s: what"; they do not
  /// fail the run.
  std::vector<std::string> warnings;

  bool ok() const { return !interrupted && errors.empty(); }
  /// "ok", "failed" or "interrupted" (summary.json's status).
  const char* status() const;
  /// Adds a failure found after the run (phase recording), at its end time.
  void AddFailure(const std::string& cause);
};

class Session {
 public:
  /// Loads `file` with the `--set` overrides; throws config::ScenarioError
  /// listing every problem (nothing has run or been written).
  explicit Session(const std::string& file, const std::vector<std::string>& set = {},
                   const std::map<std::string, std::string>& unit_types = {});
  explicit Session(loader::Scenario scenario);

  const loader::Scenario& scenario() const { return s_; }
  /// Observers are the caller's and must outlive Run.
  void AddObserver(cosim::Observer* observer);
  /// Measures only these metrics, in this order; false (nothing changed)
  /// when the scenario lacks one of them.
  bool Measure(const std::vector<std::string>& names);

  /// Runs to the stop time, or to the first communication point after
  /// `stop` turned true. Once per session: a second call throws
  /// std::logic_error (the units have run; load the scenario again).
  RunReport Run(const std::atomic<bool>* stop = nullptr);

 private:
  loader::Scenario s_;
  std::vector<cosim::MetricSpec> measured_;
  std::unique_ptr<cosim::MetricsObserver> metrics_;  // the master's observer from Run on
};

/// The recorded signals kept in memory (what signals.csv holds, as numbers):
/// a row every `interval` from the start, one column per probe.
class SignalRecorder : public cosim::Observer {
 public:
  SignalRecorder(std::vector<cosim::Probe> probes, cosim::TimeNs interval);
  void OnStart(const cosim::Master& master) override;
  void OnSample(cosim::TimeNs t, const cosim::System& system) override;

  const std::vector<cosim::Probe>& probes() const { return probes_; }
  /// The rows' times (s), and each probe's column.
  const std::vector<double>& time_s() const { return time_s_; }
  const std::vector<std::vector<double>>& columns() const { return columns_; }

 private:
  std::vector<cosim::Probe> probes_;
  cosim::TimeNs interval_, start_ = 0;
  std::vector<double> time_s_;
  std::vector<std::vector<double>> columns_;
};

/// summary.json of a run of `scenario` (the scenario `file` as given):
/// scenario, status, errors, settings, provenance, metrics and timing; the
/// caller adds what it wrote (recording, plots, replay, mcap).
nlohmann::ordered_json Summary(const loader::Scenario& scenario, const std::string& file,
                               const RunReport& report);

/// The plots of a robot run in `dir` from its signals.csv: the robot's and,
/// in a fleet, each other robot's (prefixed with its name). Returns the
/// files written (paths).
std::vector<std::string> WriteRobotPlots(const loader::Scenario& scenario, const std::string& dir,
                                         plots::PlotFormat format);

}  // namespace linesim::session
