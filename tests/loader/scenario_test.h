#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <vector>

#include "loader/scenario.h"

namespace linesim::loader::testing {

/// Writes `text` to a fresh file in the test's temporary folder.
inline std::string WriteScenario(const std::string& name, const std::string& text) {
  // ctest runs tests as parallel processes: the pid keeps their files apart.
  const std::string path = ::testing::TempDir() + std::to_string(getpid()) + "_" + name;
  std::ofstream(path) << text;
  return path;
}

/// Every issue of loading `file` with `sets`, one per line, for matching in
/// assertions; "(no error)" when it loads.
inline std::string Issues(const std::string& file, const std::vector<std::string>& sets = {}) {
  try {
    LoadScenario(file, sets);
  } catch (const ScenarioError& e) {
    return e.what();
  }
  return "(no error)";
}

/// A Real parameter of unit `unit` in the built system (element `index` of
/// an array).
inline double Param(const Scenario& s, const std::string& unit, const std::string& name,
                    std::size_t index = 0) {
  const auto& v = s.system->unit(*s.system->FindUnit(unit)).variables();
  const auto ref = *v.Find(name);
  return v.info(ref).type == cosim::VarType::kRealArray ? v.GetRealElement(ref, index)
                                                        : v.GetReal(ref);
}

inline bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// A valid two-unit system: a step source driving one DC motor.
inline const char* kValidScenario = R"(name: tiny
duration_s: 0.01
master: {algorithm: jacobi, step_s: 0.001}
units:
  supply:
    type: step_signal
    parameters: {count: 1, unit: V, steps: [{time_s: 0.002, value: 12}]}
  motor:
    type: dc_motor
    parameters: {count: 1, model: maxon_re40_148877}
connections:
  - {from: supply.value, to: motor.voltage}
)";

}  // namespace linesim::loader::testing
