#pragma once
// How a linesim unit's VariableTable appears as FMI 2.0 scalar variables:
// the one mapping that the model description writer and the FMU runtime
// (fmu_runtime.cc) share, so that the value references written into
// modelDescription.xml are the ones the binary serves.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cosim/unit.h"
#include "cosim/variable_table.h"

namespace linesim::fmu_export {

/// One FMI 2.0 ScalarVariable: a scalar of the table, or one element of a
/// Real array. Its value reference is its index in Layout::variables.
struct ExportedVariable {
  std::string name;         // "resistance", "ranges[1]" (1-based, FMI structured naming)
  cosim::ValueRef ref = 0;  // in the unit's table
  std::size_t element = 0;  // element of a Real array
  bool is_element = false;  // true: GetRealElement(ref, element)
  cosim::VarType type = cosim::VarType::kReal;  // scalar type (kReal for an element)
};

struct Layout {
  std::vector<ExportedVariable> variables;
  /// For each table variable, the value reference of its first scalar.
  std::vector<std::uint32_t> first_vr;
};

/// Table variables in declaration order; a Real array of n elements becomes
/// n Real scalars, named "x" when n == 1 and "x[1]" .. "x[n]" otherwise.
Layout MakeLayout(const cosim::VariableTable& table);

/// The FMI 3.0 type of a linesim Integer: Int64 when its declared range
/// reaches beyond 32 bits (a device seed up to 2^32 - 1), else Int32 (as
/// the FMI 2.0 Integer). The writer and the runtime's fmi3Get/SetInt32 and
/// Int64 decide by it.
bool IsInt64In3(const cosim::VariableInfo& info);

/// FNV-1a 64 of `text`, as an FMI 2.0 guid "{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}"
/// (two differently seeded hashes fill its 128 bits).
std::string GuidOf(const std::string& text);

/// The guid of an exported FMU: GuidOf its resource file and scene file
/// (empty when it has none); fmi2Instantiate checks it.
std::string GuidOfResources(const std::string& resource, const std::string& scene);

/// A UnitState as bytes (fmi2SerializeFMUstate) and back; Deserialize
/// throws std::runtime_error on bytes it did not write.
std::vector<char> SerializeState(const cosim::UnitState& state);
cosim::UnitState DeserializeState(const char* data, std::size_t size);

}  // namespace linesim::fmu_export
