#include "cosim/unit.h"

#include <cmath>

namespace linesim::cosim {

UnitState Unit::SaveState() const {
  UnitState state;
  SaveStateInto(state);
  return state;
}

void Unit::SaveStateInto(UnitState& state) const {
  state.type_name = type_name_;
  state.variables.resize(variables_.size());
  for (const auto& info : variables_.infos()) {
    Value& slot = state.variables[info.ref];
    // Numbers in place; strings and arrays keep their capacity.
    switch (info.type) {
      case VarType::kReal:
        slot = variables_.GetReal(info.ref);
        break;
      case VarType::kInteger:
        slot = variables_.GetInteger(info.ref);
        break;
      case VarType::kBoolean:
        slot = variables_.GetBoolean(info.ref);
        break;
      case VarType::kString:
        if (auto* s = std::get_if<std::string>(&slot)) {
          *s = variables_.GetString(info.ref);
        } else {
          slot = variables_.GetString(info.ref);
        }
        break;
      case VarType::kRealArray: {
        const auto values = variables_.GetRealArray(info.ref);
        if (auto* v = std::get_if<std::vector<double>>(&slot)) {
          v->assign(values.begin(), values.end());
        } else {
          slot = std::vector<double>(values.begin(), values.end());
        }
        break;
      }
    }
  }
  state.reals.clear();
  state.integers.clear();
  state.strings.clear();
  SaveInternal(state);
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
  if (variables_.RealInputsFinite()) return true;
  const auto problem = FindNonFinite(variables_, variables_.real_inputs());
  if (!problem) return true;
  Fail(Where() + ": " + problem->text + " at t = " + FormatSeconds(t) + " s", problem->variable);
  return false;
}

void Unit::Warn(TimeNs t, const std::string& what) {
  // The last place says how many more there were.
  if (warnings_.size() + 1 < kMaxWarnings) {
    warnings_.push_back("at t = " + FormatSeconds(t) + " s: " + what);
    return;
  }
  ++warnings_dropped_;
  const std::string more = "and " + std::to_string(warnings_dropped_) + " more warning" +
                           (warnings_dropped_ == 1 ? "" : "s") + " like the ones before";
  if (warnings_.size() < kMaxWarnings) {
    warnings_.push_back(more);
  } else {
    warnings_.back() = more;
  }
}

TimeNs Unit::InputTimeNs(double seconds, const std::string& variable) const {
  if (const auto problem = TimeProblem(seconds)) {
    throw UnitError(Where() + ": '" + variable + "' = " + FormatValue(seconds) + " s " + *problem,
                    variable);
  }
  return SecondsToNs(seconds);
}

double Unit::CheckCount(double count, const std::string& variable) const {
  if (!(std::abs(count) <= kMaxExactCount)) {
    throw UnitError(Where() + ": '" + variable + "' = " + FormatValue(count) +
                        " counts is beyond +-2^53, the largest count a Real carries exactly",
                    variable);
  }
  return count;
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
  const auto& first = problems.front();
  throw UnitError(text, first.variable + (first.index ? "[" + std::to_string(*first.index) + "]" : ""));
}

}  // namespace linesim::cosim
