#include "python/python_unit.h"

#include <pybind11/stl.h>

#include <deque>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/unit_registry.h"
#include "cosim/system.h"
#include "cosim/unit.h"

namespace py = pybind11;

namespace linesim::python {

void PythonRun::Interrupt(py::error_already_set error) {
  if (!pending) pending.emplace(std::move(error));
  stop = true;
}

namespace {

// The run whose units are being created on this thread (BuildingRun).
thread_local PythonRun* building_run = nullptr;

// What a Python unit raised that must end the run and reach the caller
// unchanged rather than become the unit's failure: anything that is not
// an Exception (KeyboardInterrupt, SystemExit, GeneratorExit).
bool MustReachCaller(const py::error_already_set& e) { return !e.matches(PyExc_Exception); }

std::string Shown(py::handle value) {
  std::string text = py::repr(value).cast<std::string>();
  if (text.size() > 80) text = text.substr(0, 77) + "...";
  return "a " + py::str(py::type::handle_of(value).attr("__qualname__")).cast<std::string>() +
         ": " + text;
}

// `value` as a double when it is a number (bool, int, float, numpy's
// scalars: anything float() takes but text), else nothing.
std::optional<double> AsNumber(py::handle value) {
  if (value.is_none() || py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value)) {
    return std::nullopt;
  }
  const double x = PyFloat_AsDouble(value.ptr());
  if (x == -1.0 && PyErr_Occurred() != nullptr) {
    PyErr_Clear();
    return std::nullopt;
  }
  return x;
}

// A unit written in Python: a class with `inputs`, `outputs` and
// `parameters` (dicts of name -> (unit of measure, size or default)), and
// `setup(self)`, `do_step(self, t, dt)` (seconds); the variables are the
// object's attributes (a float, or a list for size > 1). Each call takes
// the GIL for its duration only: native units step without it.
class PythonUnit : public cosim::Unit {
 public:
  PythonUnit(const std::string& type, const std::string& name, PyObject* cls)
      : cosim::Unit(type, name), run_(building_run) {
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
    } catch (const cosim::UnitError& e) {
      return Fail(e.what(), e.variable());
    } catch (py::error_already_set& e) {
      if (run_ != nullptr && MustReachCaller(e)) {
        // The run stops after this step; linesim.run raises it.
        run_->Interrupt(std::move(e));
        return cosim::StepResult::kOk;
      }
      return Fail(std::string("the Python unit raised: ") + e.what());
    } catch (const std::exception& e) {
      return Fail(std::string("the Python unit raised: ") + e.what());
    }
    return cosim::StepResult::kOk;
  }

 private:
  struct Slot {
    std::string name;
    std::string unit;
    bool array;
    double value;
    std::vector<double> values;
  };

  void Declare(PyObject* cls);
  void DeclareParameter(const std::string& var, const std::string& unit, py::handle value);

  void Give(const std::vector<Slot*>& slots) {
    for (const Slot* s : slots) {
      if (s->array) {
        object_.attr(s->name.c_str()) = py::cast(s->values);
      } else {
        object_.attr(s->name.c_str()) = s->value;
      }
    }
  }

  // The outputs from the object's attributes: a number, or a sequence of
  // `size` numbers; anything else fails naming the variable, what it got
  // and what it takes.
  void Take() {
    for (Slot* s : outputs_) {
      const py::object v = object_.attr(s->name.c_str());
      const std::string takes =
          s->array ? "a list of " + std::to_string(s->values.size()) + " numbers (" + s->unit + ")"
                   : "a number (" + s->unit + ")";
      if (!s->array) {
        const auto x = AsNumber(v);
        if (!x)
          throw cosim::UnitError("output '" + s->name + "' takes " + takes + ", got " + Shown(v),
                                 s->name);
        s->value = *x;
        continue;
      }
      if (!py::isinstance<py::sequence>(v) || py::isinstance<py::str>(v)) {
        throw cosim::UnitError("output '" + s->name + "' takes " + takes + ", got " + Shown(v),
                               s->name);
      }
      const py::sequence items = py::reinterpret_borrow<py::sequence>(v);
      if (items.size() != s->values.size()) {
        throw cosim::UnitError("output '" + s->name + "' takes " + takes + ", got " +
                                   std::to_string(items.size()) + " values",
                               s->name);
      }
      for (std::size_t i = 0; i < items.size(); ++i) {
        const auto x = AsNumber(items[i]);
        if (!x) {
          const std::string element = s->name + "[" + std::to_string(i) + "]";
          throw cosim::UnitError(
              "output '" + s->name + "' takes " + takes + "; " + element + " is " + Shown(items[i]),
              element);
        }
        s->values[i] = *x;
      }
    }
  }

  void Call(const char* method) {
    if (py::hasattr(object_, method)) object_.attr(method)();
  }

  // Runs `f` holding the GIL; what it raises becomes the unit's error,
  // said while the GIL is still held. KeyboardInterrupt and SystemExit
  // stop the run and reach the caller.
  template <typename F>
  void WithPython(F&& f) {
    py::gil_scoped_acquire gil;
    try {
      f();
    } catch (const cosim::UnitError&) {
      throw;
    } catch (py::error_already_set& e) {
      const std::string what = e.what();
      if (run_ != nullptr && MustReachCaller(e)) run_->Interrupt(std::move(e));
      throw cosim::UnitError(std::string("the Python unit raised: ") + what);
    } catch (const std::exception& e) {
      throw cosim::UnitError(std::string("the Python unit raised: ") + e.what());
    }
  }

  PythonRun* run_;
  py::object object_;
  std::deque<Slot> slots_;  // stable addresses: the variable table points into them
  std::vector<Slot*> inputs_, outputs_, parameters_;
};

// The instance and its declared variables, bound into the table. Each
// name follows the rules of every unit's variables (cosim::IsIdentifier:
// signals.csv's header and the connections' "unit.variable" rely on them).
void PythonUnit::Declare(PyObject* cls) {
  object_ = py::reinterpret_borrow<py::object>(cls)();
  const auto declared = [&](const char* what) {
    return py::hasattr(object_, what) ? py::dict(object_.attr(what)) : py::dict();
  };
  const auto declare = [&](const char* what, auto&& bind) {
    const std::string second = std::string(what) == "parameters" ? "default" : "size";
    for (const auto& [key, spec] : declared(what)) {
      const std::string where = std::string(what) + "[" + std::string(py::repr(key)) + "]";
      if (!py::isinstance<py::str>(key))
        throw std::invalid_argument(where + ": a name must be a str");
      const std::string var = std::string(py::str(key));
      if (!cosim::IsIdentifier(var)) {
        throw std::invalid_argument(where + ": '" + var +
                                    "' is not a valid variable name: use letters, digits and '_'");
      }
      if (!py::isinstance<py::tuple>(spec) || py::len(spec) != 2 ||
          !py::isinstance<py::str>(py::reinterpret_borrow<py::tuple>(spec)[0])) {
        throw std::invalid_argument(where + " must be (unit, " + second + "), got " +
                                    std::string(py::repr(spec)));
      }
      const py::tuple t = py::reinterpret_borrow<py::tuple>(spec);
      bind(var, std::string(py::str(t[0])), t[1]);
    }
  };
  // Inputs and outputs: (unit, size); parameters: (unit, default).
  const auto size_of = [](const std::string& var, py::handle size) {
    if (py::isinstance<py::bool_>(size) || PyIndex_Check(size.ptr()) == 0) {
      throw std::invalid_argument("'" + var + "': the size must be an int, got " + Shown(size));
    }
    const auto n = py::reinterpret_steal<py::int_>(PyNumber_Index(size.ptr())).cast<std::int64_t>();
    if (n < 1) throw std::invalid_argument("'" + var + "' must have a size of at least 1");
    return static_cast<std::size_t>(n);
  };
  const auto bind_signal = [&](bool input) {
    return [&, input](const std::string& var, const std::string& unit, py::handle size) {
      const std::size_t n = size_of(var, size);
      Slot& slot = slots_.emplace_back(Slot{var, unit, n > 1, 0.0, std::vector<double>(n, 0.0)});
      if (input && slot.array) variables().Input(var, unit, &slot.values, "Python input");
      if (input && !slot.array) variables().Input(var, unit, &slot.value, "Python input");
      if (!input && slot.array) variables().Output(var, unit, &slot.values, "Python output", {});
      if (!input && !slot.array) variables().Output(var, unit, &slot.value, "Python output", {});
      (input ? inputs_ : outputs_).push_back(&slot);
    };
  };
  declare("inputs", bind_signal(true));
  declare("outputs", bind_signal(false));
  declare("parameters", [&](const std::string& var, const std::string& unit, py::handle value) {
    DeclareParameter(var, unit, value);
  });
}

// A parameter with its default: a number, or a list of numbers.
void PythonUnit::DeclareParameter(const std::string& var, const std::string& unit,
                                  py::handle value) {
  Slot slot{var, unit, false, 0.0, {}};
  const std::string takes =
      "parameters['" + var + "']: the default must be a number or a list of numbers, got ";
  if (const auto x = AsNumber(value)) {
    slot.value = *x;
  } else if (py::isinstance<py::sequence>(value) && !py::isinstance<py::str>(value)) {
    slot.array = true;
    for (const py::handle item : value) {
      const auto element = AsNumber(item);
      if (!element) throw std::invalid_argument(takes + Shown(value));
      slot.values.push_back(*element);
    }
  } else {
    throw std::invalid_argument(takes + Shown(value));
  }
  Slot& kept = slots_.emplace_back(std::move(slot));
  if (kept.array) {
    variables().Parameter(var, unit, &kept.values, "Python parameter");
  } else {
    variables().Parameter(var, unit, &kept.value, "Python parameter");
  }
  parameters_.push_back(&kept);
}

}  // namespace

BuildingRun::BuildingRun(PythonRun* run) : saved_(building_run) { building_run = run; }
BuildingRun::~BuildingRun() { building_run = saved_; }

void SignalCheck::OnSample(cosim::TimeNs, const cosim::System&) {
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < kSignalCheckInterval) return;
  last_ = now;
  CheckNow();
}

bool SignalCheck::CheckNow() {
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) run_.Interrupt(py::error_already_set());
  return run_.stop;
}

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

}  // namespace linesim::python
