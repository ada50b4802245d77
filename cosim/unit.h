#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/variable_table.h"

namespace linesim::cosim {

enum class StepResult { kOk, kDiscard, kError };

/// A snapshot of one unit: every declared variable plus whatever internal
/// state the unit adds (integrator states, random generator, counters).
struct UnitState {
  std::string type_name;  // a state restores only into a unit of its type
  std::vector<Value> variables;
  std::vector<double> reals;
  std::vector<std::int64_t> integers;
  std::vector<std::string> strings;
};

/// Thrown by a unit for a failure it cannot recover from; the master adds the
/// unit name and time.
class UnitError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  /// With the variable the failure concerns ("x", "ranges[3]"), which run
  /// errors report in a field of their own.
  UnitError(const std::string& what, std::string variable)
      : std::runtime_error(what), variable_(std::move(variable)) {}
  const std::string& variable() const { return variable_; }

 private:
  std::string variable_;
};

/// The FMI-style co-simulation unit. Lifecycle, in order:
///   Setup(start, stop) -> parameters and start values set through the table
///   -> Initialize() (may be called several times while the master
///   propagates initial values) -> repeated {set inputs, DoStep, get outputs}
///   -> Terminate().
/// Outputs are valid after Initialize() and after each DoStep(t, dt), for the
/// time t + dt. Once the master has initialized every unit it locks the
/// tables: a fixed parameter then refuses a new value (VariableTable::Lock).
class Unit {
 public:
  Unit(std::string type_name, std::string instance_name)
      : type_name_(std::move(type_name)), name_(std::move(instance_name)) {}
  virtual ~Unit() = default;
  Unit(const Unit&) = delete;
  Unit& operator=(const Unit&) = delete;

  const std::string& type_name() const { return type_name_; }
  const std::string& name() const { return name_; }
  VariableTable& variables() { return variables_; }
  const VariableTable& variables() const { return variables_; }

  /// Checks parameter values after they are set and before Setup, so that a
  /// scenario is refused before time zero. The default reports every
  /// parameter value that breaks the rule declared with it (see Rule), each
  /// element of an array on its own. Declare single-parameter rules with the
  /// parameter; override only for rules between parameters (a < b, list
  /// lengths that must agree), and start from the base:
  ///
  ///   std::vector<ParameterProblem> CheckParameters() const override {
  ///     auto problems = Unit::CheckParameters();
  ///     if (min_ >= max_) problems.push_back({"max", std::nullopt, "must be > min"});
  ///     return problems;
  ///   }
  virtual std::vector<ParameterProblem> CheckParameters() const;

  virtual void Setup(TimeNs start, TimeNs stop) {
    (void)start;
    (void)stop;
  }
  /// Computes outputs at the start time from parameters, start values and
  /// the current inputs. Must be idempotent.
  virtual void Initialize() {}
  /// At a communication point, after new inputs are set: recomputes the
  /// outputs that depend directly on inputs (declared with depends_on) from
  /// the current state and those inputs, without advancing. The master calls
  /// it only for units that declare such outputs; the default does nothing.
  virtual void UpdateOutputs() {}
  /// Advances from t to t + dt with the inputs held as set.
  virtual StepResult DoStep(TimeNs t, TimeNs dt) = 0;
  virtual void Terminate() {}

  /// Why the last DoStep did not return kOk (empty when it did).
  const std::string& last_error() const { return last_error_; }
  /// The variable that failure concerns (a non-finite input), or empty.
  const std::string& last_error_variable() const { return last_error_variable_; }
  /// Non-empty when the unit asked, during its last DoStep (which
  /// succeeded), to end the simulation there (an FMU's terminate request):
  /// why, in one sentence. The master ends the run normally after that
  /// step.
  const std::string& stop_request() const { return stop_request_; }

  /// What the unit warned of during its run (Warn), in order: each "at t =
  /// T s: what". The session reports them with the run (summary.json
  /// "warnings", the console); they never fail it.
  const std::vector<std::string>& warnings() const { return warnings_; }

  /// "unit 'name' (type)": how messages name this unit.
  std::string Where() const { return "unit '" + name_ + "' (" + type_name_ + ")"; }

  /// Every declared variable plus the unit's internal state. A restored unit
  /// continues bit for bit like the one that was saved.
  UnitState SaveState() const;
  void RestoreState(const UnitState& state);
  /// SaveState into `state`, reusing its storage: no allocation for a unit
  /// whose variables are numbers, once `state` has held this unit's state
  /// (the master saves every step with master.retry on).
  void SaveStateInto(UnitState& state) const;

 protected:
  /// Internal state beyond the variable table; the default has none.
  virtual void SaveInternal(UnitState& state) const { (void)state; }
  virtual void RestoreInternal(const UnitState& state) { (void)state; }

  /// For Initialize: throws UnitError naming the unit and every problem that
  /// CheckParameters() reports, as "parameter 'x[i]' must be ...; ...".
  void ThrowIfBadParameters() const;

  /// For DoStep: true when every Real input (each element of an array) is
  /// finite; otherwise records "input 'x[k]' is nan at t = ..." as the
  /// step's error and returns false. Connected inputs come from outputs the
  /// master checks; this catches start values and units stepped by hand.
  bool InputsFinite(TimeNs t);

  /// For DoStep, UpdateOutputs and Initialize, where a signal in seconds
  /// (a scan's or a match's time) becomes nanoseconds: the time, or a
  /// UnitError naming the unit and `variable` when it is no time linesim
  /// represents (cosim::TimeProblem: beyond kMaxTimeSeconds, below 1 ns,
  /// not finite).
  TimeNs InputTimeNs(double seconds, const std::string& variable) const;
  /// The same where a count carried as a Real (an encoder's position in
  /// counts) becomes an integer: `count` when it is finite and within
  /// +-kMaxExactCount, else a UnitError naming `variable`.
  double CheckCount(double count, const std::string& variable) const;

  /// For DoStep: record why the step failed and return kError.
  StepResult Fail(std::string message, std::string variable = {}) {
    last_error_ = std::move(message);
    last_error_variable_ = std::move(variable);
    return StepResult::kError;
  }
  void ClearError() {
    last_error_.clear();
    last_error_variable_.clear();
    stop_request_.clear();
  }
  /// For DoStep: the step succeeded and the unit asks to end the run here.
  void RequestStop(std::string reason) { stop_request_ = std::move(reason); }
  /// Something the run's results should be read with (a contact the model
  /// does not resolve), at time t. At most kMaxWarnings are kept: beyond
  /// kMaxWarnings - 1 the last says how many more there were.
  void Warn(TimeNs t, const std::string& what);
  static constexpr std::size_t kMaxWarnings = 20;
  /// For Initialize, which may run several times before time zero: forget
  /// the warnings of an earlier call.
  void ClearWarnings() {
    warnings_.clear();
    warnings_dropped_ = 0;
  }

 private:
  std::string type_name_;
  std::string name_;
  VariableTable variables_;
  std::string last_error_;
  std::string last_error_variable_;
  std::string stop_request_;
  std::vector<std::string> warnings_;
  std::size_t warnings_dropped_ = 0;
};

}  // namespace linesim::cosim
