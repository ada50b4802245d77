#include "cosim/unit.h"

#include <cmath>

namespace linesim::cosim {

UnitState Unit::SaveState() const {
  UnitState state;
  state.type_name = type_name_;
  state.variables.reserve(variables_.size());
  for (const auto& info : variables_.infos())
    state.variables.push_back(variables_.GetValue(info.ref));
  SaveInternal(state);
  return state;
}

void Unit::RestoreState(const UnitState& state) {
  if (state.type_name != type_name_) {
    throw std::invalid_argument("state of a '" + state.type_name + "' unit restored into " +
                                Where());
  }
  if (state.variables.size() != variables_.size()) {
    throw std::invalid_argument("state of " + std::to_string(state.variables.size()) +
                                " variables restored into " + Where() + " with " +
                                std::to_string(variables_.size()));
  }
  for (ValueRef r = 0; r < variables_.size(); ++r) variables_.SetValue(r, state.variables[r]);
  RestoreInternal(state);
}

bool Unit::InputsFinite(TimeNs t) {
  for (const VariableInfo& info : variables_.infos()) {
    if (info.causality != Causality::kInput) continue;
    if (info.type == VarType::kReal) {
      const double v = variables_.GetReal(info.ref);
      if (!std::isfinite(v)) {
        Fail(Where() + ": input '" + info.name + "' is " + FormatValue(v) +
             " at t = " + FormatSeconds(t) + " s");
        return false;
      }
    } else if (info.type == VarType::kRealArray) {
      const auto values = variables_.GetRealArray(info.ref);
      for (std::size_t k = 0; k < values.size(); ++k) {
        if (!std::isfinite(values[k])) {
          Fail(Where() + ": input '" + info.name + "[" + std::to_string(k) + "]' is " +
               FormatValue(values[k]) + " at t = " + FormatSeconds(t) + " s");
          return false;
        }
      }
    }
  }
  return true;
}

void Unit::ThrowIfBadParameters() const {
  const auto problems = CheckParameters();
  if (problems.empty()) return;
  std::string text = Where() + ": ";
  for (std::size_t p = 0; p < problems.size(); ++p) {
    const auto& problem = problems[p];
    if (p > 0) text += "; ";
    text += "parameter '" + problem.variable +
            (problem.index ? "[" + std::to_string(*problem.index) + "]" : "") + "' " +
            problem.message;
  }
  throw UnitError(text);
}

}  // namespace linesim::cosim
