#pragma once

// Runs a scenario file end to end as `linesim run` does (without writing
// files) and returns its metrics, printing them for the test log.
#include <gtest/gtest.h>

#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "cosim/observers.h"
#include "loader/scenario.h"

namespace linesim::test_scenarios {

inline std::map<std::string, double> RunFile(const std::string& file,
                                             const std::vector<std::string>& sets) {
  loader::Scenario s = loader::LoadScenario(file, sets);
  cosim::MetricsObserver metrics(s.metrics);
  s.master->AddObserver(&metrics);
  const cosim::RunResult result = s.master->Run();
  EXPECT_TRUE(result.ok) << result.ErrorText();
  std::map<std::string, double> out;
  for (const auto& [metric, value] : metrics.Results()) out[metric] = value;
  std::cout << file;
  for (const auto& set : sets) std::cout << " --set " << set;
  for (const auto& [metric, value] : out) std::cout << "\n  " << metric << " = " << value;
  std::cout << "\n";
  return out;
}

/// A shipped scenario (scenarios/NAME.yaml).
inline std::string Shipped(const std::string& name) {
  return std::string(LINESIM_SOURCE_DIR "/scenarios/") + name + ".yaml";
}

}  // namespace linesim::test_scenarios
