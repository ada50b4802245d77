#pragma once

#include <atomic>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "plots/robot_plots.h"
#include "session/session.h"

namespace linesim::session {

/// The folder could not be prepared, or the recording would be too large:
/// nothing ran (the message says which file and why).
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct FolderOptions {
  /// The most signals.csv may take (an estimate from the duration, the
  /// interval and the columns, checked before anything is written).
  double max_output_mb = 1024.0;  // the command line's default (--max-output-mb)
  plots::PlotFormat format = plots::PlotFormat::kPng;
  bool replay = true;  // replay.html of a robot run
  bool mcap = false;   // run.mcap
};

/// What RunIntoFolder wrote besides the report.
struct FolderRun {
  RunReport report;
  std::int64_t rows = 0;           // of signals.csv
  std::vector<std::string> files;  // plots and replay.html, by name
  bool mcap = false;               // run.mcap written
  /// Why plots or the replay are missing although the run stands.
  std::vector<std::string> warnings;
  /// Non-empty when the final summary.json could not be written (the run
  /// then counts as failed: the started one says so).
  std::string summary_error;
};

/// Runs `session` (its scenario file `file` as given) into the folder
/// `dir`, as `linesim run --out` does: the previous run's files removed, a
/// summary.json saying "started" first, signals.csv, the plots of a robot
/// run, replay.html, run.mcap, and the final summary.json. Throws
/// OutputError before anything runs when the folder cannot be prepared.
FolderRun RunIntoFolder(Session& session, const std::string& file, const std::string& dir,
                        const FolderOptions& options, const std::atomic<bool>* stop = nullptr);

}  // namespace linesim::session
