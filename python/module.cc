// linesim's Python face (the `linesim` package's native part, _linesim): a
// run session in the Python process. The package's Python code
// (linesim/__init__.py) shapes what this returns into Result objects and
// exceptions.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "config/scenario_error.h"
#include "config/unit_registry.h"
#include "cosim/run_error_json.h"
#include "cosim/variable_rows.h"
#include "loader/scenario.h"
#include "platform/platform.h"
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

// A unit written in Python: a class with `inputs`, `outputs` and
// `parameters` (dicts of name -> (unit of measure, size or default)), and
// `setup(self)`, `do_step(self, t, dt)` (seconds); the variables are the
// object's attributes (a float, or a list for size > 1). Each call takes
// the GIL for its duration only: native units step without it.
class PythonUnit : public cosim::Unit {
 public:
  PythonUnit(const std::string& type, const std::string& name, PyObject* cls)
      : cosim::Unit(type, name) {
    py::gil_scoped_acquire gil;
    try {
      Declare(cls);
    } catch (const std::exception& e) {
      // Said and let go while the GIL is held: a Python error's objects
      // and the instance must not outlive it.
      const std::string what = e.what();
      object_ = py::object();
      throw std::runtime_error("the Python class " + type + " cannot be used: " + what);
    }
  }

  ~PythonUnit() override {
    py::gil_scoped_acquire gil;
    object_ = py::object();
  }

  void Setup(cosim::TimeNs, cosim::TimeNs) override {
    WithPython([&] {
      // Every declared variable is an attribute from the start (outputs at
      // their start value, 0).
      Give(parameters_);
      Give(inputs_);
      Give(outputs_);
      Call("setup");
    });
  }

  void Initialize() override {
    WithPython([&] {
      Give(inputs_);
      Call("initialize");
      Take();
    });
  }

  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override {
    ClearError();
    py::gil_scoped_acquire gil;
    try {
      Give(inputs_);
      if (py::hasattr(object_, "do_step")) {
        object_.attr("do_step")(cosim::NsToSeconds(t), cosim::NsToSeconds(dt));
      }
      Take();
    } catch (const std::exception& e) {
      return Fail(std::string("the Python unit raised: ") + e.what());
    }
    return cosim::StepResult::kOk;
  }

 private:
  struct Slot {
    std::string name;
    bool array;
    double value;
    std::vector<double> values;
  };

  // The instance and its declared variables, bound into the table.
  void Declare(PyObject* cls) {
    object_ = py::reinterpret_borrow<py::object>(cls)();
    const auto declared = [&](const char* what) {
      return py::hasattr(object_, what) ? py::dict(object_.attr(what)) : py::dict();
    };
    const auto declare = [&](const char* what, auto&& bind) {
      for (const auto& [key, spec] : declared(what)) {
        const std::string var = py::str(key);
        if (!py::isinstance<py::tuple>(spec) || py::len(spec) != 2 ||
            !py::isinstance<py::str>(py::reinterpret_borrow<py::tuple>(spec)[0])) {
          throw std::invalid_argument(std::string(what) + "['" + var + "'] must be (unit, " +
                                      (std::string(what) == "parameters" ? "default" : "size") +
                                      "), got " + std::string(py::repr(spec)));
        }
        const py::tuple t = py::reinterpret_borrow<py::tuple>(spec);
        bind(var, py::str(t[0]).cast<std::string>(), t[1]);
      }
    };
    // Inputs and outputs: (unit, size); parameters: (unit, default).
    const auto size_of = [](const std::string& var, py::handle size) {
      const auto n = size.cast<std::int64_t>();
      if (n < 1) throw std::invalid_argument("'" + var + "' must have a size of at least 1");
      return static_cast<std::size_t>(n);
    };
    declare("inputs", [&](const std::string& var, const std::string& unit, py::handle size) {
      const std::size_t n = size_of(var, size);
      Slot& slot = slots_.emplace_back(Slot{var, n > 1, 0.0, std::vector<double>(n, 0.0)});
      if (slot.array) {
        variables().Input(var, unit, &slot.values, "Python input");
      } else {
        variables().Input(var, unit, &slot.value, "Python input");
      }
      inputs_.push_back(&slot);
    });
    declare("outputs", [&](const std::string& var, const std::string& unit, py::handle size) {
      const std::size_t n = size_of(var, size);
      Slot& slot = slots_.emplace_back(Slot{var, n > 1, 0.0, std::vector<double>(n, 0.0)});
      if (slot.array) {
        variables().Output(var, unit, &slot.values, "Python output", {});
      } else {
        variables().Output(var, unit, &slot.value, "Python output", {});
      }
      outputs_.push_back(&slot);
    });
    declare("parameters", [&](const std::string& var, const std::string& unit, py::handle value) {
      Slot slot{var, py::isinstance<py::sequence>(value), 0.0, {}};
      if (slot.array) {
        slot.values = value.cast<std::vector<double>>();
      } else {
        slot.value = value.cast<double>();
      }
      Slot& kept = slots_.emplace_back(std::move(slot));
      if (kept.array) {
        variables().Parameter(var, unit, &kept.values, "Python parameter");
      } else {
        variables().Parameter(var, unit, &kept.value, "Python parameter");
      }
      parameters_.push_back(&kept);
    });
  }

  void Give(const std::vector<Slot*>& slots) {
    for (const Slot* s : slots) {
      if (s->array) {
        object_.attr(s->name.c_str()) = py::cast(s->values);
      } else {
        object_.attr(s->name.c_str()) = s->value;
      }
    }
  }
  void Take() {
    for (Slot* s : outputs_) {
      const py::object v = object_.attr(s->name.c_str());
      if (s->array) {
        const auto values = v.cast<std::vector<double>>();
        if (values.size() != s->values.size()) {
          throw cosim::UnitError("output '" + s->name + "' has " + std::to_string(values.size()) +
                                     " values, declared " + std::to_string(s->values.size()),
                                 s->name);
        }
        s->values = values;
      } else {
        s->value = v.cast<double>();
      }
    }
  }
  void Call(const char* method) {
    if (py::hasattr(object_, method)) object_.attr(method)();
  }
  // Runs `f` holding the GIL; what it raises becomes the unit's error,
  // said while the GIL is still held.
  template <typename F>
  void WithPython(F&& f) {
    py::gil_scoped_acquire gil;
    try {
      f();
    } catch (const cosim::UnitError&) {
      throw;
    } catch (const std::exception& e) {
      throw cosim::UnitError(std::string("the Python unit raised: ") + e.what());
    }
  }

  py::object object_;
  std::deque<Slot> slots_;  // stable addresses: the variable table points into them
  std::vector<Slot*> inputs_, outputs_, parameters_;
};

// Registers the class `cls` as unit type `type` (once per type name).
void RegisterPythonUnit(const std::string& type, py::object cls) {
  if (config::FindUnitType(type) != nullptr) {
    throw py::value_error("a unit type '" + type + "' is registered already");
  }
  // The registry lives until the process ends, after the interpreter: the
  // class is kept for good (never released).
  PyObject* kept = cls.release().ptr();
  config::UnitType t;
  t.name = type;
  t.description = "a unit written in Python (" + std::string(py::str(py::handle(kept))) + ")";
  t.create = [type, kept](const config::UnitBuildContext& c) -> std::unique_ptr<cosim::Unit> {
    return std::make_unique<PythonUnit>(type, c.name, kept);
  };
  config::RegisterUnitType(std::move(t));
}

// One run: {"issues": [...]} when the scenario is refused; else status,
// metrics, signals (time_s and one array per recorded column), units of
// measure, errors and summary.json's text.
py::dict Run(const std::string& file, const std::vector<std::string>& set,
             const std::map<std::string, std::string>& unit_types, const std::string& out_dir) {
  std::optional<session::Session> run;
  std::optional<config::ScenarioError> refused;
  {
    // No Python object is touched while the scenario loads and runs: other
    // Python threads go on.
    py::gil_scoped_release release;
    try {
      run.emplace(file, set, unit_types);
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
  if (out_dir.empty()) {
    py::gil_scoped_release release;
    report = run->Run();
  } else {
    // The command line's files too (linesim run --out), with its defaults.
    session::FolderRun written;
    std::string refused_output;
    {
      py::gil_scoped_release release;
      try {
        written = session::RunIntoFolder(*run, file, out_dir, session::FolderOptions{});
      } catch (const session::OutputError& e) {
        refused_output = e.what();
      }
    }
    if (!refused_output.empty()) throw py::value_error(refused_output);
    if (!written.summary_error.empty()) written.report.AddFailure(written.summary_error);
    report = std::move(written.report);
    out["warnings"] = written.warnings;
  }
  out["status"] = report.status();
  py::list metrics;
  for (const auto& [name, value] : report.metrics) metrics.append(py::make_tuple(name, value));
  out["metrics"] = metrics;
  py::list errors;
  for (const auto& e : report.errors) errors.append(RunErrorDict(e));
  out["errors"] = errors;

  // Each column as the bytes of its doubles: the package makes numpy arrays
  // of them where numpy is installed, array.array('d') otherwise.
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
  out["summary"] = session::Summary(s, file, report).dump();
  return out;
}

// Runs every run of `spec` on `jobs` threads: a table as columns (id,
// point, sample, repeat, seed, status, each parameter, each metric, error,
// wall_s), in run order. `progress(done, total)` is called after each run
// (with the GIL; None: not called). Ctrl-C stops the runs not yet started
// and raises KeyboardInterrupt.
py::dict RunSweep(const sweep::SweepSpec& spec, int jobs, const py::object& progress) {
  const std::int64_t total = sweep::RunCount(spec);
  std::vector<std::int64_t> ids(static_cast<std::size_t>(total));
  for (std::int64_t i = 0; i < total; ++i) ids[static_cast<std::size_t>(i)] = i;
  std::vector<sweep::RunSpec> runs(ids.size());
  std::vector<sweep::RunOutcome> outcomes(ids.size());
  std::atomic<bool> stop{false};
  bool interrupted = false;
  std::int64_t done = 0;
  {
    py::gil_scoped_release release;
    sweep::RunOnThreads(spec, ids, jobs, stop,
                        [&](const sweep::RunSpec& run, const sweep::RunOutcome& outcome) {
                          runs[static_cast<std::size_t>(run.id)] = run;
                          outcomes[static_cast<std::size_t>(run.id)] = outcome;
                          ++done;
                          py::gil_scoped_acquire gil;
                          if (PyErr_CheckSignals() != 0) {
                            PyErr_Clear();
                            interrupted = true;
                            stop = true;
                            return;
                          }
                          if (!progress.is_none()) progress(done, total);
                        });
  }
  if (interrupted) {
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }
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
    table[py::str(spec.parameters[p].path)] =
        column([p](R r, O) { return p < r.values.size() ? r.values[p] : std::string(); });
  }
  for (std::size_t m = 0; m < spec.metrics.size(); ++m) {
    table[py::str(spec.metrics[m])] = column([m](R, O o) { return o.metrics[m]; });
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
    py::list issues;
    for (const auto& i : e.issues()) issues.append(IssueDict(i));
    py::dict out;
    out["issues"] = issues;
    return out;
  }
}

py::object Runs(const std::string& file, const std::vector<std::string>& set, std::int64_t n,
                int jobs, const py::object& progress) {
  return Refusing([&]() -> py::object {
    return RunSweep(sweep::RepeatSweepSpec(file, set, n), jobs, progress);
  });
}

py::object Sweep(const std::string& file, int jobs, const py::object& progress) {
  return Refusing(
      [&]() -> py::object { return RunSweep(sweep::LoadSweepSpec(file), jobs, progress); });
}

// A unit's variable table: one dict per variable (its start value as
// `linesim inspect` prints it: declared, or as the scenario set it).
py::list VariableDicts(const cosim::Unit& unit) {
  py::list rows;
  for (const auto& v : cosim::VariableRows(unit)) {
    py::dict d;
    d["name"] = v.name;
    d["causality"] = v.causality;
    d["type"] = v.type;
    d["size"] = v.size;
    d["unit"] = v.unit;
    d["start"] = v.start;
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

// The system a scenario builds: each unit with its type, step and variable
// table, the connections, and the step order; {"issues": [...]} when the
// scenario is refused.
py::object InspectScenario(const std::string& file, const std::vector<std::string>& set) {
  return Refusing([&]() -> py::object {
    const loader::Scenario s = loader::LoadScenario(file, set);
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
  m.def("run", &linesim::python::Run, py::arg("file"), py::arg("set"), py::arg("unit_types"),
        py::arg("out"));
  m.def("register_unit", &linesim::python::RegisterPythonUnit, py::arg("type"), py::arg("cls"));
  m.def("inspect", &linesim::python::Inspect, py::arg("type"));
  m.def("inspect_scenario", &linesim::python::InspectScenario, py::arg("file"), py::arg("set"));
  m.def("runs", &linesim::python::Runs, py::arg("file"), py::arg("set"), py::arg("n"),
        py::arg("jobs"), py::arg("progress"));
  m.def("sweep", &linesim::python::Sweep, py::arg("file"), py::arg("jobs"), py::arg("progress"));
  m.def("unit_types", &linesim::config::UnitTypeNames);
  m.def("math_library", &linesim::platform::MathLibrary);
}
