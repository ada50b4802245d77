#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace linesim::config {

/// One thing wrong with a scenario: where (file, line, key path) and what
/// (the bad value and what was expected).
struct Issue {
  std::string file;
  int line = 0;          // 1-based; 0 when unknown
  std::string key_path;  // "units.motors.parameters.resistance"
  std::string message;
  bool from_command_line = false;  // the value came from --set
  /// The key path itself is wrong (no such key or list item), as opposed to
  /// a bad value at a right path: a sweep refuses such a parameter path at
  /// once instead of failing every run.
  bool unknown_path = false;

  std::string ToString() const;
};

/// Every issue of a scenario at once; what() lists them one per line.
class ScenarioError : public std::runtime_error {
 public:
  explicit ScenarioError(std::vector<Issue> issues);
  const std::vector<Issue>& issues() const { return issues_; }

 private:
  std::vector<Issue> issues_;
};

}  // namespace linesim::config
