#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

namespace linesim::loader::testing {

/// Writes `text` to a fresh file in the test's temporary folder.
inline std::string WriteScenario(const std::string& name, const std::string& text) {
  // ctest runs tests as parallel processes: the pid keeps their files apart.
  const std::string path = ::testing::TempDir() + std::to_string(getpid()) + "_" + name;
  std::ofstream(path) << text;
  return path;
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
