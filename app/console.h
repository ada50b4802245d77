#pragma once

#include <atomic>
#include <ostream>
#include <string>

#include "config/scenario_error.h"

namespace linesim::app {

/// "linesim: the WHAT is refused (N problems):" and one issue per line.
void PrintIssues(const config::ScenarioError& e, const std::string& what, std::ostream& out);

/// Creates the output folder `dir` (and its parents); false, after saying
/// why on stderr, when it cannot be made or a file has its name.
bool CreateOutputFolder(const std::string& dir);

/// Ctrl-C (SIGINT) and SIGTERM set the returned flag and print `message`
/// (a literal: it is written from the signal handler); a second signal ends
/// the process at once. The flag is the same for every caller.
std::atomic<bool>& InstallStopSignals(const char* message);

/// The exit status of a command stopped by a signal (the shell's for Ctrl-C).
inline constexpr int kExitInterrupted = 130;

}  // namespace linesim::app
