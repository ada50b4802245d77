#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "cosim/unit.h"

namespace linesim::cosim {

/// One variable of a unit as `linesim inspect` and the Python package's
/// inspect describe it: causality and type as text ("Real[3]" for an
/// array), its unit of measure ("" for none), its start value (declared,
/// or as a scenario set it), its rule ("> 0", "(0, 1]", "one of: a, b",
/// "required"; "" for none), its description and the variables it depends
/// on directly.
struct VariableRow {
  std::string name, causality, type, unit, start, rule, description;
  std::size_t size = 1;
  std::vector<std::string> depends_on;
};

std::vector<VariableRow> VariableRows(const Unit& unit);

}  // namespace linesim::cosim
