#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <variant>
#include <vector>

namespace linesim::cosim {

/// The largest count a Real carries exactly (2^53: a double holds every
/// integer up to it). A count held in a Real (an encoder's counts, a
/// count per revolution) that a unit converts to an integer stays within
/// it (Rule::Count, Unit::CheckCount).
inline constexpr double kMaxExactCount = 9007199254740992.0;

/// Value reference: the index of a variable in its unit's table.
using ValueRef = std::uint32_t;

enum class VarType { kReal, kInteger, kBoolean, kString, kRealArray };
enum class Causality { kParameter, kInput, kOutput, kLocal };
/// FMI variability. Checked by the table's setters: a constant is never set
/// from outside the unit (only RestoreState writes it); a fixed parameter is
/// set before the run only (the table refuses it once the master has
/// initialized the unit, see VariableTable::Lock); a tunable one may change
/// between steps. Discrete and continuous describe signals (inputs, outputs,
/// locals), which the master writes at communication points.
enum class Variability { kConstant, kFixed, kTunable, kDiscrete, kContinuous };

std::string_view ToString(VarType t);
std::string_view ToString(Causality c);
std::string_view ToString(Variability v);

/// A value of any variable type, used at the boundary (parameters from files,
/// start values, saved states); the stepping hot path uses typed accessors.
using Value = std::variant<double, std::int64_t, bool, std::string, std::vector<double>>;

/// Human-readable rendering of a value ("1.5", "[1, 2]", "true", "\"x\"").
std::string FormatValue(const Value& v);
/// A number as the shortest text that reads back to it ("0.1", "1e-05",
/// "nan"): for messages, files and the YAML the loader writes.
std::string FormatValue(double x);
/// The inverse for files: a finite number written as text (an optional
/// leading '+'), whatever the locale; nothing for anything else.
std::optional<double> ParseFiniteValue(std::string_view text);

/// A value a unit refuses (a parameter's rule, or a unit's own check),
/// found before time zero.
struct ParameterProblem {
  std::string variable;
  std::optional<std::size_t> index;  // element of an array parameter
  std::string message;               // what was expected, and the value
};

/// The values a parameter accepts, declared with it (FMI's min/max and
/// more): a range (each end inclusive or exclusive), positivity, finiteness,
/// an allowed set of strings or integers, and "required" (no default: the
/// start value is NaN or "" and the scenario must set it). Every numeric rule
/// also requires a finite value. For an array the rule applies to each
/// element. A default-constructed Rule accepts everything.
///
///   v.Parameter("mass", "kg", &mass_, "total mass", Rule::Positive().NoDefault());
///   v.Parameter("eta", "1", &eta_, "efficiency", Rule::Range(0, false, 1, true));
///   v.Parameter("mode", &mode_, "how", Rule::OneOf({"full", "current_only"}));
class Rule {
 public:
  Rule() = default;

  /// Any finite number.
  static Rule Finite();
  /// > 0.
  static Rule Positive();
  /// >= 0.
  static Rule NonNegative();
  /// >= min, or > min when not inclusive.
  static Rule AtLeast(double min, bool inclusive = true);
  /// <= max, or < max when not inclusive.
  static Rule AtMost(double max, bool inclusive = true);
  /// [min, max]; each end inclusive unless said otherwise ("(0, 1]" is
  /// Range(0, false, 1, true)).
  static Rule Range(double min, bool min_inclusive, double max, bool max_inclusive);
  static Rule Range(double min, double max) { return Range(min, true, max, true); }
  /// A String parameter: one of these.
  static Rule OneOf(std::vector<std::string> allowed);
  static Rule OneOf(std::initializer_list<const char*> allowed);
  /// An Integer parameter: one of these.
  static Rule OneOf(std::vector<std::int64_t> allowed);
  static Rule OneOf(std::initializer_list<int> allowed);
  /// No default, any finite number (or any non-empty string): the start
  /// value is NaN (or "") and the parameter must be set.
  static Rule Required() { return Rule().NoDefault(); }

  /// The same rule, and the parameter has no default (robot-specific): NaN
  /// or "" means "not set" and is reported as "must be set (robot-specific:
  /// no default)".
  Rule NoDefault() const;
  /// The same rule for a time in seconds, which units convert to integer
  /// nanoseconds: also finite, within +-kMaxTimeSeconds (cosim/time.h; an
  /// end the rule leaves open or puts beyond it becomes the limit), and
  /// not a non-zero value below the 1 ns resolution; a value refused by
  /// the limit is told why. VariableTable gives it to every Real parameter
  /// whose unit is "s", so no unit declares it by hand.
  Rule Time() const;
  /// The same rule for a count carried as a Real that the unit converts to
  /// an integer (an encoder's counts per revolution): also finite and
  /// within +-kMaxExactCount, told why when refused by it.
  Rule Count() const;

  bool empty() const;
  bool required() const { return required_; }
  /// The numeric bounds, for FMI's min / max (an exclusive end is given as
  /// its value: FMI bounds are inclusive); nothing when unbounded.
  std::optional<double> lower() const { return min_ ? std::optional<double>(min_->value) : std::nullopt; }
  std::optional<double> upper() const { return max_ ? std::optional<double>(max_->value) : std::nullopt; }
  /// For tables: "> 0", "[0, 1]", "(0, 1]", "finite", "one of: a, b",
  /// "required", "required, > 0"; "" when there is no rule.
  std::string Text() const;

  /// Why `x` breaks the rule ("must be > 0, got -1"), or nothing.
  std::optional<std::string> Violation(double x) const;
  std::optional<std::string> Violation(std::int64_t x) const;
  std::optional<std::string> Violation(const std::string& x) const;

  /// Throws std::logic_error when the rule cannot apply to a variable of
  /// this type (a set of strings on a Real, a range on a Boolean).
  void CheckApplies(const std::string& variable, VarType type) const;

 private:
  struct Bound {
    double value = 0;
    bool inclusive = true;
  };
  std::string Bounds() const;  // "> 0", "[0, 1]"; "" without bounds
  /// The rule bounded to +-max_abs (Time, Count).
  Rule Limited(double max_abs, double resolution, const char* why) const;
  /// " (why)" when `x` broke an end that is the limit's.
  std::string LimitReason(double x) const;
  bool numeric_ = false;  // a number rule: finite, maybe bounded
  std::optional<Bound> min_, max_;
  std::optional<std::vector<std::string>> strings_;
  std::optional<std::vector<std::int64_t>> integers_;
  bool required_ = false;
  // Time, Count: the representable range (both ends are within it), the
  // resolution (a non-zero value below it is refused; 0: none) and why.
  struct Limit {
    double max_abs = 0;
    double resolution = 0;
    const char* why = "";
  };
  std::optional<Limit> limit_;
};

struct VariableInfo {
  ValueRef ref = 0;
  std::string name;
  VarType type = VarType::kReal;
  std::size_t size = 1;  // element count; 1 for scalars
  Causality causality = Causality::kLocal;
  Variability variability = Variability::kContinuous;
  std::string unit;  // SI unit string, "1" for dimensionless
  std::string description;
  Value start;
  /// Parameters only: the values it accepts (empty: any).
  Rule rule;
  /// Outputs only: the inputs this output depends on directly (feedthrough
  /// within one communication point). Empty means none.
  std::vector<ValueRef> depends_on;
};

/// The single declaration of a unit's variables. Each entry binds a name to a
/// member of the unit; the member's value at declaration time is the start
/// value. Units are neither copied nor moved after construction, so the
/// bound addresses stay valid.
class VariableTable {
 public:
  VariableTable() = default;
  VariableTable(const VariableTable&) = delete;
  VariableTable& operator=(const VariableTable&) = delete;

  /// A parameter; `rule` says which values it accepts (Unit::CheckParameters
  /// reports every value that breaks it). A rule that cannot apply to the
  /// type, or a required parameter with a start value, is a std::logic_error.
  ValueRef Parameter(std::string name, std::string unit, double* storage, std::string description,
                     Variability v = Variability::kFixed);
  ValueRef Parameter(std::string name, std::string unit, std::vector<double>* storage,
                     std::string description, Variability v = Variability::kFixed);
  ValueRef Parameter(std::string name, std::int64_t* storage, std::string description,
                     Variability v = Variability::kFixed);
  ValueRef Parameter(std::string name, bool* storage, std::string description,
                     Variability v = Variability::kFixed);
  ValueRef Parameter(std::string name, std::string* storage, std::string description,
                     Variability v = Variability::kFixed);
  ValueRef Parameter(std::string name, std::string unit, double* storage, std::string description,
                     Rule rule, Variability v = Variability::kFixed);
  ValueRef Parameter(std::string name, std::string unit, std::vector<double>* storage,
                     std::string description, Rule rule, Variability v = Variability::kFixed);
  ValueRef Parameter(std::string name, std::int64_t* storage, std::string description, Rule rule,
                     Variability v = Variability::kFixed);
  ValueRef Parameter(std::string name, std::string* storage, std::string description, Rule rule,
                     Variability v = Variability::kFixed);
  /// Sets the rule of a parameter declared earlier (for parameters declared
  /// in a loop or by a helper); same checks as at declaration.
  void SetRule(ValueRef ref, Rule rule);

  ValueRef Input(std::string name, std::string unit, double* storage, std::string description);
  ValueRef Input(std::string name, std::string unit, std::vector<double>* storage,
                 std::string description);
  ValueRef Input(std::string name, std::int64_t* storage, std::string description);
  ValueRef Input(std::string name, bool* storage, std::string description);
  ValueRef Input(std::string name, std::string* storage, std::string description);

  /// `depends_on` names inputs declared before this output.
  ValueRef Output(std::string name, std::string unit, double* storage, std::string description,
                  const std::vector<std::string>& depends_on);
  ValueRef Output(std::string name, std::string unit, std::vector<double>* storage,
                  std::string description, const std::vector<std::string>& depends_on);
  ValueRef Output(std::string name, std::int64_t* storage, std::string description,
                  const std::vector<std::string>& depends_on);
  ValueRef Output(std::string name, bool* storage, std::string description,
                  const std::vector<std::string>& depends_on);
  ValueRef Output(std::string name, std::string* storage, std::string description,
                  const std::vector<std::string>& depends_on);

  ValueRef Local(std::string name, std::string unit, double* storage, std::string description);
  ValueRef Local(std::string name, std::string unit, std::vector<double>* storage,
                 std::string description);

  std::size_t size() const { return infos_.size(); }
  const std::vector<VariableInfo>& infos() const { return infos_; }
  const VariableInfo& info(ValueRef ref) const { return infos_.at(ref); }
  std::optional<ValueRef> Find(std::string_view name) const;
  std::vector<std::string> Names() const;
  /// The Real and Real[] inputs, and outputs, in declaration order: what the
  /// finite checks scan, listed once as variables are declared.
  const std::vector<ValueRef>& real_inputs() const { return real_inputs_; }
  const std::vector<ValueRef>& real_outputs() const { return real_outputs_; }

  /// Where a Real or Real[] variable's value lives: a double, or a vector
  /// (units are never moved, so both addresses stay valid). For the hot
  /// paths that resolve a variable once and then touch only its value (the
  /// master's transfers, the finite checks): a VariableInfo fills several
  /// cache lines of its own, and reading its type at every transfer and
  /// check cost ten robots (BM_Fleet/10) 1.5-2 ms per robot and simulated
  /// 5 s in cache misses.
  struct RealSlot {
    const double* scalar = nullptr;              // a Real
    const std::vector<double>* array = nullptr;  // a Real[]
  };
  struct WritableRealSlot {
    double* scalar = nullptr;
    std::vector<double>* array = nullptr;
  };
  /// `ref` must name a Real or Real[] (std::logic_error otherwise).
  RealSlot ResolveReal(ValueRef ref) const;
  /// The same for a variable the setters accept (std::logic_error for a
  /// read-only one, as they would throw).
  WritableRealSlot ResolveWritableReal(ValueRef ref);
  /// Whether every real input (output) is finite: one pass over their
  /// values alone. FindNonFinite says which one is not.
  bool RealInputsFinite() const { return AllFinite(real_input_slots_); }
  bool RealOutputsFinite() const { return AllFinite(real_output_slots_); }

  /// Ends the configuration of the unit: from now on the setters refuse a
  /// fixed parameter (std::logic_error), as they always refuse a constant.
  /// The master calls it once every unit is initialized; RestoreState still
  /// writes every variable.
  void Lock();
  bool locked() const { return locked_; }

  // Typed access. Each checks the type and throws std::logic_error on misuse
  // or on a variable its variability makes read-only (see Lock); array
  // setters check the element count.
  double GetReal(ValueRef ref) const { return *Slot<double>(ref, VarType::kReal); }
  void SetReal(ValueRef ref, double v) { *Writable<double>(ref, VarType::kReal) = v; }
  std::span<const double> GetRealArray(ValueRef ref) const;
  /// The value(s) of a Real or Real[] variable as a span, for scans over
  /// many variables (the master's finite checks); `ref` must name one of
  /// those (real_inputs() and real_outputs() list them).
  std::span<const double> RealValues(ValueRef ref) const {
    if (infos_[ref].type == VarType::kReal) return {static_cast<const double*>(storage_[ref]), 1};
    const auto* v = static_cast<const std::vector<double>*>(storage_[ref]);
    return {v->data(), v->size()};
  }
  void SetRealArray(ValueRef ref, std::span<const double> v);
  double GetRealElement(ValueRef ref, std::size_t index) const;
  void SetRealElement(ValueRef ref, std::size_t index, double v);
  std::int64_t GetInteger(ValueRef ref) const {
    return *Slot<std::int64_t>(ref, VarType::kInteger);
  }
  void SetInteger(ValueRef ref, std::int64_t v) {
    *Writable<std::int64_t>(ref, VarType::kInteger) = v;
  }
  bool GetBoolean(ValueRef ref) const { return *Slot<bool>(ref, VarType::kBoolean); }
  void SetBoolean(ValueRef ref, bool v) { *Writable<bool>(ref, VarType::kBoolean) = v; }
  const std::string& GetString(ValueRef ref) const {
    return *Slot<std::string>(ref, VarType::kString);
  }
  void SetString(ValueRef ref, std::string v) {
    *Writable<std::string>(ref, VarType::kString) = std::move(v);
  }

  /// Generic access for the boundary. SetValue converts an integer to a real
  /// and a scalar real to every element of an array; other mismatches throw
  /// std::invalid_argument with a message saying what was expected.
  Value GetValue(ValueRef ref) const;
  void SetValue(ValueRef ref, const Value& v);

 private:
  /// Declares a variable bound to `storage`; its type, element count and
  /// start value come from the storage. Defined in the .cc for the five
  /// storage types only.
  template <typename T>
  ValueRef Bind(std::string name, Causality causality, Variability variability, std::string unit,
                T* storage, std::string description,
                const std::vector<std::string>& depends_on = {});
  std::vector<ValueRef> ResolveDependencies(const std::string& output,
                                            const std::vector<std::string>& names) const;

  template <typename T>
  T* Slot(ValueRef ref, VarType expected) const {
    if (ref >= infos_.size() || infos_[ref].type != expected) ThrowTypeMisuse(ref, expected);
    return static_cast<T*>(storage_[ref]);
  }
  [[noreturn]] void ThrowTypeMisuse(ValueRef ref, VarType expected) const;
  template <typename T>
  T* Writable(ValueRef ref, VarType expected) {
    T* slot = Slot<T>(ref, expected);
    if (read_only_[ref]) ThrowReadOnly(ref);
    return slot;
  }
  [[noreturn]] void ThrowReadOnly(ValueRef ref) const;

  // Unit::RestoreState writes every variable, read-only or not.
  friend class Unit;
  void RestoreValue(ValueRef ref, const Value& v);

  std::vector<VariableInfo> infos_;
  std::vector<void*> storage_;
  std::unordered_map<std::string, ValueRef> by_name_;
  std::vector<ValueRef> real_inputs_;
  std::vector<ValueRef> real_outputs_;
  std::vector<RealSlot> real_input_slots_;  // the same, resolved
  std::vector<RealSlot> real_output_slots_;
  static bool AllFinite(std::span<const RealSlot> slots);
  // Per variable: the setters refuse it (a constant, or a fixed parameter
  // after Lock). One flag, so that the hot path pays one load.
  std::vector<char> read_only_;
  bool locked_ = false;
};

/// Every element of `v` that breaks the rule of parameter `info`, worded as
/// Unit::CheckParameters reports them ("must be > 0, got -1", index set for
/// an element of a list). A scalar given for an array parameter is checked
/// once, without an index. For the loader and sweeps, to refuse a value at
/// its key before running. Values of the wrong type are not this check's
/// business (SetValue refuses them): they give no problem here.
std::vector<ParameterProblem> CheckRule(const VariableInfo& info, const Value& v);
/// Every parameter of `table` whose current value breaks its rule: what the
/// default Unit::CheckParameters returns.
std::vector<ParameterProblem> CheckRules(const VariableTable& table);

/// The first non-finite value among `refs` (Real or Real[] variables of
/// `table`), as "input 'x[k]' is nan" (the variable's causality, its name
/// and the element of an array); nothing when all are finite.
std::optional<std::string> FirstNonFinite(const VariableTable& table,
                                          std::span<const ValueRef> refs);
/// The same, with the variable on its own ("x", "ranges[3]").
struct NonFinite {
  std::string variable;
  std::string text;  // as FirstNonFinite says it
};
std::optional<NonFinite> FindNonFinite(const VariableTable& table,
                                       std::span<const ValueRef> refs);

}  // namespace linesim::cosim
