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
  /// The most the run's files may take together (MiB): signals.csv, the
  /// plots' scripts with their data, replay.html and run.mcap, each at its
  /// longest (from the duration, the rates, the columns and the scene),
  /// checked before anything is written.
  double max_output_mb = 1024.0;  // the command line's default (--max-output-mb)
  plots::PlotFormat format = plots::PlotFormat::kPng;
  bool replay = true;  // replay.html of a robot run
  bool mcap = false;   // run.mcap
};

/// A file of the run at its longest, as RunIntoFolder checks it: its name,
/// the bound (bytes) and what the bound is made of.
struct OutputBound {
  std::string file;
  std::uint64_t bytes = 0;
  std::string detail;
};

/// The files `s` (loaded, not yet run) writes with `options`, each at its
/// longest: signals.csv (every row, each number at 25 characters), the
/// plots' scripts with the columns they copy from it, replay.html
/// (replay::ReplayBytesBound) and run.mcap (mcap::RunLog::BytesBound).
std::vector<OutputBound> OutputBounds(const loader::Scenario& s, const FolderOptions& options);

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
/// `dir`, as `linesim run --out` does: the outputs' sizes checked, the
/// previous run's files removed (those its summary.json lists under
/// `outputs`, and every name a run writes; nothing else of the folder), a
/// summary.json saying "started" first, signals.csv, the plots of a robot
/// run, replay.html, run.mcap (both saying how the run ended), and the
/// final summary.json. Throws OutputError before anything runs when the
/// files would be too large or the folder cannot be prepared (a folder it
/// made for the run is then removed again).
FolderRun RunIntoFolder(Session& session, const std::string& file, const std::string& dir,
                        const FolderOptions& options, const std::atomic<bool>* stop = nullptr);

}  // namespace linesim::session
