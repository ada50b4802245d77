#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "cosim/parameter_checks.h"
#include "cosim/unit.h"

namespace linesim::control {

/// Start value of a robot-specific parameter (geometry, wheel radius,
/// feedforwards derived from the motors): it has no default, so that a
/// robot description that forgets it fails instead of silently inheriting
/// another robot's number.
inline constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();

/// The one wording for an unset robot-specific parameter.
inline constexpr const char* kUnsetMessage = "must be set (robot-specific: no default)";

/// Reports `name` when it was never set (NaN) and returns false; true when
/// set, so that the caller goes on with its range check.
inline bool CheckSet(cosim::ParameterChecks& c, const char* name, double value) {
  if (!std::isnan(value)) return true;
  c.Add({name, std::nullopt, kUnsetMessage});
  return false;
}

/// Array form: all elements unset is one problem without an index; some
/// unset are one problem each. Returns whether every element is set.
inline bool CheckSet(cosim::ParameterChecks& c, const char* name,
                     const std::vector<double>& values) {
  std::size_t unset = 0;
  for (double v : values) unset += std::isnan(v) ? 1 : 0;
  if (unset == 0) return true;
  if (unset == values.size()) {
    c.Add({name, std::nullopt, kUnsetMessage});
  } else {
    for (std::size_t k = 0; k < values.size(); ++k) {
      if (std::isnan(values[k])) c.Add({name, k, kUnsetMessage});
    }
  }
  return false;
}

}  // namespace linesim::control
