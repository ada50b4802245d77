#include "config/scenario_error.h"

namespace linesim::config {

std::string Issue::ToString() const {
  std::string out = file;
  if (line > 0) out += ":" + std::to_string(line);
  if (!key_path.empty()) out += (out.empty() ? "" : ": ") + key_path;
  if (from_command_line) out += " (set on the command line)";
  out += (out.empty() ? "" : ": ") + message;
  return out;
}

namespace {
std::string Join(const std::vector<Issue>& issues) {
  std::string out;
  for (const auto& i : issues) out += (out.empty() ? "" : "\n") + i.ToString();
  return out;
}
}  // namespace

ScenarioError::ScenarioError(std::vector<Issue> issues)
    : std::runtime_error(Join(issues)), issues_(std::move(issues)) {}

}  // namespace linesim::config
