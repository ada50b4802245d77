#pragma once

#include <string>
#include <vector>

namespace linesim::app {

/// Exit statuses of the `linesim` command.
inline constexpr int kExitOk = 0;
inline constexpr int kExitRunFailed = 1;  // a unit failed during the run
inline constexpr int kExitBadInput = 2;   // wrong file, key, value or option

/// `linesim run FILE --out DIR [--set path=value ...]`.
int RunCommand(const std::string& file, const std::string& out_dir,
               const std::vector<std::string>& set_args);

/// `linesim inspect TYPE|FILE [--set path=value ...]`.
int InspectCommand(const std::string& what, const std::vector<std::string>& set_args);

}  // namespace linesim::app
