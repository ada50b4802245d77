#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <utility>
#include <stdexcept>
#include <string>
#include <vector>

namespace linesim::fmu {

/// Every refusal of an FMU (its archive, its model description, its binary,
/// a call that failed), worded for the user: what is wrong and where.
class FmuError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The FMI variable types linesim maps: FMI 2.0 Real / Integer /
/// Enumeration (as kInt32, with its items) / Boolean / String; FMI 3.0
/// Float64 (also arrays, of fixed dimensions or sized by structural
/// parameters) / Float32 / Int8 to Int64 / UInt8 to UInt64 / Enumeration
/// (as kInt64, with its items) / Boolean / String. Floats are linesim Reals,
/// every integer type a linesim Integer (int64) checked against the FMI
/// type's range when given to the FMU (UInt64 above 2^63 - 1 is refused
/// when read). FMI 3.0 Binary and Clock variables are left out (the FMU
/// keeps their start values): one that a scenario connects or records is
/// then no variable of the unit. The first four keep their values (the
/// storage classes, see StorageOf).
enum class FmiType {
  kFloat64, kInt32, kBoolean, kString,
  kFloat32, kInt8, kUInt8, kInt16, kUInt16, kUInt32, kInt64, kUInt64
};
inline constexpr int kFmiTypeCount = 12;

/// Where a type's values live in linesim: 0 Real, 1 Integer, 2 Boolean,
/// 3 String.
int StorageOf(FmiType type);
/// The range of an integer type as linesim's Integer can hold it.
std::pair<std::int64_t, std::int64_t> IntegerRange(FmiType type);

struct FmiVariable {
  std::string name;
  std::uint32_t value_reference = 0;
  FmiType type = FmiType::kFloat64;
  /// As in the model description: parameter, calculatedParameter,
  /// structuralParameter, input, output, local, independent.
  std::string causality = "local";
  /// constant, fixed, tunable, discrete, continuous.
  std::string variability = "continuous";
  std::string description;
  /// FMI 3.0 arrays: the fixed dimensions (empty for a scalar); `size` is
  /// their product (1 for a scalar).
  std::vector<std::size_t> dimensions;
  std::size_t size = 1;
  bool size_from_structural = false;  // a dimension given by a structural parameter
  /// The declared min, max and nominal (on the variable or its declared
  /// type), for numeric types; nothing when not declared.
  std::optional<double> min, max, nominal;
  /// Enumerations: the items (value, name), ascending by value; a value
  /// given to the FMU must be one of them.
  std::vector<std::pair<std::int64_t, std::string>> items;
  std::string declared_type;
  bool has_start = false;
  std::vector<double> start_reals;  // Float64 (one per element)
  std::int64_t start_integer = 0;
  bool start_boolean = false;
  std::string start_string;
  /// The unit as the FMU declares it (on the variable or its declared
  /// type), "" when none; and the unit string linesim compares (SI, in
  /// linesim's spelling: "m", "rad/s", "N.m", "1"), see LinesimUnit.
  std::string fmi_unit;
  std::string unit;
  /// Outputs: the inputs the output depends on directly (ModelStructure),
  /// as indices into ModelDescription::variables (FMI 2.0 value references
  /// are unique per type only); nothing when the FMU does not say (then
  /// every input is assumed).
  std::optional<std::vector<std::uint32_t>> dependencies;
  int line = 0;  // in modelDescription.xml
};

/// One <Unit> of UnitDefinitions: its SI base-unit exponents (kg, m, s, A,
/// K, mol, cd, rad), factor and offset (value_SI = factor * value + offset).
struct FmiUnit {
  std::string name;
  bool has_base_unit = false;
  int exponents[8] = {};
  double factor = 1.0;
  double offset = 0.0;
};

struct ModelDescription {
  int fmi_major = 0;  // 2 or 3
  std::string fmi_version;
  std::string model_name;
  std::string token;  // FMI 2.0 guid, FMI 3.0 instantiationToken
  std::string description;
  std::string generation_tool;
  std::string generation_date;
  bool has_co_simulation = false;
  bool has_model_exchange = false;
  bool has_scheduled_execution = false;
  std::string model_identifier;  // of <CoSimulation>
  bool can_get_and_set_state = false;
  bool can_serialize_state = false;
  bool can_handle_variable_step = false;
  bool can_interpolate_inputs = false;
  bool can_return_early = false;         // FMI 3.0 mightReturnEarlyFromDoStep
  bool needs_execution_tool = false;
  bool only_once_per_process = false;
  std::optional<double> fixed_internal_step;  // FMI 3.0 fixedInternalStepSize
  std::optional<double> default_start, default_stop, default_tolerance, default_step;
  std::vector<FmiVariable> variables;
  /// Variables read but left out, "name (type)": FMI 3.0 Binary.
  std::vector<std::string> left_out;
  std::map<std::string, FmiUnit> units;
};

/// The most variables a model description may declare (elements of
/// <ModelVariables>, those linesim leaves out included), counted before any
/// is read; beyond it the FMU is refused. Large Modelica models have some
/// 10^5. Reading and declaring them is linear, about 1.3 KB and 15 us per
/// variable (`linesim inspect` of an FMI 2.0 FMU, 2-core machine: 40k
/// variables 0.5 s / 80 MB, 200k 3 s / 0.3 GB, 1M 17 s / 1.3 GB), so the
/// limit bounds an FMU's load to some 6 s and 0.7 GB (500k measured).
inline constexpr std::size_t kMaxVariables = 500'000;

/// The largest modelDescription.xml linesim reads, checked before reading
/// it: kMaxVariables variables at some 200 bytes each (a Modelica tool's
/// ScalarVariable with a description) with room to spare.
inline constexpr std::uintmax_t kMaxModelDescriptionBytes = std::uintmax_t{128} << 20;

/// Reads and checks a modelDescription.xml (at most
/// kMaxModelDescriptionBytes): FMI 2.0 or 3.0, with a
/// co-simulation interface, variables of the mapped types. Throws FmuError
/// naming `file` and the line of the problem: invalid XML, an FMI version
/// other than 2.0 or 3.0, model exchange only, clocks, a variable type or
/// array dimension linesim does not map.
ModelDescription ParseModelDescription(const std::string& file);
/// The same from text already read; `file` names it in messages.
ModelDescription ParseModelDescriptionText(const std::string& text, const std::string& file);

/// The unit linesim compares for a declared FMI unit: "" (no unit) gives
/// "1" for a Float64; a name whose base units (from UnitDefinitions, or
/// from the name's own SI symbols) match one of linesim's spellings takes
/// that spelling ("m.s-1" -> "m/s"); a unit with factor != 1 or offset != 0
/// (deg, rpm, degC) keeps its own name, so that it connects only to the
/// same name (linesim converts no units).
std::string LinesimUnit(const std::string& fmi_unit, const std::map<std::string, FmiUnit>& units);

/// The SI base-unit exponents (kg, m, s, A, K, mol, cd, rad, FMI's order)
/// of a unit expression in FMI / Modelica syntax or linesim's spelling
/// ("N.m", "m/s2", "kg.m2", "N.m.s/rad", "1"); nothing when a symbol is not
/// an SI one without prefix. The exporter writes UnitDefinitions with it, so
/// an exported FMU's units read back as they were written.
std::optional<std::array<int, 8>> SiExponents(const std::string& unit);

/// "Float64", "Int32", "Boolean", "String", "Float32", "UInt64", ...
/// (FMI 3.0 names).
const char* ToString(FmiType type);

}  // namespace linesim::fmu
