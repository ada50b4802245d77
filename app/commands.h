#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "loader/robot_scenario.h"
#include "plots/gnuplot.h"

namespace linesim::sweep {
class MpiSession;
}

namespace linesim::app {

/// Exit statuses of the `linesim` command.
inline constexpr int kExitOk = 0;
inline constexpr int kExitRunFailed = 1;  // a unit failed during the run
inline constexpr int kExitBadInput = 2;   // wrong file, key, value or option

/// The most signals.csv a run may write unless --max-output-mb says more:
/// 1 GiB (a run of 10 minutes recording 100 columns at 1 kHz needs 1.3 GB).
inline constexpr double kDefaultMaxOutputMb = 1024.0;

/// What a robot run's plots read, for a caller that draws more from its
/// signals.csv (the comparison of runs).
struct RunColumns {
  std::string error_column;                 // deviation or drift ("" for none)
  std::vector<std::string> belt_on_columns;  // each belt's scheduled on state
  std::string task;                          // path, hold, route
  loader::RobotInfo::FigureBound bound;      // the scenario's figures.bound
};

/// `linesim run FILE --out DIR [--set path=value ...] [--max-output-mb N]
/// [--format png|svg|pdf]`. A run whose recording would exceed
/// `max_output_mb` (estimated from its rows, columns and the longest text a
/// number takes) is refused before it starts (exit 2, nothing written). A
/// file with a top-level `compare` key is a comparison of runs
/// (CompareCommand). `columns`, when given, receives what the plots read.
/// A robot run also writes DIR/replay.html (replay/) unless `replay` is
/// false (`--no-replay`).
/// `write_mcap` (--mcap): also DIR/run.mcap, the run for Foxglove and
/// PlotJuggler (mcap/run_log.h).
int RunCommand(const std::string& file, const std::string& out_dir,
               const std::vector<std::string>& set_args,
               double max_output_mb = kDefaultMaxOutputMb,
               plots::PlotFormat format = plots::PlotFormat::kPng,
               RunColumns* columns = nullptr, bool replay = true,
               bool write_mcap = false);

/// `linesim run COMPARE.yaml --out DIR`: every run the file lists, its base
/// scenario with the run's settings (and `set_args`), into DIR/FOLDER as
/// `linesim run` writes it, then their deviations or drifts over time in one
/// figure, DIR/comparison.png (app/compare_command.cc). Exit 0 when every
/// run is ok, 1 when one failed, 2 on bad input with nothing run.
/// Whether `file` is a comparison (a YAML map with a top-level `compare`).
bool IsComparisonFile(const std::string& file);

int CompareCommand(const std::string& file, const std::string& out_dir,
                   const std::vector<std::string>& set_args, double max_output_mb,
                   plots::PlotFormat format);

/// `linesim inspect TYPE|FILE [--set path=value ...]`.
int InspectCommand(const std::string& what, const std::vector<std::string>& set_args);

/// `linesim inspect --all`: every registered unit type with its variable
/// table, in Markdown (the text of docs/units.md).
int UnitReferenceCommand();

/// `linesim export-fmu TYPE [--set key=value ...] [--scene S] [--fmi 2|3]
/// --out NAME.fmu` (app/export_command.cc); fmi_version 0: automatic.
int ExportFmuCommand(const std::string& type, const std::vector<std::string>& set_args,
                     const std::string& scene, int fmi_version, const std::string& out);

struct SweepArgs {
  std::string file;
  std::string out_dir;
  int jobs = 1;
  bool jobs_given = false;  // --jobs on the command line (it means nothing under mpirun)
  bool resume = false;
  bool force = false;
  /// `linesim run FILE --runs N`: N > 0 makes `file` a scenario run N times
  /// with its own seed each (sweep::RepeatSweepSpec) with `sets` applied;
  /// afterwards the first run is run once more as `linesim run` into
  /// DIR/run_0 for its signals and plots.
  std::int64_t repeats = 0;
  std::vector<std::string> sets;
  double max_output_mb = kDefaultMaxOutputMb;  // for the repeats' run_0
  plots::PlotFormat format = plots::PlotFormat::kPng;  // run_0's pictures
  bool mcap = false;  // run_0 also writes run.mcap (--mcap)
};

/// `linesim sweep FILE --out DIR [--jobs N] [--resume|--force]`; under
/// mpirun `mpi` is the MPI session (rank 0 dispatches and writes, the other
/// ranks run), otherwise null and the runs go on `jobs` threads. Exits 0
/// when every run is ok, 1 when a run failed (it has a row with its error),
/// 2 on bad input with nothing written, 130 when interrupted. With
/// `repeats`, the same for `linesim run FILE --runs N`.
int SweepCommand(const SweepArgs& args, sweep::MpiSession* mpi);

}  // namespace linesim::app
