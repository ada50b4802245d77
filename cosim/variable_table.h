#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <variant>
#include <vector>

namespace linesim::cosim {

/// Value reference: the index of a variable in its unit's table.
using ValueRef = std::uint32_t;

enum class VarType { kReal, kInteger, kBoolean, kString, kRealArray };
enum class Causality { kParameter, kInput, kOutput, kLocal };
/// FMI variability: fixed parameters are set before initialize only; tunable
/// ones may change between steps; discrete values change only at
/// communication points; continuous ones may change at any time.
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

  // Typed access. Each checks the type and throws std::logic_error on misuse;
  // array setters check the element count.
  double GetReal(ValueRef ref) const { return *Slot<double>(ref, VarType::kReal); }
  void SetReal(ValueRef ref, double v) { *Slot<double>(ref, VarType::kReal) = v; }
  std::span<const double> GetRealArray(ValueRef ref) const;
  void SetRealArray(ValueRef ref, std::span<const double> v);
  double GetRealElement(ValueRef ref, std::size_t index) const;
  void SetRealElement(ValueRef ref, std::size_t index, double v);
  std::int64_t GetInteger(ValueRef ref) const {
    return *Slot<std::int64_t>(ref, VarType::kInteger);
  }
  void SetInteger(ValueRef ref, std::int64_t v) { *Slot<std::int64_t>(ref, VarType::kInteger) = v; }
  bool GetBoolean(ValueRef ref) const { return *Slot<bool>(ref, VarType::kBoolean); }
  void SetBoolean(ValueRef ref, bool v) { *Slot<bool>(ref, VarType::kBoolean) = v; }
  const std::string& GetString(ValueRef ref) const {
    return *Slot<std::string>(ref, VarType::kString);
  }
  void SetString(ValueRef ref, std::string v) {
    *Slot<std::string>(ref, VarType::kString) = std::move(v);
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

  std::vector<VariableInfo> infos_;
  std::vector<void*> storage_;
  std::unordered_map<std::string, ValueRef> by_name_;
  std::vector<ValueRef> real_inputs_;
  std::vector<ValueRef> real_outputs_;
};

/// The first non-finite value among `refs` (Real or Real[] variables of
/// `table`), as "input 'x[k]' is nan" (the variable's causality, its name
/// and the element of an array); nothing when all are finite.
std::optional<std::string> FirstNonFinite(const VariableTable& table,
                                          std::span<const ValueRef> refs);

}  // namespace linesim::cosim
