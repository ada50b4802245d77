#include "session/run_folder.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>

#include "cosim/files.h"
#include "mcap/run_log.h"
#include "replay/replay_recorder.h"

namespace linesim::session {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

// The recording's size, said before anything runs: rows from the duration
// and the interval, each column at most 24 characters and its comma (a
// double's shortest round-trip text, sign and exponent included).
void CheckRecordingSize(const loader::Scenario& s, const std::string& file, double max_mb) {
  const cosim::MasterOptions& o = s.master->options();
  const double rows =
      std::floor(static_cast<double>(o.stop - o.start) /
                 static_cast<double>(std::max<cosim::TimeNs>(1, s.record_interval))) +
      2.0;
  const double bytes = rows * 25.0 * static_cast<double>(s.recorded.size() + 1);
  if (bytes > max_mb * 1024.0 * 1024.0) {
    throw OutputError(file + ": the recording would take up to " +
                      cosim::FormatValue(std::ceil(bytes / (1024.0 * 1024.0))) + " MB (" +
                      cosim::FormatValue(rows) + " rows of " +
                      std::to_string(s.recorded.size() + 1) + " columns), more than the " +
                      cosim::FormatValue(max_mb) +
                      " MB allowed: record fewer variables or at a longer recording.interval_s, "
                      "or raise the limit with --max-output-mb");
  }
}

// A previous run's outputs go first: the folder never holds files of two
// runs (a summary that fails to write must not leave the old one behind).
void RemovePrevious(const loader::Scenario& s, const fs::path& dir) {
  std::vector<std::string> previous = plots::RobotPlotFiles();
  if (s.robot) {
    for (const auto& other : s.robot->fleet) {
      for (auto& name : plots::RobotPlotFiles(other.name + "_")) previous.push_back(name);
    }
  }
  for (const char* name : {"summary.json", "replay.html", "run.mcap"}) previous.push_back(name);
  for (const auto& name : previous) {
    std::error_code ec;
    fs::remove(dir / name, ec);
    if (ec) {
      throw OutputError("cannot remove the previous run's " + (dir / name).string() + ": " +
                        ec.message());
    }
  }
}

}  // namespace

FolderRun RunIntoFolder(Session& session, const std::string& file, const std::string& out_dir,
                        const FolderOptions& options, const std::atomic<bool>* stop) {
  const loader::Scenario& s = session.scenario();
  CheckRecordingSize(s, file, options.max_output_mb);
  // Everything is checked: only now is anything written.
  const fs::path dir(out_dir);
  {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir, ec)) {
      throw OutputError("cannot create the output folder " + out_dir + ": " +
                        (ec ? ec.message() : "a file of that name exists"));
    }
  }
  RemovePrevious(s, dir);
  // A summary from the start, saying the run failed: the final one replaces
  // it; a run killed on the way, or whose final summary cannot be written,
  // still leaves a summary.json, and one that says what happened.
  try {
    Json started;
    started["scenario"] = s.name;
    started["file"] = file;
    started["status"] = "failed";
    started["errors"] = {
        "the run started but did not finish writing its summary (killed, or "
        "its final summary.json could not be written)"};
    cosim::WriteFileAtomically((dir / "summary.json").string(), started.dump(2) + "\n");
  } catch (const std::exception& e) {
    throw OutputError(e.what());
  }
  const fs::path csv_path = dir / "signals.csv";
  std::ofstream csv(csv_path, std::ios::binary | std::ios::trunc);
  if (!csv) throw OutputError("cannot write " + csv_path.string());

  cosim::CsvRecorder recorder(csv, s.recorded, s.record_interval);
  session.AddObserver(&recorder);
  // The replay page of a robot run (replay/): sampled by an observer.
  std::unique_ptr<replay::ReplayRecorder> replayer;
  if (s.robot && options.replay) {
    replayer = std::make_unique<replay::ReplayRecorder>(
        replay::ReplaySpecFor(s, s.robot->figure_bound.value_m, s.robot->figure_bound.label));
    session.AddObserver(replayer.get());
  }
  // The run for Foxglove and PlotJuggler, gathered as it runs.
  const fs::path mcap_path = dir / "run.mcap";
  std::ofstream mcap_file;
  std::unique_ptr<mcap::RunLog> mcap_log;
  if (options.mcap) {
    mcap_file.open(mcap_path, std::ios::binary | std::ios::trunc);
    if (!mcap_file) throw OutputError("cannot write " + mcap_path.string());
    mcap_log = std::make_unique<mcap::RunLog>(mcap_file, s);
    session.AddObserver(mcap_log.get());
  }

  FolderRun out;
  out.report = session.Run(stop);
  RunReport& report = out.report;
  csv.close();
  // A full disk shows only here (buffered writes fail late): a run whose
  // signals were lost has failed, whatever the units did.
  const bool csv_written = !csv.fail();
  if (!csv_written) {
    report.AddFailure("cannot write " + csv_path.string() +
                      " (disk full or not writable): the signals are incomplete");
  }
  if (mcap_log) {
    mcap_file.close();
    if (mcap_file.fail()) {
      report.AddFailure("cannot write " + mcap_path.string() + " (disk full or not writable)");
    }
    out.mcap = true;
  }
  out.rows = recorder.rows();

  Json summary = Summary(s, file, report);
  Json columns = Json::array();
  for (const auto& p : s.recorded) columns.push_back(p.label);
  summary["recording"] = {{"file", "signals.csv"},
                          {"rows", recorder.rows()},
                          {"interval_s", cosim::NsToSeconds(s.record_interval)},
                          {"columns", columns}};
  if (mcap_log) {
    summary["mcap"] = {
        {"file", "run.mcap"}, {"bytes", mcap_log->bytes()}, {"messages", mcap_log->messages()}};
  }
  // Robot runs are drawn (also a failed one: the plots show how it failed).
  if (s.robot && recorder.rows() > 0 && csv_written) {
    try {
      for (const auto& p : WriteRobotPlots(s, dir.string(), options.format)) {
        out.files.push_back(fs::path(p).filename().string());
      }
      summary["plots"] = {{"files", out.files}};
    } catch (const std::exception& e) {
      // The run itself is fine: say why there are no pictures, do not fail.
      summary["plots"] = {{"error", e.what()}};
      out.warnings.push_back(std::string("no plots: ") + e.what());
    }
  }
  if (replayer && replayer->frames() > 0) {
    try {
      replayer->Write((dir / "replay.html").string());
      out.files.push_back("replay.html");
      summary["replay"] = {{"file", "replay.html"}};
    } catch (const std::exception& e) {
      summary["replay"] = {{"error", e.what()}};  // as for the plots: the run stands
      out.warnings.push_back(std::string("no replay: ") + e.what());
    }
  }
  try {
    cosim::WriteFileAtomically((dir / "summary.json").string(), summary.dump(2) + "\n");
  } catch (const std::exception& e) {
    out.summary_error = e.what();
  }
  return out;
}

}  // namespace linesim::session
