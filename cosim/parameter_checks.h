#pragma once

#include <optional>
#include <string>
#include <vector>

#include "cosim/unit.h"

namespace linesim::cosim {

/// Collects a unit's parameter problems for CheckParameters, with the
/// common rules and one wording for them ("must be positive and finite,
/// got -1"). Arrays are checked element by element, each bad element a
/// problem with its index. A rule on one parameter is better declared with
/// it (cosim::Rule, which inspect prints and sweeps check before running);
/// this is for what a declaration cannot say.
class ParameterChecks {
 public:
  void Positive(const char* name, double value);
  void Positive(const char* name, const std::vector<double>& values);
  void NonNegative(const char* name, double value);
  void NonNegative(const char* name, const std::vector<double>& values);
  void Finite(const char* name, double value);
  void Finite(const char* name, const std::vector<double>& values);

  /// Any other rule: `ok(value)` must hold; `expected` says what should.
  template <class Ok>
  void Check(const char* name, double value, Ok ok, const char* expected) {
    if (!ok(value)) Add(name, std::nullopt, expected, value);
  }
  template <class Ok>
  void Check(const char* name, const std::vector<double>& values, Ok ok, const char* expected) {
    for (std::size_t k = 0; k < values.size(); ++k) {
      if (!ok(values[k])) Add(name, k, expected, values[k]);
    }
  }
  /// A problem worded by the unit itself.
  void Add(ParameterProblem problem) { problems_.push_back(std::move(problem)); }

  std::vector<ParameterProblem> Take() { return std::move(problems_); }

 private:
  void Add(const char* name, std::optional<std::size_t> index, const char* expected, double value);

  std::vector<ParameterProblem> problems_;
};

}  // namespace linesim::cosim
