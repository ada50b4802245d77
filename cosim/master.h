#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "cosim/algorithm.h"
#include "cosim/run_error.h"
#include "cosim/system.h"
#include "cosim/time.h"

namespace linesim::cosim {

/// Step rejection (scenario key master.retry). When a unit returns
/// StepResult::kDiscard, every unit that took part in the step is restored
/// to its start (Unit::SaveState / RestoreState, saved before each step
/// only when this is on) and the step is tried again, smaller: the largest
/// divisor of the master step at most `shrink` times the step that was
/// discarded, so that the master's communication points stay start + k h.
/// After each accepted step the step grows by `grow` (again a divisor of
/// the master step) back to the master step. A step below `min_step` fails
/// the run, naming the unit, the time and its cause. Deterministic: the
/// sequence of steps depends only on which steps the units discard.
/// Observers still see the system at the master's steps only. Units slower
/// than the master (a multiple of its step) keep their step: a discard of
/// theirs cannot be retried and fails the run.
struct RetryOptions {
  bool enabled = false;
  TimeNs min_step = 1'000;  // 1 us
  double shrink = 0.5;      // in (0, 1)
  double grow = 2.0;        // >= 1
};

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
  RetryOptions retry;
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
  /// Each names the unit, the time, the phase and the cause (RunError::
  /// message says it in one sentence).
  std::vector<RunError> errors;
  /// With master.retry: steps a unit discarded (each was retried smaller),
  /// and the smallest step taken (the master step when none was rejected).
  std::int64_t rejected_steps = 0;
  TimeNs smallest_step = 0;
  /// Non-empty when a unit asked to end the simulation before the stop
  /// time (Unit::stop_request): the run ended normally at end_time, after
  /// the step in which it asked; "unit 'name' (type): why".
  std::string ended_by;
  /// Every error's message, joined by "; " (empty when there is none).
  std::string ErrorText() const;
};

/// The co-simulation master: the execution side (time, multirate by
/// integer decimation of the base step, initial value propagation, the
/// NaN/Inf guard, step rejection and retry, errors, observers) around a
/// StepAlgorithm (Jacobi or Gauss-Seidel) that orders one communication
/// step.
class Master : private StepContext {
 public:
  /// Builds the system if needed and checks the steps; throws ConfigError
  /// listing every problem.
  Master(System& system, MasterOptions options);
  ~Master() override;

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
  const StepAlgorithm& algorithm() const { return *algorithm_; }
  TimeNs time() const { return time_; }
  /// Communication step of unit i as a multiple of the base step.
  std::int64_t decimation(std::size_t unit) const { return decimation_[unit]; }
  /// Wall time spent in each unit (Setup, Initialize, DoStep, UpdateOutputs),
  /// in seconds, one entry per unit from Start() on (which zeroes them);
  /// zero without `profile`. DoStep and UpdateOutputs are timed at one base
  /// step in 31 and scaled: an estimate (reading the clock at every unit
  /// step cost 2-3 % of a run).
  const std::vector<double>& unit_wall_seconds() const { return unit_wall_seconds_; }
  /// Wall time of Start, every Step and Finish together (units included);
  /// zero without `profile`.
  double total_wall_seconds() const { return total_wall_seconds_; }
  /// The timed base steps (one in 31), measured whole and unscaled: their
  /// wall time (transfers, checks and observers included), the time at least
  /// one unit was running in them (the union of the units' intervals: with
  /// threads, overlapping units count once), and each unit's own time in
  /// them. Busy <= step by construction (every unit interval lies inside its
  /// step), so 1 - busy / step is the master's and observers' share in
  /// [0, 1]; without threads the units' own times add up to busy exactly.
  double sampled_step_seconds() const { return sampled_step_seconds_; }
  double sampled_busy_seconds() const { return sampled_busy_seconds_; }
  const std::vector<double>& sampled_unit_seconds() const { return sampled_unit_seconds_; }
  /// With master.retry: the step the master takes next (a divisor of the
  /// base step; the base step when nothing was discarded lately).
  TimeNs current_step() const { return current_step_; }

 private:
  // StepContext: what the algorithm calls.
  void TransferInto(std::size_t u) override;
  void TransferFrom(std::size_t u) override;
  bool UpdateOutputs(std::size_t u) override;
  StepResult StepUnit(std::size_t u) override;
  bool CheckOutputs(std::size_t u) override;

  bool AtPoint(std::size_t u) const {
    return plan_first_ ? step_index_ % decimation_[u] == 0 : decimation_[u] == 1;
  }
  /// Advances one base step from t with retries (master.retry on).
  bool StepWithRetry(TimeNs t);
  /// After an accepted step: the first due unit (dependency order) that
  /// asked to end the run, recorded in ended_by_; true when one did.
  bool StopRequested();
  /// Plans the communication step from tau by dt (first: tau is a base point).
  void Plan(TimeNs tau, TimeNs dt, bool first);
  /// The largest divisor of the base step <= limit, or 0 when none is.
  TimeNs DivisorAtMost(TimeNs limit) const;
  void RecordPendingErrors();
  void PropagateInitialValues();
  /// Link l through its resolved storage (Reals; the rest through
  /// TransferChecked). True when the destination's value changed.
  bool Transfer(std::size_t l);
  /// A link through the tables' typed, checked accessors: the integers,
  /// booleans and strings, and a real link whose array end no longer has
  /// the size it had at construction (the accessors throw what they say).
  bool TransferChecked(const Link& link);
  bool CheckUnitOutputs(std::size_t u, TimeNs t, RunPhase phase);
  void RecordError(std::size_t u, TimeNs t, RunPhase phase, std::string_view phase_text,
                   std::string cause, std::string variable = {});
  /// Initialize with profiling; a failure is recorded and returns false.
  bool InitializeUnit(std::size_t u);
  void Notify(TimeNs t);
  /// A unit's DoStep or UpdateOutputs on a timed step starts / ends.
  std::int64_t UnitCallStarts();
  void UnitCallEnds(std::size_t u, std::int64_t started_ns);
  friend class UnitCallTimer;

  System& system_;
  MasterOptions options_;
  std::unique_ptr<StepAlgorithm> algorithm_;
  std::vector<Observer*> observers_;
  std::vector<std::int64_t> decimation_;
  // Each link with its ends' storage, resolved at construction, so that a transfer
  // reads the values and nothing of the variables' descriptions (a fleet's
  // transfers ran out of cache on those).
  struct ResolvedLink {
    std::size_t from_unit = 0, to_unit = 0;
    VarType type = VarType::kReal;
    VariableTable::RealSlot from;
    VariableTable::WritableRealSlot to;
    std::ptrdiff_t from_index = -1, to_index = -1;
  };
  std::vector<ResolvedLink> resolved_;
  std::vector<std::vector<std::size_t>> links_into_;  // per destination unit
  std::vector<std::vector<std::size_t>> links_from_;  // per source unit
  std::vector<bool> has_feedthrough_;                 // some output depends on an input
  std::vector<std::size_t> due_at_point_;             // due at the base point
  std::vector<std::size_t> every_step_;               // decimation 1, dependency order
  std::vector<double> unit_wall_seconds_;
  std::vector<double> sampled_unit_seconds_;
  double sampled_step_seconds_ = 0;
  double sampled_busy_seconds_ = 0;
  // The timed steps' busy union: units running now (threads may overlap)
  // and since when; guarded by busy_mutex_ (taken on timed steps only).
  std::mutex busy_mutex_;
  int units_running_ = 0;
  std::int64_t busy_since_ns_ = 0;
  std::vector<RunError> errors_;
  // The communication step being taken (StepContext's view).
  const std::vector<std::size_t>* plan_due_ = &due_at_point_;
  TimeNs plan_t_ = 0;
  TimeNs plan_dt_ = 0;
  bool plan_first_ = true;
  // Per unit, filled during a step: its result and why.
  struct Pending {
    StepResult result = StepResult::kOk;
    std::string cause;
    std::string variable;
  };
  std::vector<Pending> pending_;
  // master.retry
  std::vector<UnitState> saved_;
  std::vector<TimeNs> divisors_;  // of the base step, ascending
  TimeNs current_step_ = 0;
  TimeNs smallest_step_ = 0;
  std::int64_t rejected_steps_ = 0;
  double total_wall_seconds_ = 0;
  TimeNs time_ = 0;
  std::int64_t step_index_ = 0;
  // Whether this base step's unit steps are timed (one in kProfileEvery).
  bool profile_step_ = false;
  bool started_ = false;
  bool failed_ = false;
  std::string ended_by_;
  // With master.retry: where a stop request inside a base step ended it.
  TimeNs stopped_at_ = 0;
};

}  // namespace linesim::cosim
