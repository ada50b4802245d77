// linesim's Python face (the `linesim` package's native part, _linesim): a
// run session in the Python process. The package's Python code
// (linesim/__init__.py) shapes what this returns into Result objects and
// exceptions.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "config/scenario_error.h"
#include "cosim/run_error_json.h"
#include "loader/scenario.h"
#include "platform/platform.h"
#include "session/session.h"

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

// One run: {"issues": [...]} when the scenario is refused; else status,
// metrics, signals (time_s and one array per recorded column), units of
// measure, errors and summary.json's text.
py::dict Run(const std::string& file, const std::vector<std::string>& set) {
  std::optional<session::Session> run;
  std::optional<config::ScenarioError> refused;
  {
    // No Python object is touched while the scenario loads and runs: other
    // Python threads go on.
    py::gil_scoped_release release;
    try {
      run.emplace(file, set);
    } catch (const config::ScenarioError& e) {
      refused = e;
    }
  }
  py::dict out;
  if (refused) {
    py::list issues;
    for (const auto& i : refused->issues()) issues.append(IssueDict(i));
    out["issues"] = issues;
    return out;
  }
  const loader::Scenario& s = run->scenario();
  session::SignalRecorder recorder(s.recorded, s.record_interval);
  run->AddObserver(&recorder);
  session::RunReport report;
  {
    py::gil_scoped_release release;
    report = run->Run();
  }
  out["status"] = report.status();
  py::list metrics;
  for (const auto& [name, value] : report.metrics) metrics.append(py::make_tuple(name, value));
  out["metrics"] = metrics;
  py::list errors;
  for (const auto& e : report.errors) errors.append(RunErrorDict(e));
  out["errors"] = errors;

  const auto array = [](const std::vector<double>& v) {
    return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
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
  out["summary"] = session::Summary(s, file, report).dump();
  return out;
}

// A unit type's variable table: one dict per variable.
py::list Inspect(const std::string& type) {
  std::unique_ptr<cosim::Unit> unit;
  try {
    unit = loader::CreateDefaultUnit(type);
  } catch (const config::ScenarioError& e) {
    throw py::value_error(e.what());
  }
  py::list rows;
  const cosim::VariableTable& table = unit->variables();
  for (const auto& v : table.infos()) {
    py::dict d;
    d["name"] = v.name;
    d["causality"] = std::string(cosim::ToString(v.causality));
    d["type"] = std::string(cosim::ToString(v.type));
    d["size"] = v.size;
    d["unit"] = v.unit;
    d["start"] = cosim::FormatValue(table.GetValue(v.ref));
    d["rule"] = v.rule.empty() ? std::string() : v.rule.Text();
    d["description"] = v.description;
    rows.append(d);
  }
  return rows;
}

}  // namespace
}  // namespace linesim::python

PYBIND11_MODULE(_linesim, m) {
  m.doc() = "linesim's native part: run sessions and the unit registry";
  m.def("run", &linesim::python::Run, py::arg("file"), py::arg("set"));
  m.def("inspect", &linesim::python::Inspect, py::arg("type"));
  m.def("unit_types", &linesim::config::UnitTypeNames);
  m.def("math_library", &linesim::platform::MathLibrary);
}
