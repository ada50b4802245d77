#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "cosim/system.h"
#include "cosim/time.h"

namespace linesim::cosim {

enum class Algorithm { kJacobi, kGaussSeidel };
/// "jacobi" or "gauss_seidel": the names scenarios, summaries and messages use.
std::string_view ToString(Algorithm a);
/// The inverse of ToString; false, leaving *out alone, for any other text.
bool ParseAlgorithm(std::string_view text, Algorithm* out);
std::vector<std::string> AlgorithmNames();

struct MasterOptions {
  Algorithm algorithm = Algorithm::kGaussSeidel;
  TimeNs base_step = 1'000'000;
  TimeNs start = 0;
  TimeNs stop = 1'000'000'000;
  /// Jacobi only: step the units due at one communication point on several
  /// threads. Results do not depend on it.
  int threads = 1;
  /// Measure each unit's wall time (two clock reads per unit step).
  bool profile = true;
};

class Master;

/// Read-only watcher of a run: sees the system after initialization and
/// after every base step. It must not change any unit.
class Observer {
 public:
  virtual ~Observer() = default;
  virtual void OnStart(const Master& master) { (void)master; }
  virtual void OnSample(TimeNs t, const System& system) = 0;
  /// Called once at the end, also after a failure, so that observers can
  /// flush what they have.
  virtual void OnEnd(TimeNs t, bool ok) {
    (void)t;
    (void)ok;
  }
};

struct RunResult {
  bool ok = true;
  TimeNs end_time = 0;  // the last time at which all outputs were valid
  std::int64_t base_steps = 0;
  /// Each names the unit, the time and the cause.
  std::vector<std::string> errors;
};

/// The fixed-step co-simulation master: Jacobi or Gauss-Seidel, multirate by
/// integer decimation of the base step, initial value propagation, and a
/// guard that stops on a NaN or Inf output.
class Master {
 public:
  /// Builds the system if needed and checks the steps; throws ConfigError
  /// listing every problem.
  Master(System& system, MasterOptions options);
  ~Master();

  void AddObserver(Observer* observer) { observers_.push_back(observer); }

  /// Setup, initialize, step to the stop time, terminate. Unit failures do
  /// not throw: they end the run and are returned in RunResult::errors.
  RunResult Run();

  // Stepwise use (tests, embedding): Start() sets up and initializes,
  // Step() advances one base step, Finish() terminates.
  void Start();
  bool Step();
  RunResult Finish();

  const System& system() const { return system_; }
  const MasterOptions& options() const { return options_; }
  TimeNs time() const { return time_; }
  /// Communication step of unit i as a multiple of the base step.
  std::int64_t decimation(std::size_t unit) const { return decimation_[unit]; }
  /// Wall time spent in each unit (Setup, Initialize, DoStep, UpdateOutputs),
  /// in seconds, one entry per unit from Start() on (which zeroes them);
  /// zero without `profile`.
  const std::vector<double>& unit_wall_seconds() const { return unit_wall_seconds_; }
  /// Wall time of Start, every Step and Finish together (units included);
  /// zero without `profile`.
  double total_wall_seconds() const { return total_wall_seconds_; }

 private:
  void PropagateInitialValues();
  bool Transfer(const Link& link);
  bool StepUnit(std::size_t u, TimeNs t, TimeNs dt);
  bool CheckOutputs(std::size_t u, TimeNs t);
  bool UpdateUnitOutputs(std::size_t u, TimeNs t);
  /// "unit 'u' (type) at t = ... s: phase: cause", the unit named once.
  void RecordError(std::size_t u, TimeNs t, const std::string& phase, const std::string& cause);
  /// Initialize with profiling; a failure is recorded and returns false.
  bool InitializeUnit(std::size_t u);
  void Notify(TimeNs t);

  System& system_;
  MasterOptions options_;
  std::vector<Observer*> observers_;
  std::vector<std::int64_t> decimation_;
  std::vector<std::vector<std::size_t>> links_into_;  // per destination unit
  std::vector<std::vector<std::size_t>> links_from_;  // per source unit
  std::vector<bool> has_feedthrough_;                 // some output depends on an input
  struct Arena;                                       // TBB arena of `threads` threads
  std::unique_ptr<Arena> arena_;
  std::vector<std::size_t> due_;
  std::vector<double> unit_wall_seconds_;
  std::vector<std::string> errors_;
  std::vector<std::string> pending_errors_;  // per unit, filled during a step
  double total_wall_seconds_ = 0;
  TimeNs time_ = 0;
  std::int64_t step_index_ = 0;
  bool started_ = false;
  bool failed_ = false;
};

}  // namespace linesim::cosim
