#include "session/session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "cosim/run_error_json.h"
#include "platform/provenance.h"

namespace linesim::session {

namespace {

using Json = nlohmann::ordered_json;

Json Number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// The worker's parameter `name` as the built unit has it (its default when
// the scenario gives none); 0 when the unit or parameter is not there.
double WorkerParameter(const cosim::System& system, const std::string& worker,
                       const std::string& name) {
  const auto unit = system.FindUnit(worker);
  if (!unit) return 0.0;
  const cosim::VariableTable& v = system.unit(*unit).variables();
  const auto ref = v.Find(name);
  return ref ? v.GetReal(*ref) : 0.0;
}

// The caption line naming the run: the scenario's description, its name
// (with the robot's in a fleet) and seed.
std::string RunCaption(const loader::Scenario& s, const loader::RobotInfo& robot) {
  std::string run = s.name + (robot.name.empty() ? "" : ", robot " + robot.name) + ", seed " +
                    std::to_string(s.seed);
  return s.description.empty() ? run : s.description + " (" + run + ")";
}

// What the plots of a robot run draw, by the columns the robot expansion
// names. `robot` is the scenario's robot, or in a fleet any of its robots
// (the others drawn in its top view; `first` is the scenario's).
plots::RobotPlotSpec PlotSpec(const loader::Scenario& s, plots::PlotFormat format,
                              const loader::RobotInfo& robot, const loader::RobotInfo& first) {
  plots::RobotPlotSpec spec;
  spec.run_caption = RunCaption(s, robot);
  spec.scene = s.scene;
  spec.path_m = robot.path;
  spec.x_column = robot.x_column;
  spec.y_column = robot.y_column;
  spec.yaw_column = robot.yaw_column;
  spec.z_column = robot.z_column;
  spec.wheel_columns = robot.wheel_columns;
  spec.error_column = robot.error_column;
  const bool hold = robot.task == "hold";
  spec.error_label = hold ? "drift from the held position" : "deviation from the path";
  spec.error_name = hold ? "drift of the robot's centre from the held position"
                         : "deviation of the robot's centre from the desired path";
  // The scenario's published bound (figures.bound), the same for each
  // robot of a fleet.
  const loader::RobotInfo::FigureBound& bound = first.figure_bound;
  spec.error_bound.value_m = bound.value_m;
  spec.error_bound.label = bound.label;
  if (bound.final_pose) spec.error_bound.from_column = robot.task_done_column;
  spec.format = format;
  spec.belt_speed_columns = robot.belt_speed_columns;
  spec.belt_on_columns = robot.belt_on_columns;
  spec.belt_travel_columns = robot.belt_travel_columns;
  spec.flow_columns = robot.flow_columns;
  spec.flow_labels = robot.flow_sensor_names;
  spec.flow_truth_columns = robot.flow_truth_columns;
  spec.flow_filtered_columns = robot.flow_filtered_columns;
  spec.flow_reference_column = robot.flow_reference_column;
  for (std::size_t w = 0; w < robot.worker_columns.size(); ++w) {
    plots::RobotPlotSpec::Worker worker;
    worker.x_column = robot.worker_columns[w].first;
    worker.y_column = robot.worker_columns[w].second;
    if (w < robot.worker_names.size()) {
      worker.name = robot.worker_names[w];
      worker.leg_radius_m = WorkerParameter(*s.system, worker.name, "leg_radius");
      worker.torso_radius_m = WorkerParameter(*s.system, worker.name, "torso_radius");
    }
    if (w < robot.worker_leg_columns.size()) worker.leg_columns = robot.worker_leg_columns[w];
    spec.workers.push_back(worker);
  }
  // A fleet: each robot's plots, with the others in the top view; the
  // first robot's files have no prefix, the others' their name.
  spec.robot_name = robot.name;
  const auto add_other = [&](const loader::RobotInfo& other, std::size_t index) {
    if (other.name == robot.name) return;
    spec.others.push_back({other.name, other.x_column, other.y_column, other.yaw_column,
                           other.body_length_m.value_or(0.0), other.body_width_m.value_or(0.0),
                           index});
  };
  add_other(first, 0);
  for (std::size_t i = 0; i < first.fleet.size(); ++i) add_other(first.fleet[i], i + 1);
  if (robot.name != first.name) spec.file_prefix = robot.name + "_";
  spec.safety = {robot.velocity_x_column, robot.velocity_y_column,
                 robot.speed_cap_column,  robot.protective_column,
                 robot.warning_column,    robot.person_distance_column,
                 robot.field_set_column,  {}};
  if (!robot.scan_unit.empty() && robot.scan_geometry) {
    // The beams' geometry as the system description gives it.
    const loader::RobotInfo::ScanGeometry& g = *robot.scan_geometry;
    plots::RobotPlotSpec::Scan& scan = spec.scan;
    scan.sensor = robot.scan_unit;
    scan.time_s = robot.scan_time_s;
    scan.mount_x_m = g.mount_x_m;
    scan.mount_y_m = g.mount_y_m;
    scan.mount_yaw_rad = g.mount_yaw_rad;
    scan.first_beam_rad = g.first_beam_rad;
    scan.beam_step_rad = g.beam_step_rad;
    scan.no_return_m = g.no_return_m;
    for (int k = 0; k < g.beams; ++k) {
      scan.range_columns.push_back(robot.scan_unit + ".ranges[" + std::to_string(k) + "]");
    }
    scan.scan_time_column = robot.scan_unit + ".scan_time";
  }
  if (robot.body_length_m) spec.body_length_m = *robot.body_length_m;
  if (robot.body_width_m) spec.body_width_m = *robot.body_width_m;
  // The fields' reach beyond the body's front (base_link's origin is the
  // body's centre).
  for (const auto& reach : robot.field_reach_m) {
    spec.safety.field_depths_m.push_back(
        {reach[0] - 0.5 * spec.body_length_m, reach[1] - 0.5 * spec.body_length_m});
  }
  return spec;
}

}  // namespace

const char* RunReport::status() const {
  return interrupted ? "interrupted" : errors.empty() ? "ok" : "failed";
}

void RunReport::AddFailure(const std::string& cause) {
  cosim::RunError e = cosim::MakeRunError(std::nullopt, cosim::RunPhase::kRecording, "", cause);
  e.message = e.cause;
  e.time = result.end_time;
  errors.push_back(std::move(e));
}

Session::Session(const std::string& file, const std::vector<std::string>& set,
                 const std::map<std::string, std::string>& unit_types)
    : Session(loader::LoadScenario(file, set, unit_types)) {}

Session::Session(loader::Scenario scenario) : s_(std::move(scenario)), measured_(s_.metrics) {}

void Session::AddObserver(cosim::Observer* observer) { s_.master->AddObserver(observer); }

bool Session::Measure(const std::vector<std::string>& names) {
  std::vector<cosim::MetricSpec> wanted;
  for (const auto& name : names) {
    const auto it = std::find_if(s_.metrics.begin(), s_.metrics.end(),
                                 [&](const cosim::MetricSpec& m) { return m.name == name; });
    if (it == s_.metrics.end()) return false;
    wanted.push_back(*it);
  }
  measured_ = std::move(wanted);
  return true;
}

RunReport Session::Run(const std::atomic<bool>* stop) {
  // The master would set up and initialize the used units again, with the
  // last run's metrics observer (freed below) still registered.
  if (metrics_) throw std::logic_error(s_.name + ": a session runs once; load the scenario again");
  RunReport report;
  metrics_ = std::make_unique<cosim::MetricsObserver>(measured_);
  cosim::MetricsObserver& metrics = *metrics_;
  s_.master->AddObserver(&metrics);
  const auto wall0 = std::chrono::steady_clock::now();
  s_.master->Start();
  while (s_.master->Step()) {
    if (stop != nullptr && stop->load(std::memory_order_relaxed)) {
      report.interrupted = true;
      break;
    }
  }
  report.result = s_.master->Finish();
  report.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  report.metrics = metrics.Results();
  report.errors = report.result.errors;
  for (std::size_t u = 0; u < s_.system->unit_count(); ++u) {
    const cosim::Unit& unit = s_.system->unit(u);
    for (const auto& w : unit.warnings()) report.warnings.push_back(unit.Where() + " " + w);
  }
  // A metric that overflowed fails the run, naming the metric.
  for (auto& e : metrics.NonFiniteErrors(report.result.end_time)) {
    report.errors.push_back(std::move(e));
  }
  return report;
}

SignalRecorder::SignalRecorder(std::vector<cosim::Probe> probes, cosim::TimeNs interval)
    : probes_(std::move(probes)), interval_(interval), columns_(probes_.size()) {}

void SignalRecorder::OnStart(const cosim::Master& master) {
  start_ = master.options().start;
  // As signals.csv: every base step unless an interval is given (the
  // loader makes it a whole number of base steps).
  if (interval_ <= 0) interval_ = master.options().base_step;
}

void SignalRecorder::OnSample(cosim::TimeNs t, const cosim::System& system) {
  if ((t - start_) % interval_ != 0) return;
  time_s_.push_back(cosim::NsToSeconds(t));
  for (std::size_t i = 0; i < probes_.size(); ++i) {
    columns_[i].push_back(cosim::ReadProbe(system, probes_[i]));
  }
}

nlohmann::ordered_json Summary(const loader::Scenario& s, const std::string& file,
                               const RunReport& report) {
  const cosim::RunResult& result = report.result;
  Json summary;
  summary["scenario"] = s.name;
  summary["file"] = file;
  summary["status"] = report.status();
  // The first failure as data ({"unit", "time_s", "phase", "variable",
  // "cause", "message"}), null when the run is ok; every message in
  // "errors".
  summary["error"] =
      report.errors.empty() ? Json(nullptr) : cosim::RunErrorJson(report.errors.front());
  Json messages = Json::array();
  for (const auto& e : report.errors) messages.push_back(e.message);
  summary["errors"] = messages;
  // What the units warned of (a worker touching a robot): the results hold,
  // but are to be read with it.
  Json warnings = Json::array();
  for (const auto& w : report.warnings) warnings.push_back(w);
  summary["warnings"] = warnings;
  // A unit that asked to end the run early (an FMU's terminate request):
  // which and why; absent when the run reached its stop time.
  if (!result.ended_by.empty()) summary["ended_by"] = result.ended_by;
  const cosim::MasterOptions& options = s.master->options();
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
  for (const auto& [name, value] : report.metrics) metric_values[name] = Number(value);
  summary["metrics"] = metric_values;

  const double simulated_s = cosim::NsToSeconds(result.end_time - options.start);
  Json timing;
  timing["simulated_s"] = simulated_s;
  timing["wall_s"] = report.wall_s;
  timing["real_time_factor"] = Number(simulated_s / report.wall_s);
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
  return summary;
}

std::vector<std::string> WriteRobotPlots(const loader::Scenario& s, const std::string& dir,
                                         plots::PlotFormat format) {
  std::vector<std::string> files;
  if (!s.robot) return files;
  for (const auto& p : plots::WriteRobotPlots(dir, PlotSpec(s, format, *s.robot, *s.robot))) {
    files.push_back(p);
  }
  for (const loader::RobotInfo& other : s.robot->fleet) {
    for (const auto& p : plots::WriteRobotPlots(dir, PlotSpec(s, format, other, *s.robot))) {
      files.push_back(p);
    }
  }
  return files;
}

}  // namespace linesim::session
