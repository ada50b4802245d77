#include "cosim/unit.h"

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
  // Read-only variables too: a restored unit is the saved one, whatever
  // the lock says.
  for (ValueRef r = 0; r < variables_.size(); ++r) variables_.RestoreValue(r, state.variables[r]);
  RestoreInternal(state);
}

std::vector<ParameterProblem> Unit::CheckParameters() const { return CheckRules(variables_); }

bool Unit::InputsFinite(TimeNs t) {
  const auto problem = FirstNonFinite(variables_, variables_.real_inputs());
  if (!problem) return true;
  Fail(Where() + ": " + *problem + " at t = " + FormatSeconds(t) + " s");
  return false;
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
