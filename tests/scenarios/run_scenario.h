#pragma once

// Runs a scenario file end to end as `linesim run` does (without writing
// files) and returns its metrics, printing them for the test log.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "cosim/observers.h"
#include "loader/scenario.h"
#include "tests/spread.h"

namespace linesim::test_scenarios {

inline std::map<std::string, double> RunFile(const std::string& file,
                                             const std::vector<std::string>& sets,
                                             bool print = true) {
  loader::Scenario s = loader::LoadScenario(file, sets);
  cosim::MetricsObserver metrics(s.metrics);
  s.master->AddObserver(&metrics);
  const cosim::RunResult result = s.master->Run();
  EXPECT_TRUE(result.ok) << result.ErrorText();
  std::map<std::string, double> out;
  for (const auto& [metric, value] : metrics.Results()) out[metric] = value;
  if (!print) return out;
  std::cout << file;
  for (const auto& set : sets) std::cout << " --set " << set;
  for (const auto& [metric, value] : out) std::cout << "\n  " << metric << " = " << value;
  std::cout << "\n";
  return out;
}

/// Every metric of a file run for seeds first..first+count-1 (the
/// scenario's top-level `seed:`, set after `sets`), one value per seed in
/// seed order.
struct SeedRuns {
  std::vector<std::uint64_t> seeds;
  std::map<std::string, test_spread::Spread> metrics;

  /// One metric's spread; a metric the scenario does not have fails the test.
  const test_spread::Spread& operator[](const std::string& metric) const {
    const auto it = metrics.find(metric);
    if (it == metrics.end()) {
      ADD_FAILURE() << "no metric " << metric;
      static const test_spread::Spread kNone{{std::nan("")}};
      return kNone;
    }
    return it->second;
  }
};

/// Seeds a closed-loop test runs in the sanitizer build (tools/sanitize.sh):
/// there it looks for memory errors and undefined behaviour, which the
/// first seeds exercise on the same code paths as the rest; the spread over
/// every seed is checked by the Release build's run of the same test.
#ifdef LINESIM_SANITIZED
inline constexpr int kSanitizerSeeds = 2;
#endif

/// Runs `file` with `sets` once per seed and prints each metric's
/// min / median / max over the seeds.
inline SeedRuns RunSeeds(const std::string& file, std::vector<std::string> sets, int count,
                         std::uint64_t first = 1) {
#ifdef LINESIM_SANITIZED
  count = std::min(count, kSanitizerSeeds);
#endif
  SeedRuns runs;
  sets.push_back("");
  for (int i = 0; i < count; ++i) {
    const std::uint64_t seed = first + static_cast<std::uint64_t>(i);
    sets.back() = "seed=" + std::to_string(seed);
    runs.seeds.push_back(seed);
    for (const auto& [metric, value] : RunFile(file, sets, false)) {
      runs.metrics[metric].values.push_back(value);
      runs.metrics[metric].seeds.push_back(seed);
    }
  }
  sets.pop_back();
  std::cout << file;
  for (const auto& set : sets) std::cout << " --set " << set;
  std::cout << ", seeds " << first << ".." << first + static_cast<std::uint64_t>(count) - 1;
  for (const auto& [metric, spread] : runs.metrics) {
    std::cout << "\n  " << metric << ": " << spread.Text();
  }
  std::cout << "\n";
  return runs;
}

/// A shipped scenario (scenarios/NAME.yaml).
inline std::string Shipped(const std::string& name) {
  return std::string(LINESIM_SOURCE_DIR "/scenarios/") + name + ".yaml";
}

}  // namespace linesim::test_scenarios
