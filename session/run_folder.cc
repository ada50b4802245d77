#include "session/run_folder.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>

#include "cosim/files.h"
#include "cosim/system.h"
#include "mcap/run_log.h"
#include "replay/replay_recorder.h"

namespace linesim::session {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

constexpr double kBytesPerMb = 1024.0 * 1024.0;
// The longest text of a number in signals.csv and plots.gp, its comma
// included (a double's shortest round-trip text, sign and exponent).
constexpr std::uint64_t kCsvNumberBytes = 25;

std::uint64_t RecordedRows(const loader::Scenario& s) {
  const cosim::MasterOptions& o = s.master->options();
  return static_cast<std::uint64_t>(std::max<cosim::TimeNs>(o.stop - o.start, 0) /
                                    std::max<cosim::TimeNs>(1, s.record_interval)) +
         2;
}

// One robot's plots.gp at its longest: the columns its time plots copy
// from signals.csv on every row (time, position, error, belts' speed and
// on state, optic flow, the safety function's; plots/robot_plots.cc's
// $signals block) and, over terrain, the height profile (three numbers a
// row); the other robots' and workers' tracks (at most about 1,000 points
// each); the scene's outlines (a belt's direction arrows every metre, a
// cylinder as a polygon); the desired path; the snapshot scan; the
// script's own text.
std::uint64_t PlotsBytes(const loader::RobotInfo& robot, std::size_t other_robots,
                         const models::Scene& scene, std::uint64_t rows) {
  const std::uint64_t n = kCsvNumberBytes;
  const std::uint64_t columns =
      3 + (robot.error_column.empty() ? 0 : 1) + (robot.flow_reference_column.empty() ? 0 : 1) +
      (robot.speed_cap_column.empty() ? 0 : 6) + robot.belt_speed_columns.size() +
      robot.belt_on_columns.size() + robot.flow_columns.size() + robot.flow_truth_columns.size() +
      robot.flow_filtered_columns.size() + (robot.z_column.empty() ? 0 : 3);
  std::uint64_t bytes = rows * columns * n;
  bytes += (robot.worker_columns.size() + other_robots) * 1002 * 2 * n;
  constexpr std::uint64_t kSolid = 72 * 2 * kCsvNumberBytes + 256;
  bytes += (scene.obstacles.size() + 2 * scene.carried.size() + scene.terrain.size()) * kSolid;
  for (const models::Belt& b : scene.belts) {
    bytes += kSolid +
             static_cast<std::uint64_t>(std::min(std::max(b.area.length_m, 0.0), 1e9) + 2) * 4 * n;
  }
  bytes += robot.path.size() * 2 * n;
  if (robot.scan_geometry) bytes += static_cast<std::uint64_t>(robot.scan_geometry->beams) * 3 * n;
  // Outlines at five instants (body and wheels, this robot and the others),
  // labels and the script's text with the names in it.
  bytes += 5 * (1 + other_robots) * (5 + robot.wheel_columns.size()) * 2 * n;
  std::uint64_t names = 0;
  for (const auto& s : scene.surfaces) names += s.name.size();
  for (const auto& b : scene.belts) names += b.name.size();
  for (const auto& o : scene.obstacles) names += o.name.size();
  for (const auto& c : scene.carried) names += c.name.size();
  for (const auto& t : scene.terrain) names += t.name.size();
  return bytes + 64 * 1024 + 4 * names;
}

std::string Megabytes(std::uint64_t bytes) {
  return cosim::FormatValue(std::ceil(static_cast<double>(bytes) / kBytesPerMb * 10.0) / 10.0) +
         " MB";
}

// Their sum may not pass --max-output-mb, said before anything runs.
void CheckOutputSizes(const std::vector<OutputBound>& files, const std::string& file,
                      const FolderOptions& options, bool replay) {
  std::uint64_t total = 0;
  for (const auto& f : files) total += f.bytes;
  if (static_cast<double>(total) <= options.max_output_mb * kBytesPerMb) return;
  std::string list;
  for (const auto& f : files) {
    list += (list.empty() ? "" : ", ") + f.file + " up to " + Megabytes(f.bytes) + " (" + f.detail +
            ")";
  }
  throw OutputError(
      file + ": the run's files would take up to " + Megabytes(total) + ", more than the " +
      cosim::FormatValue(options.max_output_mb) + " MB allowed (--max-output-mb): " + list +
      ". Record fewer variables or at a longer recording.interval_s, run a shorter duration_s" +
      (replay ? ", leave out the replay (--no-replay)" : "") +
      (options.mcap ? ", leave out run.mcap" : "") + ", or raise the limit with --max-output-mb");
}

// The plot files (script and pictures in `format`) of a robot with `prefix`.
std::vector<std::string> PlotFiles(const std::string& prefix, plots::PlotFormat format) {
  const std::string extension = "." + std::string(plots::PlotExtension(format));
  std::vector<std::string> names;
  for (auto& name : plots::RobotPlotFiles(prefix)) {
    if (name.ends_with(".gp") || name.ends_with(extension)) names.push_back(std::move(name));
  }
  return names;
}

// Every file this run may write into its folder, by name.
std::vector<std::string> Outputs(const loader::Scenario& s, const FolderOptions& options) {
  std::vector<std::string> names = {"summary.json", "signals.csv"};
  if (s.robot) {
    for (auto& n : PlotFiles("", options.format)) names.push_back(std::move(n));
    for (const auto& other : s.robot->fleet) {
      for (auto& n : PlotFiles(other.name + "_", options.format)) names.push_back(std::move(n));
    }
    if (options.replay) names.push_back("replay.html");
  }
  if (options.mcap) names.push_back("run.mcap");
  return names;
}

// Whether `name` is one linesim writes into a run's folder: a fixed name,
// or a robot's plot file, unprefixed or prefixed with a robot's name and
// '_' (letters, digits, '_': cosim::IsIdentifier).
bool IsOutputName(const std::string& name) {
  for (const char* fixed : {"summary.json", "signals.csv", "replay.html", "run.mcap"}) {
    if (name == fixed) return true;
  }
  for (const auto& plot : plots::RobotPlotFiles()) {
    if (name == plot) return true;
    if (name.size() > plot.size() + 1 && name.ends_with("_" + plot) &&
        cosim::IsIdentifier(name.substr(0, name.size() - plot.size() - 1))) {
      return true;
    }
  }
  return false;
}

// The files the previous run in the folder wrote, by its summary.json: a
// linesim summary (an object with `scenario` and `status`) lists them under
// `outputs` (older ones: their plots' pictures, whose prefixes name the
// robots, and their replay, log and signals). Only names linesim writes
// count; anything else the folder holds is the user's.
std::vector<std::string> PreviousOutputs(const fs::path& dir) {
  std::vector<std::string> names;
  std::ifstream in(dir / "summary.json", std::ios::binary);
  if (!in) return names;
  const Json summary = Json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!summary.is_object() || !summary.contains("scenario") || !summary.contains("status")) {
    return names;
  }
  const auto add = [&](const Json& v) {
    if (v.is_string() && IsOutputName(v.get<std::string>())) names.push_back(v.get<std::string>());
  };
  if (summary.contains("outputs") && summary["outputs"].is_array()) {
    for (const auto& v : summary["outputs"]) add(v);
  }
  if (summary.contains("plots") && summary["plots"].is_object() &&
      summary["plots"].contains("files") && summary["plots"]["files"].is_array()) {
    for (const auto& v : summary["plots"]["files"]) {
      if (!v.is_string()) continue;
      const std::string picture = v.get<std::string>();
      for (const auto& plot : plots::RobotPlotFiles()) {
        if (!picture.ends_with(plot)) continue;
        for (auto& n : plots::RobotPlotFiles(picture.substr(0, picture.size() - plot.size()))) {
          if (IsOutputName(n)) names.push_back(std::move(n));
        }
      }
    }
  }
  for (const char* key : {"replay", "mcap", "recording"}) {
    if (summary.contains(key) && summary[key].is_object() && summary[key].contains("file")) {
      add(summary[key]["file"]);
    }
  }
  return names;
}

// A previous run's outputs go first: the folder never holds files of two
// runs (a summary that fails to write must not leave the old one behind).
// What is removed: the files the previous run's summary lists, the names
// every run writes, and the files this run may write; each with its ".tmp"
// (a write cut off by a kill); but signals.csv, written over.
void RemovePrevious(const fs::path& dir, const std::vector<std::string>& outputs) {
  std::set<std::string> previous(outputs.begin(), outputs.end());
  for (auto& name : PreviousOutputs(dir)) previous.insert(std::move(name));
  for (auto& name : plots::RobotPlotFiles()) previous.insert(std::move(name));
  for (const char* name : {"summary.json", "replay.html", "run.mcap"}) previous.insert(name);
  // signals.csv is written over from its start right after: what stands at
  // its name (a link the user made to another disk) is written to, not
  // removed.
  previous.erase("signals.csv");
  for (const auto& name : previous) {
    for (const std::string& file : {name, name + ".tmp"}) {
      std::error_code ec;
      fs::remove(dir / file, ec);
      // A name too long for the file system cannot be there.
      if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::filename_too_long) {
        throw OutputError("cannot remove the previous run's " + (dir / file).string() + ": " +
                          ec.message());
      }
    }
  }
}

// Creates `dir` and its missing parents; returns those it created, the
// deepest first (to be taken back if the run cannot start).
std::vector<fs::path> CreateFolder(const fs::path& dir) {
  std::vector<fs::path> missing;
  std::error_code ec;
  for (fs::path p = dir; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir, ec)) {
    throw OutputError("cannot create the output folder " + dir.string() + ": " +
                      (ec ? ec.message() : "a file of that name exists"));
  }
  return missing;
}

// How the run ended, for the replay and the log: the status, the time
// reached and the time it was to reach, and why when not ok.
struct Ending {
  std::string status;
  cosim::TimeNs end = 0, stop = 0;
  std::string message;
};

Ending EndingOf(const loader::Scenario& s, const RunReport& report) {
  Ending e{report.status(), report.result.end_time, s.master->options().stop, ""};
  if (report.interrupted) {
    e.message = "stopped by Ctrl-C or SIGTERM";
  } else if (!report.errors.empty()) {
    e.message = report.errors.front().message;
  } else if (!report.result.ended_by.empty()) {
    e.message = "ended early by " + report.result.ended_by;
  }
  return e;
}

}  // namespace

std::vector<OutputBound> OutputBounds(const loader::Scenario& s, const FolderOptions& options) {
  std::vector<OutputBound> files;
  const std::uint64_t rows = RecordedRows(s);
  files.push_back({"signals.csv", rows * kCsvNumberBytes * (s.recorded.size() + 1),
                   cosim::FormatValue(static_cast<double>(rows)) + " rows of " +
                       std::to_string(s.recorded.size() + 1) + " columns"});
  if (s.robot) {
    const std::size_t others = s.robot->fleet.size();
    std::uint64_t plots = PlotsBytes(*s.robot, others, s.scene, rows);
    for (const auto& other : s.robot->fleet) plots += PlotsBytes(other, others, s.scene, rows);
    files.push_back({others > 0 ? "the plots.gp files" : "plots.gp", plots,
                     others > 0 ? "one per robot, with their data" : "with its data"});
    if (options.replay) {
      const replay::ReplaySpec spec =
          replay::ReplaySpecFor(s, s.robot->figure_bound.value_m, s.robot->figure_bound.label);
      const cosim::MasterOptions& o = s.master->options();
      const auto frames = std::max<cosim::TimeNs>(o.stop - o.start, 0) /
                              std::max<cosim::TimeNs>(1, spec.rates.frame_interval) +
                          1;
      files.push_back(
          {"replay.html", replay::ReplayBytesBound(spec, o.start, o.stop),
           std::to_string(frames) + " frames" +
               (spec.lasers.empty() ? ""
                                    : ", the scans of " + std::to_string(spec.lasers.size()) +
                                          (spec.lasers.size() == 1 ? " laser" : " lasers"))});
    }
  }
  if (options.mcap) {
    files.push_back({"run.mcap", mcap::RunLog::BytesBound(s), "as if nothing compressed"});
  }
  return files;
}

FolderRun RunIntoFolder(Session& session, const std::string& file, const std::string& out_dir,
                        const FolderOptions& options, const std::atomic<bool>* stop) {
  const loader::Scenario& s = session.scenario();
  CheckOutputSizes(OutputBounds(s, options), file, options, s.robot && options.replay);
  // Everything is checked: only now is anything written.
  const fs::path dir(out_dir);
  const std::vector<std::string> outputs = Outputs(s, options);
  const std::vector<fs::path> created = CreateFolder(dir);
  try {
    RemovePrevious(dir, outputs);
    // A summary from the start, saying the run failed: the final one
    // replaces it; a run killed on the way, or whose final summary cannot
    // be written, still leaves a summary.json, and one that says what
    // happened and which files it may have written.
    Json started;
    started["scenario"] = s.name;
    started["file"] = file;
    started["status"] = "failed";
    started["errors"] = {
        "the run started but did not finish writing its summary (killed, or "
        "its final summary.json could not be written)"};
    started["outputs"] = outputs;
    cosim::WriteFileAtomically((dir / "summary.json").string(), started.dump(2) + "\n");
  } catch (const std::exception& e) {
    // Nothing of this run stays: the folders it made go too (if empty).
    for (const fs::path& p : created) {
      std::error_code ec;
      fs::remove(p, ec);
    }
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
  const Ending ending = EndingOf(s, report);
  if (mcap_log) {
    mcap_log->Close({ending.status, ending.end, ending.stop, ending.message});
    mcap_file.close();
    if (mcap_file.fail()) {
      report.AddFailure("cannot write " + mcap_path.string() + " (disk full or not writable)");
    }
    out.mcap = true;
  }
  out.rows = recorder.rows();

  Json summary = Summary(s, file, report);
  summary["outputs"] = outputs;
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
    replayer->SetOutcome({ending.status, cosim::NsToSeconds(ending.end),
                          cosim::NsToSeconds(ending.stop), ending.message});
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
