#pragma once

#include <ostream>
#include <string>

#include "config/scenario_error.h"

namespace linesim::app {

/// "linesim: the WHAT is refused (N problems):" and one issue per line.
void PrintIssues(const config::ScenarioError& e, const std::string& what, std::ostream& out);

/// Creates the output folder `dir` (and its parents); false, after saying
/// why on stderr, when it cannot be made or a file has its name.
bool CreateOutputFolder(const std::string& dir);

}  // namespace linesim::app
