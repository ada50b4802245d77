#include "app/commands.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/console.h"
#include "config/unit_registry.h"
#include "cosim/files.h"
#include "cosim/observers.h"
#include "cosim/run_error_json.h"
#include "loader/scenario.h"
#include "mcap/run_log.h"
#include "platform/provenance.h"
#include "plots/robot_plots.h"
#include "replay/replay_recorder.h"
#include "units/fmu/fmu_unit.h"

namespace linesim::app {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

Json Number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

std::string TypeLabel(const cosim::VariableInfo& v) {
  if (v.type == cosim::VarType::kRealArray) return "Real[" + std::to_string(v.size) + "]";
  return std::string(cosim::ToString(v.type));
}

// The variable table as aligned columns; "start" is the value the unit
// starts with: its declared start value, or what the scenario set; "rule"
// the values a parameter accepts ("> 0", "(0, 1]", "one of: a, b",
// "required"), "-" for none.
constexpr int kTableColumns = 7;
using TableRow = std::array<std::string, kTableColumns>;

std::vector<TableRow> TableRows(const cosim::Unit& unit) {
  std::vector<TableRow> rows{{"name", "causality", "type", "unit", "start", "rule", "description"}};
  const auto& table = unit.variables();
  for (const auto& v : table.infos()) {
    std::string description = v.description;
    if (!v.depends_on.empty()) {
      description += " [depends directly on:";
      for (auto ref : v.depends_on) description += " " + table.info(ref).name;
      description += "]";
    }
    rows.push_back({v.name, std::string(cosim::ToString(v.causality)), TypeLabel(v),
                    v.unit.empty() ? "-" : v.unit, cosim::FormatValue(table.GetValue(v.ref)),
                    v.rule.empty() ? "-" : v.rule.Text(), description});
  }
  return rows;
}

void PrintTable(const cosim::Unit& unit, std::ostream& out) {
  const std::vector<TableRow> rows = TableRows(unit);
  std::size_t width[kTableColumns - 1] = {};
  for (const auto& r : rows) {
    for (int c = 0; c + 1 < kTableColumns; ++c) width[c] = std::max(width[c], r[c].size());
  }
  for (const auto& r : rows) {
    out << "  ";
    for (int c = 0; c + 1 < kTableColumns; ++c)
      out << std::left << std::setw(static_cast<int>(width[c]) + 2) << r[c];
    out << r[kTableColumns - 1] << "\n";
  }
}

// A table cell in Markdown: a '|' would end the cell.
std::string MarkdownCell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

void PrintMarkdownTable(const cosim::Unit& unit, std::ostream& out) {
  const std::vector<TableRow> rows = TableRows(unit);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    out << "|";
    for (const auto& cell : rows[i]) out << " " << MarkdownCell(cell) << " |";
    out << "\n";
    if (i == 0) out << "|---|---|---|---|---|---|---|\n";
  }
}

// Paper 1, Sec. VI-B: with the modified system the maximum deviation
// crossing the line at 0.10 m/s is under 4 cm; the robot-level plots draw
// it as the bound the deviation and the holds' drift are judged by.
constexpr double kPaperBoundM = 0.04;
constexpr const char* kPaperBoundLabel = "4 cm (paper 1, Sec. VI-B)";

// What the plots of a robot run draw, by the columns the robot expansion
// names.
// `robot` is the scenario's robot, or in a fleet any of its robots (the
// others drawn in its top view).
plots::RobotPlotSpec PlotSpec(const loader::Scenario& s, plots::PlotFormat format,
                              const loader::RobotInfo& robot, const loader::RobotInfo* first) {
  plots::RobotPlotSpec spec;
  spec.title = s.name;
  spec.scene = s.scene;
  spec.path_m = robot.path;
  spec.x_column = robot.x_column;
  spec.y_column = robot.y_column;
  spec.yaw_column = robot.yaw_column;
  spec.z_column = robot.z_column;
  spec.wheel_columns = robot.wheel_columns;
  spec.error_column = robot.error_column;
  spec.error_label =
      robot.task != "hold" ? "deviation from the path (m)" : "drift from the held position (m)";
  spec.error_name = robot.task != "hold" ? "deviation of the robot's centre from the desired path"
                                         : "drift of the robot's centre from the held position";
  spec.error_bound_m = kPaperBoundM;
  spec.error_bound_label = kPaperBoundLabel;
  spec.format = format;
  spec.belt_speed_columns = robot.belt_speed_columns;
  spec.belt_on_columns = robot.belt_on_columns;
  spec.belt_travel_columns = robot.belt_travel_columns;
  spec.flow_columns = robot.flow_columns;
  spec.flow_labels = robot.flow_sensor_names;
  spec.flow_truth_columns = robot.flow_truth_columns;
  spec.flow_filtered_columns = robot.flow_filtered_columns;
  spec.flow_reference_column = robot.flow_reference_column;
  spec.worker_columns = robot.worker_columns;
  // A fleet: each robot's plots, with the others in the top view; the
  // first robot's files have no prefix, the others' their name.
  spec.robot_name = robot.name;
  const loader::RobotInfo& lead = first != nullptr ? *first : robot;
  const auto add_other = [&](const loader::RobotInfo& other) {
    if (other.name == robot.name) return;
    spec.others.push_back({other.name, other.x_column, other.y_column, other.yaw_column,
                           other.body_length_m.value_or(0.0), other.body_width_m.value_or(0.0)});
  };
  add_other(lead);
  for (const loader::RobotInfo& other : lead.fleet) add_other(other);
  if (first != nullptr && robot.name != first->name) spec.file_prefix = robot.name + "_";
  if (!robot.name.empty()) spec.title = s.name + " (" + robot.name + ")";
  spec.safety = {robot.velocity_x_column, robot.velocity_y_column, robot.speed_cap_column,
                 robot.protective_column,  robot.warning_column,    robot.person_distance_column};
  if (!robot.scan_unit.empty()) {
    // The beams' geometry is the laser unit's: read its parameters.
    for (std::size_t u = 0; u < s.system->unit_count(); ++u) {
      const cosim::Unit& unit = s.system->unit(u);
      if (unit.name() != robot.scan_unit) continue;
      const cosim::VariableTable& v = unit.variables();
      const auto real = [&](const char* name) { return v.GetReal(*v.Find(name)); };
      plots::RobotPlotSpec::Scan& scan = spec.scan;
      scan.sensor = robot.scan_unit;
      scan.time_s = robot.scan_time_s;
      scan.mount_x_m = real("mount_x");
      scan.mount_y_m = real("mount_y");
      scan.mount_yaw_rad = real("mount_yaw");
      scan.first_beam_rad = real("first_beam_angle");
      scan.beam_step_rad = real("angular_step");
      scan.no_return_m = real("no_return_value");
      const std::size_t beams = v.info(*v.Find("ranges")).size;
      for (std::size_t k = 0; k < beams; ++k) {
        scan.range_columns.push_back(robot.scan_unit + ".ranges[" + std::to_string(k) + "]");
      }
      scan.scan_time_column = robot.scan_unit + ".scan_time";
    }
  }
  if (robot.body_length_m) spec.body_length_m = *robot.body_length_m;
  if (robot.body_width_m) spec.body_width_m = *robot.body_width_m;
  return spec;
}

}  // namespace

int RunCommand(const std::string& file, const std::string& out_dir,
               const std::vector<std::string>& set_args, double max_output_mb,
               plots::PlotFormat format, RunColumns* plot_columns, bool replay,
               bool write_mcap) {
  if (IsComparisonFile(file)) {
    if (write_mcap) {
      std::cerr << "linesim: " << file
                << ": --mcap writes the log of one run; a comparison file (compare:) runs "
                   "several: run the one you want to see as a scenario with --mcap\n";
      return kExitBadInput;
    }
    return CompareCommand(file, out_dir, set_args, max_output_mb, format);
  }
  loader::Scenario s;
  try {
    s = loader::LoadScenario(file, set_args);
  } catch (const config::ScenarioError& e) {
    PrintIssues(e, "scenario", std::cerr);
    return kExitBadInput;
  }
  // The recording's size, said before anything runs: rows from the
  // duration and the interval, each column at most 24 characters and its
  // comma (a double's shortest round-trip text, sign and exponent included).
  {
    const cosim::MasterOptions& o = s.master->options();
    const double rows =
        std::floor(static_cast<double>(o.stop - o.start) /
                   static_cast<double>(std::max<cosim::TimeNs>(1, s.record_interval))) +
        2.0;
    const double bytes = rows * 25.0 * static_cast<double>(s.recorded.size() + 1);
    if (bytes > max_output_mb * 1024.0 * 1024.0) {
      std::cerr << "linesim: " << file << ": the recording would take up to "
                << cosim::FormatValue(std::ceil(bytes / (1024.0 * 1024.0))) << " MB ("
                << cosim::FormatValue(rows) << " rows of " << s.recorded.size() + 1
                << " columns), more than the " << cosim::FormatValue(max_output_mb)
                << " MB allowed: record fewer variables or at a longer recording.interval_s, "
                   "or raise the limit with --max-output-mb\n";
      return kExitBadInput;
    }
  }

  // Everything is checked: only now is anything written.
  const fs::path dir(out_dir);
  if (!CreateOutputFolder(out_dir)) return kExitBadInput;
  // A previous run's outputs go first: the folder never holds files of two
  // runs (a summary that fails to write must not leave the old one behind).
  {
    std::vector<std::string> previous = plots::RobotPlotFiles();
    if (s.robot) {
      for (const auto& other : s.robot->fleet) {
        for (auto& name : plots::RobotPlotFiles(other.name + "_")) previous.push_back(name);
      }
    }
    previous.push_back("summary.json");
    previous.push_back("replay.html");
    previous.push_back("run.mcap");
    for (const auto& name : previous) {
      std::error_code ec;
      fs::remove(dir / name, ec);
      if (ec) {
        std::cerr << "linesim: cannot remove the previous run's " << (dir / name).string() << ": "
                  << ec.message() << "\n";
        return kExitBadInput;
      }
    }
  }
  // A summary from the start, saying the run failed: the final one replaces
  // it; a run killed on the way, or whose final summary cannot be written,
  // still leaves a summary.json, and one that says what happened.
  try {
    Json started;
    started["scenario"] = s.name;
    started["file"] = file;
    started["status"] = "failed";
    started["errors"] = {"the run started but did not finish writing its summary (killed, or "
                         "its final summary.json could not be written)"};
    cosim::WriteFileAtomically((dir / "summary.json").string(), started.dump(2) + "\n");
  } catch (const std::exception& e) {
    std::cerr << "linesim: " << e.what() << "\n";
    return kExitBadInput;
  }
  const fs::path csv_path = dir / "signals.csv";
  std::ofstream csv(csv_path, std::ios::binary | std::ios::trunc);
  if (!csv) {
    std::cerr << "linesim: cannot write " << csv_path.string() << "\n";
    return kExitBadInput;
  }

  cosim::CsvRecorder recorder(csv, s.recorded, s.record_interval);
  cosim::MetricsObserver metrics(s.metrics);
  s.master->AddObserver(&recorder);
  s.master->AddObserver(&metrics);
  // The replay page of a robot run (replay/): sampled by an observer.
  std::unique_ptr<replay::ReplayRecorder> replayer;
  if (s.robot && replay) {
    replayer = std::make_unique<replay::ReplayRecorder>(
        replay::ReplaySpecFor(s, kPaperBoundM, kPaperBoundLabel));
    s.master->AddObserver(replayer.get());
  }
  // --mcap: the run for Foxglove and PlotJuggler, gathered as it runs.
  const fs::path mcap_path = dir / "run.mcap";
  std::ofstream mcap_file;
  std::unique_ptr<mcap::RunLog> mcap_log;
  if (write_mcap) {
    mcap_file.open(mcap_path, std::ios::binary | std::ios::trunc);
    if (!mcap_file) {
      std::cerr << "linesim: cannot write " << mcap_path.string() << "\n";
      return kExitBadInput;
    }
    mcap_log = std::make_unique<mcap::RunLog>(mcap_file, s);
    s.master->AddObserver(mcap_log.get());
  }

  // Ctrl-C or SIGTERM: stop at the next communication point, keep what was
  // recorded and write the summary (status interrupted); again to quit.
  std::atomic<bool>& stop = InstallStopSignals(
      "\nlinesim: interrupted: stopping at the next communication point (again to quit at "
      "once)\n");
  const auto wall0 = std::chrono::steady_clock::now();
  s.master->Start();
  bool interrupted = false;
  while (s.master->Step()) {
    if (stop.load(std::memory_order_relaxed)) {
      interrupted = true;
      break;
    }
  }
  const cosim::RunResult result = s.master->Finish();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  csv.close();
  // A full disk shows only here (buffered writes fail late): a run whose
  // signals were lost has failed, whatever the units did.
  cosim::RunResult outcome = result;
  const bool csv_written = !csv.fail();
  if (!csv_written) {
    outcome.ok = false;
    cosim::RunError e = cosim::MakeRunError(
        std::nullopt, cosim::RunPhase::kRecording, "",
        "cannot write " + csv_path.string() + " (disk full or not writable): the signals are " +
            "incomplete");
    e.message = e.cause;
    e.time = result.end_time;
    outcome.errors.push_back(std::move(e));
  }
  if (mcap_log) {
    mcap_file.close();
    if (mcap_file.fail()) {
      outcome.ok = false;
      cosim::RunError e = cosim::MakeRunError(
          std::nullopt, cosim::RunPhase::kRecording, "",
          "cannot write " + mcap_path.string() + " (disk full or not writable)");
      e.message = e.cause;
      e.time = result.end_time;
      outcome.errors.push_back(std::move(e));
    }
  }

  // A metric that overflowed fails the run, naming the metric.
  for (auto& e : metrics.NonFiniteErrors(result.end_time)) {
    outcome.ok = false;
    outcome.errors.push_back(std::move(e));
  }

  const cosim::MasterOptions& options = s.master->options();
  const double simulated_s = cosim::NsToSeconds(result.end_time - options.start);
  Json summary;
  summary["scenario"] = s.name;
  summary["file"] = file;
  summary["status"] = interrupted ? "interrupted" : outcome.ok ? "ok" : "failed";
  // The first failure as data ({"unit", "time_s", "phase", "variable",
  // "cause", "message"}), null when the run is ok; every message in
  // "errors".
  summary["error"] = outcome.errors.empty() ? Json(nullptr) : cosim::RunErrorJson(outcome.errors[0]);
  Json messages = Json::array();
  for (const auto& e : outcome.errors) messages.push_back(e.message);
  summary["errors"] = messages;
  // A unit that asked to end the run early (an FMU's terminate request):
  // which and why; absent when the run reached its stop time.
  if (!result.ended_by.empty()) summary["ended_by"] = result.ended_by;
  Json settings;
  settings["duration_s"] = s.duration_s;
  settings["seed"] = s.seed;
  settings["master"] = {{"algorithm", cosim::ToString(options.algorithm)},
                        {"step_s", cosim::NsToSeconds(options.base_step)},
                        {"threads", options.threads}};
  if (options.retry.enabled) {
    settings["master"]["retry"] = {{"min_step_s", cosim::NsToSeconds(options.retry.min_step)},
                                   {"shrink", options.retry.shrink},
                                   {"grow", options.retry.grow},
                                   {"rejected_steps", result.rejected_steps},
                                   {"smallest_step_s", cosim::NsToSeconds(result.smallest_step)}};
  }
  Json overrides = Json::array();
  for (const auto& o : s.overrides) overrides.push_back(o.path + "=" + o.value);
  settings["overrides"] = overrides;
  Json units = Json::object();
  const cosim::System& system = *s.system;
  for (std::size_t u = 0; u < system.unit_count(); ++u) {
    units[system.unit(u).name()] = {
        {"type", system.unit(u).type_name()},
        {"step_s", cosim::NsToSeconds(options.base_step * s.master->decimation(u))}};
  }
  settings["units"] = units;
  summary["settings"] = settings;
  summary["provenance"] = platform::ProvenanceJson(s.sha256, s.seed);

  Json metric_values = Json::object();
  for (const auto& [name, value] : metrics.Results()) metric_values[name] = Number(value);
  summary["metrics"] = metric_values;

  Json timing;
  timing["simulated_s"] = simulated_s;
  timing["wall_s"] = wall_s;
  timing["real_time_factor"] = Number(simulated_s / wall_s);
  // Shares of the stepping time, from the timed base steps alone (measured
  // whole, unscaled): each unit's own time in them, and what of them no
  // unit was running for. The estimate wall_s of a unit (its sampled steps
  // scaled by 31, with Setup and Initialize) could exceed the run's wall
  // time when the costly steps fell on sampled ones (hold_straddle on own
  // sensors: -0.067 as wall_s - sum / wall_s); these shares are in [0, 1]
  // by construction.
  const cosim::Master& master = *s.master;
  const double sampled_s = master.sampled_step_seconds();
  const auto share_of_steps = [&](double seconds) {
    return sampled_s > 0.0 ? Number(seconds / sampled_s) : Json(nullptr);
  };
  Json shares = Json::object();
  for (std::size_t u = 0; u < system.unit_count(); ++u) {
    shares[system.unit(u).name()] = {{"wall_s", master.unit_wall_seconds()[u]},
                                     {"share", share_of_steps(master.sampled_unit_seconds()[u])}};
  }
  timing["units"] = shares;
  timing["master_and_observers_share"] =
      share_of_steps(sampled_s - std::min(master.sampled_busy_seconds(), sampled_s));
  summary["timing"] = timing;
  Json columns = Json::array();
  for (const auto& p : s.recorded) columns.push_back(p.label);
  summary["recording"] = {{"file", "signals.csv"},
                          {"rows", recorder.rows()},
                          {"interval_s", cosim::NsToSeconds(s.record_interval)},
                          {"columns", columns}};
  if (mcap_log) {
    summary["mcap"] = {{"file", "run.mcap"},
                       {"bytes", mcap_log->bytes()},
                       {"messages", mcap_log->messages()}};
  }
  // Robot runs are drawn (also a failed one: the plots show how it failed).
  std::vector<std::string> pictures;
  if (s.robot && recorder.rows() > 0 && csv_written) {
    try {
      for (const auto& p :
           plots::WriteRobotPlots(dir.string(), PlotSpec(s, format, *s.robot, &*s.robot))) {
        pictures.push_back(fs::path(p).filename().string());
      }
      for (const loader::RobotInfo& other : s.robot->fleet) {
        for (const auto& p :
             plots::WriteRobotPlots(dir.string(), PlotSpec(s, format, other, &*s.robot))) {
          pictures.push_back(fs::path(p).filename().string());
        }
      }
      summary["plots"] = {{"files", pictures}};
    } catch (const std::exception& e) {
      // The run itself is fine: say why there are no pictures, do not fail.
      summary["plots"] = {{"error", e.what()}};
      std::cerr << "linesim: no plots: " << e.what() << "\n";
    }
  }
  if (replayer && replayer->frames() > 0) {
    try {
      replayer->Write((dir / "replay.html").string());
      pictures.push_back("replay.html");
      summary["replay"] = {{"file", "replay.html"}};
    } catch (const std::exception& e) {
      summary["replay"] = {{"error", e.what()}};  // as for the plots: the run stands
      std::cerr << "linesim: no replay: " << e.what() << "\n";
    }
  }
  try {
    cosim::WriteFileAtomically((dir / "summary.json").string(), summary.dump(2) + "\n");
  } catch (const std::exception& e) {
    std::cerr << "linesim: " << e.what() << "\n";
    return kExitRunFailed;
  }

  std::cout << s.name << ": "
            << (interrupted  ? "INTERRUPTED"
                : outcome.ok ? "ok"
                             : "FAILED")
            << ", " << cosim::FormatSeconds(result.end_time - options.start) << " s simulated in "
            << std::setprecision(3) << wall_s << " s wall (" << std::setprecision(4)
            << simulated_s / wall_s << "x real time)\n";
  if (!result.ended_by.empty()) std::cout << "  ended early by " << result.ended_by << "\n";
  std::size_t name_width = 0;
  for (const auto& [name, value] : metrics.Results())
    name_width = std::max(name_width, name.size());
  for (const auto& [name, value] : metrics.Results()) {
    std::cout << "  " << std::left << std::setw(static_cast<int>(name_width)) << name << " = "
              << std::setprecision(6) << value << "\n";
  }
  std::cout << "  wrote " << (dir / "summary.json").string() << ", " << csv_path.string() << " ("
            << recorder.rows() << " rows)";
  for (const auto& p : pictures) std::cout << ", " << p;
  if (mcap_log) std::cout << ", run.mcap";
  std::cout << "\n";
  for (const auto& e : outcome.errors) std::cerr << "linesim: " << e.message << "\n";
  if (plot_columns && s.robot) {
    plot_columns->error_column = s.robot->error_column;
    plot_columns->belt_on_columns = s.robot->belt_on_columns;
    plot_columns->task = s.robot->task;
  }
  if (interrupted) return kExitInterrupted;
  return outcome.ok ? kExitOk : kExitRunFailed;
}

// `linesim inspect X.fmu`: what the FMU declares and what the `fmu` unit
// makes of it.
static int InspectFmu(const std::string& file) {
  std::unique_ptr<fmu::FmuUnit> unit;
  try {
    unit = std::make_unique<fmu::FmuUnit>("fmu", file);
  } catch (const std::exception& e) {
    std::cerr << "linesim: " << e.what() << "\n";
    return kExitBadInput;
  }
  const fmu::ModelDescription& md = unit->description();
  const auto yes = [](bool b) { return b ? "yes" : "no"; };
  const auto seconds = [](const std::optional<double>& v) {
    return v ? cosim::FormatValue(*v) + " s" : std::string("-");
  };
  std::cout << "FMU " << file << ": FMI " << md.fmi_version << " co-simulation, model '"
            << md.model_name << "' (modelIdentifier " << md.model_identifier << ")\n";
  if (!md.description.empty()) std::cout << "  description:      " << md.description << "\n";
  std::cout << "  generation tool:  " << (md.generation_tool.empty() ? "-" : md.generation_tool);
  if (!md.generation_date.empty()) std::cout << " (" << md.generation_date << ")";
  std::cout << "\n  token:            " << md.token << "\n";
  std::cout << "  capabilities:     canGetAndSetFMUstate " << yes(md.can_get_and_set_state)
            << ", canSerializeFMUstate " << yes(md.can_serialize_state)
            << ", canHandleVariableCommunicationStepSize " << yes(md.can_handle_variable_step);
  if (md.fmi_major == 2) {
    std::cout << ", canInterpolateInputs " << yes(md.can_interpolate_inputs);
  } else {
    std::cout << ", mightReturnEarlyFromDoStep " << yes(md.can_return_early)
              << ", fixedInternalStepSize " << seconds(md.fixed_internal_step);
  }
  std::cout << ", needsExecutionTool " << yes(md.needs_execution_tool)
            << ", canBeInstantiatedOnlyOncePerProcess " << yes(md.only_once_per_process);
  if (md.has_model_exchange) std::cout << " (also model exchange: not used)";
  std::cout << "\n  default experiment: start " << seconds(md.default_start) << ", stop "
            << seconds(md.default_stop) << ", step " << seconds(md.default_step)
            << ", tolerance "
            << (md.default_tolerance ? cosim::FormatValue(*md.default_tolerance) : "-") << "\n";
  std::cout << "variables, as a unit `type: fmu` with `parameters: {path: ...}` declares them:\n";
  PrintTable(*unit, std::cout);
  std::string left_out;
  for (const auto& m : unit->mapping()) {
    if (!m.mapped) left_out += (left_out.empty() ? "" : ", ") + m.fmi_name;
  }
  if (!left_out.empty()) {
    std::cout << "left out (inside the FMU only: the independent time, non-Real locals): "
              << left_out << "\n";
  }
  return kExitOk;
}

int UnitReferenceCommand() {
  std::cout << "# Unit types\n\n"
               "Every unit type linesim registers, with its variables as `linesim inspect TYPE`\n"
               "prints them. Generated: `build/app/linesim inspect --all > docs/units.md`\n"
               "(test `UnitReference.DocsUnitsMdIsCurrent` fails when it is stale).\n"
               "How units are used in scenario files: `docs/scenarios.md`.\n";
  for (const auto& type : config::UnitTypes()) {
    std::cout << "\n## `" << type.name << "`\n\n" << type.description << "\n";
    if (!type.model_folder.empty()) {
      std::cout << "\nModel files (`parameters.model`): `models/" << type.model_folder << "/`.\n";
    }
    if (!type.structural_keys.empty()) {
      std::cout << "\nKeys under `parameters:` that shape the unit:\n\n";
      for (const auto& k : type.structural_keys) {
        std::cout << "- `" << k.name << "`: " << k.description << "\n";
      }
    }
    std::unique_ptr<cosim::Unit> unit;
    try {
      unit = loader::CreateDefaultUnit(type);
    } catch (const config::ScenarioError& e) {
      std::cerr << "linesim: " << e.what() << "\n";
      return kExitBadInput;
    }
    std::cout << "\n";
    PrintMarkdownTable(*unit, std::cout);
  }
  return kExitOk;
}

int InspectCommand(const std::string& what, const std::vector<std::string>& set_args) {
  if (what.ends_with(".fmu") && config::FindUnitType(what) == nullptr) {
    if (!set_args.empty()) {
      std::cerr << "linesim: --set applies to a scenario file, not to an FMU\n";
      return kExitBadInput;
    }
    return InspectFmu(what);
  }
  // A type name first: a file or folder of that name where linesim runs
  // (inspect chassis from inside units/) does not hide the type.
  const config::UnitType* type = config::FindUnitType(what);
  std::error_code ec;
  const bool is_file =
      !type && (fs::exists(what, ec) || what.ends_with(".yaml") || what.ends_with(".yml"));
  if (!is_file) {
    if (!set_args.empty()) {
      std::cerr << "linesim: --set applies to a scenario file, not to a unit type\n";
      return kExitBadInput;
    }
    if (!type) {
      std::cerr << "linesim: " << config::UnknownTypeMessage(what) << "\n";
      return kExitBadInput;
    }
    std::unique_ptr<cosim::Unit> unit;
    try {
      unit = loader::CreateDefaultUnit(*type);
    } catch (const config::ScenarioError& e) {
      std::cerr << "linesim: " << e.what() << "\n";
      return kExitBadInput;
    }
    std::cout << "unit type '" << type->name << "': " << type->description << "\n";
    std::cout << "keys under parameters: that shape the unit:\n";
    std::size_t key_width = 0;
    for (const auto& k : type->structural_keys) key_width = std::max(key_width, k.name.size());
    for (const auto& k : type->structural_keys) {
      std::cout << "  " << std::left << std::setw(static_cast<int>(key_width)) << k.name << "  "
                << k.description << "\n";
    }
    std::cout << "variables (with the default keys above):\n";
    PrintTable(*unit, std::cout);
    return kExitOk;
  }

  loader::Scenario s;
  try {
    s = loader::LoadScenario(what, set_args);
  } catch (const config::ScenarioError& e) {
    PrintIssues(e, "scenario", std::cerr);
    return kExitBadInput;
  }
  const auto& o = s.master->options();
  std::cout << "scenario '" << s.name << "' (" << what << ")";
  if (!s.description.empty()) std::cout << ": " << s.description;
  std::cout << "\n  duration " << cosim::FormatSeconds(o.stop - o.start) << " s, seed " << s.seed
            << ", master " << cosim::ToString(o.algorithm) << " step "
            << cosim::FormatSeconds(o.base_step) << " s";
  if (o.retry.enabled) {
    std::cout << ", retry on (min step " << cosim::FormatSeconds(o.retry.min_step)
              << " s, shrink " << o.retry.shrink << ", grow " << o.retry.grow << ")";
  }
  std::cout << "\n";
  if (s.robot) {
    // The robot-level file and what it stands for, in the system-level
    // format (a file of its own could be run as is).
    YAML::Emitter yaml;
    yaml << s.expanded;
    std::cout << "\nexpands into this system:\n" << yaml.c_str() << "\n";
  }
  const cosim::System& system = *s.system;
  for (std::size_t u = 0; u < system.unit_count(); ++u) {
    std::cout << "\nunit '" << system.unit(u).name() << "' (" << system.unit(u).type_name()
              << ", step " << cosim::FormatSeconds(o.base_step * s.master->decimation(u))
              << " s)\n";
    PrintTable(system.unit(u), std::cout);
  }
  std::cout << "\nconnections:\n";
  for (const auto& c : system.connections()) {
    std::cout << "  " << c.from.ToString() << " -> " << c.to.ToString() << "\n";
  }
  std::cout << "\nstep order (Gauss-Seidel):";
  for (std::size_t u : system.dependency_order()) std::cout << " " << system.unit(u).name();
  std::cout << "\n";
  return kExitOk;
}

}  // namespace linesim::app
