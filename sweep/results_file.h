#pragma once

#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sweep/run_one.h"
#include "sweep/run_plan.h"
#include "sweep/sweep_spec.h"
#include "sweep/sweep_table.h"

namespace linesim::sweep {

/// Column names of results.csv: run_id, each parameter path, seed, each
/// metric, status, error, error_unit, error_time_s, error_phase,
/// error_variable, error_cause, wall_s, row_check (FNV-1a 64 of the row's
/// fields before wall_s, 16 hex digits: Resume drops a row changed by
/// accident; it is no proof against a deliberate edit, see RowCheck).
/// `error` is the whole message; the
/// error_* columns are the first failure's fields (cosim::RunError), empty
/// for an ok run or a field that does not apply.
std::vector<std::string> ResultsHeader(const SweepSpec& spec);

/// One line of results.csv (with its newline). Numbers are written as the
/// shortest text that reads back to the same double, so rows are the same
/// bytes on any machine, thread or rank; only wall_s differs between runs
/// (row_check leaves it out, so it does not).
std::string FormatRow(const RunSpec& run, const RunOutcome& outcome);

/// CSV fields, RFC 4180 quoting; nothing when a quote is left open (a line
/// cut off by a killed process).
std::optional<std::vector<std::string>> SplitCsvLine(std::string_view line);
std::string JoinCsvLine(const std::vector<std::string>& fields);

/// A fingerprint of everything that decides the rows: every file the base
/// scenario's loads read, by content (spec.inputs: scenario, robot, scene,
/// motor and sensor models, route graphs, FMUs, wherever they lie), and the
/// sweep's settings and metrics; SHA-256, 64 hex digits. A resumed sweep,
/// and every MPI rank, must match it.
std::string SweepFingerprint(const SweepSpec& spec);

/// sweep.json, which says what sweep a folder holds: name, files, run count,
/// SweepFingerprint and `inputs`, every file the rows' runs read (absolute
/// path -> SHA-256). Written atomically; throws std::runtime_error.
void WriteSweepIdentity(const std::string& path, const SweepSpec& spec,
                        const std::string& fingerprint,
                        const std::map<std::string, std::string>& inputs);
struct SweepIdentity {
  std::string fingerprint;
  std::map<std::string, std::string> inputs;
};
/// What a sweep.json holds; nothing when it is missing, unreadable or
/// lacks a field.
std::optional<SweepIdentity> ReadSweepIdentity(const std::string& path);
/// The files of `inputs` whose bytes are no longer the recorded ones, each
/// as "path (what changed)"; empty when every file is as it was.
std::vector<std::string> ChangedInputs(const std::map<std::string, std::string>& inputs);

/// The results.csv of a sweep folder, written as runs finish: one flushed
/// line per run (completion order), then sorted by run id at the end.
class ResultsFile {
 public:
  /// Starts `path` afresh with the header; throws std::runtime_error naming
  /// the file when it cannot be written.
  static ResultsFile Create(const std::string& path, const SweepSpec& spec);
  /// Continues `path`: keeps every complete row of a planned run (the first
  /// of duplicates) and drops a line cut off by a kill, rewriting the file
  /// through a temporary and a rename. A row is checked, not trusted: one
  /// whose parameter values or seed are not the plan's for its run id,
  /// whose status is neither ok nor failed, whose ok metrics or wall time
  /// do not read as finite numbers (a failed run's may be empty) is dropped
  /// (its run is done again) and counted in dropped_count(); so is a row
  /// whose row_check is not its fields' (a row edited by accident). Throws
  /// std::runtime_error when the header is not this sweep's.
  static ResultsFile Resume(const std::string& path, const SweepSpec& spec);

  ResultsFile(ResultsFile&& other) noexcept;
  ResultsFile& operator=(ResultsFile&&) = delete;
  ~ResultsFile();

  bool HasRow(std::int64_t id) const { return rows_.count(id) != 0; }
  std::size_t row_count() const { return rows_.size(); }
  /// From now on Append checks each run's files against `inputs` (those
  /// of the rows so far, as sweep.json at `identity_path` holds them) and
  /// rewrites sweep.json with the new ones before writing the row.
  void TrackInputs(std::string identity_path, const SweepSpec& spec, std::string fingerprint,
                   std::map<std::string, std::string> inputs);
  /// Appends and flushes one row, whose run read `inputs`; throws
  /// std::runtime_error on a write failure (disk full) and, with
  /// TrackInputs, when the run read a file whose bytes differ from what
  /// the rows before it were computed from (the row is not written).
  void Append(std::int64_t id, const std::string& line, bool ok,
              const std::map<std::string, std::string>& inputs = {});
  /// Rows whose run failed.
  std::int64_t failed_count() const { return failed_; }
  /// Rows Resume dropped because they did not match the plan.
  std::int64_t dropped_count() const { return dropped_; }
  /// Rewrites the file with its rows sorted by run id (temporary and rename).
  void SortByRunId();
  /// The rows parsed for the report, sorted by run id.
  SweepTable Table(const SweepSpec& spec) const;

 private:
  ResultsFile(std::string path, std::string header, std::FILE* file,
              std::map<std::int64_t, std::string> rows);
  void Rewrite();

  std::string path_;
  std::string header_;
  std::FILE* file_ = nullptr;
  std::map<std::int64_t, std::string> rows_;  // run id -> line with its newline
  std::int64_t failed_ = 0;
  std::int64_t dropped_ = 0;
  // TrackInputs: sweep.json and the files every row so far was computed from.
  bool tracking_ = false;
  std::string identity_path_;
  SweepSpec identity_spec_;
  std::string fingerprint_;
  std::map<std::string, std::string> inputs_;
};

}  // namespace linesim::sweep
