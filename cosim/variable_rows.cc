#include "cosim/variable_rows.h"

namespace linesim::cosim {

std::vector<VariableRow> VariableRows(const Unit& unit) {
  std::vector<VariableRow> rows;
  const VariableTable& table = unit.variables();
  for (const auto& v : table.infos()) {
    VariableRow row;
    row.name = v.name;
    row.causality = std::string(ToString(v.causality));
    row.type = v.type == VarType::kRealArray ? "Real[" + std::to_string(v.size) + "]"
                                             : std::string(ToString(v.type));
    row.unit = v.unit;
    row.start = FormatValue(table.GetValue(v.ref));
    row.rule = v.rule.empty() ? std::string() : v.rule.Text();
    row.description = v.description;
    row.size = v.size;
    for (const auto ref : v.depends_on) row.depends_on.push_back(table.info(ref).name);
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace linesim::cosim
