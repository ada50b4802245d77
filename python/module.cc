// linesim's Python face (the `linesim` package's native part, _linesim): a
// run session in the Python process. The package's Python code
// (linesim/__init__.py) shapes what this returns into Result objects and
// exceptions; linesim/_linesim.pyi declares these functions' types.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <exception>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "config/scenario_error.h"
#include "config/unit_registry.h"
#include "cosim/run_error_json.h"
#include "cosim/variable_rows.h"
#include "loader/scenario.h"
#include "platform/build_info.h"
#include "platform/platform.h"
#include "python/python_unit.h"
#include "python/python_values.h"
#include "session/run_folder.h"
#include "session/session.h"
#include "sweep/executor.h"
#include "sweep/run_plan.h"
#include "sweep/sweep_spec.h"

namespace py = pybind11;

namespace linesim::python {
namespace {

py::dict IssueDict(const config::Issue& i) {
  py::dict d;
  d["file"] = i.file;
  d["line"] = i.line;
  d["key"] = i.key_path;
  d["message"] = i.message;
  d["from_command_line"] = i.from_command_line;
  return d;
}

py::dict Refused(const std::vector<config::Issue>& issues) {
  py::list list;
  for (const auto& i : issues) list.append(IssueDict(i));
  py::dict out;
  out["issues"] = list;
  return out;
}

py::dict RunErrorDict(const cosim::RunError& e) {
  py::dict d;
  d["unit"] = e.unit;
  d["unit_type"] = e.unit_type;
  d["time_s"] = e.time ? py::object(py::float_(cosim::NsToSeconds(*e.time))) : py::none();
  d["phase"] = std::string(cosim::ToString(e.phase));
  d["variable"] = e.variable;
  d["cause"] = e.cause;
  d["message"] = e.message;
  return d;
}

// A scenario as the caller gave it: a file's path, or a dict of the files'
// schema (its YAML tree, built here while the GIL is held).
struct ScenarioSource {
  std::string file;  // the path, or kDictLabel
  std::optional<YAML::Node> tree;
  std::vector<config::Issue> issues;  // a dict that is not a scenario's data

  explicit ScenarioSource(py::handle given) {
    if (py::isinstance<py::dict>(given)) {
      file = kDictLabel;
      tree = TreeFromPython(given, issues);
    } else {
      file = given.cast<std::string>();
    }
  }
  // Called without the GIL.
  loader::Scenario Load(const std::vector<std::string>& set,
                        const std::map<std::string, std::string>& unit_types = {}) const {
    if (!issues.empty()) throw config::ScenarioError(issues);
    return tree ? loader::LoadScenarioTree(*tree, file, set, unit_types)
                : loader::LoadScenario(file, set, unit_types);
  }
};

// The run's metrics, each in its type (MetricKind).
py::dict TypedMetrics(const std::vector<cosim::MetricSpec>& specs,
                      const std::vector<std::pair<std::string, double>>& values) {
  std::map<std::string, std::string> kinds;
  for (const auto& m : specs) kinds[m.name] = MetricKind(m);
  py::dict metrics;
  for (const auto& [name, value] : values) {
    const auto kind = kinds.find(name);
    metrics[py::str(name)] = TypedMetric(kind == kinds.end() ? "float" : kind->second, value);
  }
  return metrics;
}

// The recorded signals: each column as the bytes of its doubles (the
// package makes numpy arrays of them where numpy is installed,
// array.array('d') otherwise), with its name and unit of measure.
void AddSignals(const loader::Scenario& s, const session::SignalRecorder& recorder, py::dict& out) {
  const auto array = [](const std::vector<double>& v) {
    return py::bytes(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(double));
  };
  py::list names, columns, units;
  names.append("time_s");
  columns.append(array(recorder.time_s()));
  units.append("s");
  for (std::size_t i = 0; i < recorder.probes().size(); ++i) {
    const cosim::Probe& p = recorder.probes()[i];
    names.append(p.label);
    columns.append(array(recorder.columns()[i]));
    const cosim::Unit& unit = s.system->unit(p.where.unit);
    units.append(unit.variables().info(p.where.ref).unit);
  }
  out["signal_names"] = names;
  out["signal_columns"] = columns;
  out["signal_units"] = units;
}

// One run: {"issues": [...]} when the scenario is refused; else status,
// metrics, signals (time_s and one array per recorded column), units of
// measure, errors and summary.json's text. Ctrl-C (and a KeyboardInterrupt
// or SystemExit from a unit written in Python) stops the run within a step
// and is raised here.
py::dict Run(const py::object& scenario, const std::vector<std::string>& set,
             const std::map<std::string, std::string>& unit_types, const std::string& out_dir) {
  const ScenarioSource source(scenario);
  PythonRun python;
  std::optional<session::Session> run;
  std::optional<config::ScenarioError> refused;
  {
    // No Python object is touched while the scenario loads and runs: other
    // Python threads go on.
    py::gil_scoped_release release;
    const BuildingRun building(&python);
    try {
      run.emplace(source.Load(set, unit_types));
    } catch (const config::ScenarioError& e) {
      refused = e;
    }
  }
  if (python.pending) throw *python.pending;  // raised while a class was instantiated
  if (refused) return Refused(refused->issues());
  const loader::Scenario& s = run->scenario();
  session::SignalRecorder recorder(s.recorded, s.record_interval);
  run->AddObserver(&recorder);
  SignalCheck signals(python);
  run->AddObserver(&signals);
  session::RunReport report;
  py::dict out;
  if (out_dir.empty()) {
    py::gil_scoped_release release;
    report = run->Run(&python.stop);
  } else {
    // The command line's files too (linesim run --out), with its defaults.
    session::FolderRun written;
    std::string refused_output;
    {
      py::gil_scoped_release release;
      try {
        written = session::RunIntoFolder(*run, source.file, out_dir, session::FolderOptions{},
                                         &python.stop);
      } catch (const session::OutputError& e) {
        refused_output = e.what();
      }
    }
    if (!refused_output.empty()) throw py::value_error(refused_output);
    if (!written.summary_error.empty()) written.report.AddFailure(written.summary_error);
    report = std::move(written.report);
    out["warnings"] = written.warnings;
  }
  if (python.pending) throw *python.pending;
  out["status"] = report.status();
  out["metrics"] = TypedMetrics(s.metrics, report.metrics);
  py::list errors;
  for (const auto& e : report.errors) errors.append(RunErrorDict(e));
  out["errors"] = errors;
  AddSignals(s, recorder, out);
  out["summary"] = session::Summary(s, source.file, report).dump();
  return out;
}

// Runs `ids` of `spec` on `jobs` threads while this thread checks for
// Ctrl-C (SignalCheck): the runs stop at their next master step and the
// KeyboardInterrupt is raised here. `progress(done, total)` is called
// after each run (with the GIL; None: not called).
void RunInterruptibly(const sweep::SweepSpec& spec, const std::vector<std::int64_t>& ids, int jobs,
                      const py::object& progress, std::vector<sweep::RunSpec>& runs,
                      std::vector<sweep::RunOutcome>& outcomes) {
  const auto total = static_cast<std::int64_t>(ids.size());
  PythonRun python;
  SignalCheck signals(python);
  std::int64_t done = 0;
  std::exception_ptr failure;
  std::atomic<bool> finished{false};
  {
    py::gil_scoped_release release;
    std::thread worker([&] {
      try {
        sweep::RunOnThreads(spec, ids, jobs, python.stop,
                            [&](const sweep::RunSpec& run, const sweep::RunOutcome& outcome) {
                              runs[static_cast<std::size_t>(run.id)] = run;
                              outcomes[static_cast<std::size_t>(run.id)] = outcome;
                              ++done;
                              if (progress.is_none()) return;
                              py::gil_scoped_acquire gil;
                              progress(done, total);
                            });
      } catch (...) {
        failure = std::current_exception();
      }
      finished = true;
    });
    while (!finished) {
      std::this_thread::sleep_for(SignalCheck::kSignalCheckInterval);
      if (!python.stop) signals.CheckNow();
    }
    worker.join();
  }
  if (python.pending) throw *python.pending;
  if (failure) std::rethrow_exception(failure);
}

// Runs every run of `spec` on `jobs` threads: a table as typed columns
// (id, point, sample, repeat, seed, status, each parameter, each metric,
// error, wall_s), in run order.
py::dict RunSweep(const sweep::SweepSpec& spec, int jobs, const py::object& progress) {
  const std::int64_t total = sweep::RunCount(spec);
  std::vector<std::int64_t> ids(static_cast<std::size_t>(total));
  for (std::int64_t i = 0; i < total; ++i) ids[static_cast<std::size_t>(i)] = i;
  // The metrics' types: from the base scenario with the sweep's settings.
  std::vector<cosim::MetricSpec> metric_specs;
  {
    py::gil_scoped_release release;
    metric_specs = loader::LoadScenario(spec.scenario, sweep::FixedOverrides(spec)).metrics;
  }
  std::vector<sweep::RunSpec> runs(ids.size());
  std::vector<sweep::RunOutcome> outcomes(ids.size());
  RunInterruptibly(spec, ids, jobs, progress, runs, outcomes);

  py::dict table;
  const auto column = [&](auto&& of) {
    py::list values;
    for (std::size_t i = 0; i < runs.size(); ++i) values.append(of(runs[i], outcomes[i]));
    return values;
  };
  using R = const sweep::RunSpec&;
  using O = const sweep::RunOutcome&;
  table["id"] = column([](R r, O) { return r.id; });
  table["point"] = column([](R r, O) { return r.point; });
  table["sample"] = column([](R r, O) { return r.sample; });
  table["repeat"] = column([](R r, O) { return r.repeat; });
  table["seed"] = column([](R, O o) { return o.seed; });
  table["status"] = column(
      [](R, O o) { return std::string(o.status == sweep::RunStatus::kOk ? "ok" : "failed"); });
  for (std::size_t p = 0; p < spec.parameters.size(); ++p) {
    std::vector<std::string> texts;
    for (const auto& r : runs) texts.push_back(p < r.values.size() ? r.values[p] : std::string());
    table[py::str(spec.parameters[p].path)] = TypedParameterColumn(texts);
  }
  for (std::size_t m = 0; m < spec.metrics.size(); ++m) {
    std::string kind = "float";
    for (const auto& ms : metric_specs) {
      if (ms.name == spec.metrics[m]) kind = MetricKind(ms);
    }
    table[py::str(spec.metrics[m])] =
        column([m, &kind](R, O o) { return TypedMetric(kind, o.metrics[m]); });
  }
  table["error"] = column([](R, O o) { return o.error; });
  table["wall_s"] = column([](R, O o) { return o.wall_s; });
  return table;
}

template <typename F>
py::object Refusing(F&& load) {
  try {
    return load();
  } catch (const config::ScenarioError& e) {
    return Refused(e.issues());
  }
}

py::object Runs(const std::string& file, const std::vector<std::string>& set, std::int64_t n,
                int jobs, const py::object& progress) {
  return Refusing([&]() -> py::object {
    return RunSweep(sweep::RepeatSweepSpec(file, set, n), jobs, progress);
  });
}

// A sweep file's path, or a dict with its keys.
py::object Sweep(const py::object& given, int jobs, const py::object& progress) {
  const ScenarioSource source(given);
  return Refusing([&]() -> py::object {
    if (!source.issues.empty()) throw config::ScenarioError(source.issues);
    return RunSweep(source.tree ? sweep::LoadSweepSpecTree(*source.tree, source.file)
                                : sweep::LoadSweepSpec(source.file),
                    jobs, progress);
  });
}

// A unit's variable table: one dict per variable, its start value in its
// type (declared, or as the scenario set it).
py::list VariableDicts(const cosim::Unit& unit) {
  py::list rows;
  const cosim::VariableTable& table = unit.variables();
  const std::vector<cosim::VariableRow> described = cosim::VariableRows(unit);
  for (std::size_t i = 0; i < described.size(); ++i) {
    const cosim::VariableRow& v = described[i];
    py::dict d;
    d["name"] = v.name;
    d["causality"] = v.causality;
    d["type"] = v.type;
    d["size"] = v.size;
    d["unit"] = v.unit;
    d["start"] = ToPython(table.GetValue(table.infos()[i].ref));
    d["rule"] = v.rule;
    d["description"] = v.description;
    d["depends_on"] = v.depends_on;
    rows.append(d);
  }
  return rows;
}

// A unit type's variable table.
py::list Inspect(const std::string& type) {
  std::unique_ptr<cosim::Unit> unit;
  try {
    unit = loader::CreateDefaultUnit(type);
  } catch (const config::ScenarioError& e) {
    throw py::value_error(e.what());
  }
  return VariableDicts(*unit);
}

// The system a scenario (a path or a dict) builds: each unit with its
// type, step and variable table, the connections, and the step order;
// {"issues": [...]} when the scenario is refused.
py::object InspectScenario(const py::object& scenario, const std::vector<std::string>& set) {
  const ScenarioSource source(scenario);
  return Refusing([&]() -> py::object {
    const loader::Scenario s = source.Load(set);
    const cosim::System& system = *s.system;
    py::dict units;
    for (std::size_t u = 0; u < system.unit_count(); ++u) {
      py::dict unit;
      unit["type"] = system.unit(u).type_name();
      unit["step_s"] = cosim::NsToSeconds(s.master->options().base_step * s.master->decimation(u));
      unit["variables"] = VariableDicts(system.unit(u));
      units[py::str(system.unit(u).name())] = unit;
    }
    py::list connections;
    for (const auto& c : system.connections()) {
      connections.append(py::make_tuple(c.from.ToString(), c.to.ToString()));
    }
    py::list order;
    for (std::size_t u : system.dependency_order()) order.append(system.unit(u).name());
    py::dict out;
    out["name"] = s.name;
    out["units"] = units;
    out["connections"] = connections;
    out["step_order"] = order;
    return out;
  });
}

}  // namespace
}  // namespace linesim::python

PYBIND11_MODULE(_linesim, m) {
  m.doc() = "linesim's native part: run sessions and the unit registry";
  m.attr("__version__") = linesim::platform::build_info::kVersion;
  m.def("run", &linesim::python::Run, py::arg("scenario"), py::arg("set"), py::arg("unit_types"),
        py::arg("out"));
  m.def("register_unit", &linesim::python::RegisterPythonUnit, py::arg("type"), py::arg("cls"));
  m.def("inspect", &linesim::python::Inspect, py::arg("type"));
  m.def("inspect_scenario", &linesim::python::InspectScenario, py::arg("scenario"), py::arg("set"));
  m.def("runs", &linesim::python::Runs, py::arg("file"), py::arg("set"), py::arg("n"),
        py::arg("jobs"), py::arg("progress"));
  m.def("sweep", &linesim::python::Sweep, py::arg("sweep"), py::arg("jobs"), py::arg("progress"));
  m.def("unit_types", &linesim::config::UnitTypeNames);
  m.def("math_library", &linesim::platform::MathLibrary);
}
