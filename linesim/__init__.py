"""linesim from Python: run a scenario and get its status, metrics, signals
(numpy arrays) and summary as data.

    import linesim
    r = linesim.run("scenarios/cross_line.yaml", set={"task.speed_mps": 0.2})
    print(r.status, r.metrics["max_path_deviation_m"])
    print(r.signals["deviation.deviation"].max(), r.units["deviation.deviation"])

A refused scenario raises ScenarioError (file, line, key and every problem);
a run that fails raises RunError (unit, variable, time and cause; the
partial result as .result). The numbers are the command line's, to the bit:
the run goes through the same session (session/session.h) with the same
math library.
"""

import array
import glob
import importlib.machinery
import importlib.util
import json
import os
import sys
import tempfile

try:
    import numpy
except ImportError:  # signals as array.array('d') then
    numpy = None


def _load_native():
    # Next to this file (an installed package, or the copy in build/python),
    # else in the build tree of the repository this file is in.
    here = os.path.dirname(os.path.abspath(__file__))
    for folder in (here, os.path.join(here, "..", "build", "python", "linesim")):
        found = glob.glob(os.path.join(folder, "_linesim*" + importlib.machinery.EXTENSION_SUFFIXES[0]))
        if found:
            break
    else:
        raise ImportError("linesim's native part (_linesim) is not built: run tools/build.sh")
    # It brings its own transcendental functions (SLEEF, as every linesim
    # executable): loaded with RTLD_DEEPBIND, it and the libraries it loads
    # (ODE, SUNDIALS, FCL, Embree) bind to them before the libm the Python
    # process has already loaded, whose results depend on the CPU.
    flags = sys.getdlopenflags()
    sys.setdlopenflags(flags | os.RTLD_DEEPBIND)
    try:
        spec = importlib.util.spec_from_file_location(__name__ + "._linesim", found[0])
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        sys.setdlopenflags(flags)
    return module


_linesim = _load_native()

__all__ = ["run", "runs", "sweep", "inspect", "unit_types", "Unit", "Result", "ScenarioError",
           "RunError"]


class Unit:
    """A unit written in Python, to put in a scenario in place of a shipped
    one (run(..., units={"path_follower": MyFollower})). Declare

        inputs = {"position": ("m", 2), "yaw": ("rad", 1)}    # name: (unit, size)
        outputs = {"velocity_command": ("m/s", 2)}            # name: (unit, size)
        parameters = {"speed": ("m/s", 0.3)}                  # name: (unit, default)

    and define setup(self) (optional), initialize(self) (optional) and
    do_step(self, t, dt) (seconds). Variables are attributes: a float, or a
    list of `size` floats; inputs are set before each call, outputs read
    after. Each call holds the GIL; the native units step without it. The
    unit replaced keeps its connections and those of its parameters this
    class declares; a master.retry restores its declared variables, not
    the object's other attributes."""

    inputs = {}
    outputs = {}
    parameters = {}


_registered = {}


def _unit_type(cls):
    # One registered type per class object (a class defined again in a
    # notebook is another type).
    if cls not in _registered:
        name = "python.%s.%s_%x" % (cls.__module__, cls.__qualname__, id(cls))
        _linesim.register_unit(name, cls)
        _registered[cls] = name
    return _registered[cls]


class ScenarioError(Exception):
    """The scenario was refused before anything ran. `problems` lists each as
    a dict {file, line, key, message, from_command_line}; `file`, `line` and
    `key` are the first one's."""

    def __init__(self, problems):
        self.problems = problems
        first = problems[0] if problems else {}
        self.file = first.get("file", "")
        self.line = first.get("line", 0)
        self.key = first.get("key", "")
        lines = []
        for p in problems:
            where = p["file"] + (":" + str(p["line"]) if p["line"] else "")
            lines.append(where + ": " + (p["key"] + ": " if p["key"] else "") + p["message"])
        super().__init__("\n".join(lines))


class RunError(Exception):
    """The run failed: `unit`, `variable`, `time_s`, `cause` and `phase` of the
    first failure, every failure in `errors`, what was recorded in `result`."""

    def __init__(self, result):
        self.result = result
        self.errors = result.errors
        first = result.errors[0]
        self.unit = first["unit"]
        self.variable = first["variable"]
        self.time_s = first["time_s"]
        self.cause = first["cause"]
        self.phase = first["phase"]
        super().__init__(first["message"])


class Result:
    """What a run gave: `status` ("ok", "failed"), `metrics` (name -> value),
    `signals` (column -> numpy array, or array.array('d') without numpy;
    with "time_s"), `units` (column -> unit of measure), `errors` (dicts),
    `summary` (summary.json as a dict), `out` (the folder written, or None)."""

    def __init__(self, raw):
        self.status = raw["status"]
        self.metrics = dict(raw["metrics"])
        self.signals = {name: _column(data)
                        for name, data in zip(raw["signal_names"], raw["signal_columns"])}
        self.units = dict(zip(raw["signal_names"], raw["signal_units"]))
        self.errors = raw["errors"]
        self.summary = json.loads(raw["summary"])

    def __repr__(self):
        return "linesim.Result(status=%r, %d metrics, %d signals of %d rows)" % (
            self.status, len(self.metrics), len(self.signals), len(self.signals["time_s"]))


def _column(data):
    if numpy is not None:
        return numpy.frombuffer(data, dtype=numpy.float64)
    column = array.array("d")
    column.frombytes(data)
    return column


def _text(value):
    # A --set value: YAML text. JSON is YAML, so lists and maps go as JSON.
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return value
    return json.dumps(value)


class _scenario_file:
    # A scenario given as a dict (the files' schema: a system's units and
    # connections, or a robot scenario) goes to the loader as a file of its
    # own: JSON, which is YAML. Named models (raw3, factory_line) are found
    # as from any file; a path in it should be absolute.
    def __init__(self, path_or_dict):
        self.given = path_or_dict
        self.temp = None

    def __enter__(self):
        if not isinstance(self.given, dict):
            return os.fspath(self.given)
        with tempfile.NamedTemporaryFile("w", suffix=".yaml", prefix="linesim_",
                                         delete=False) as f:
            json.dump(self.given, f)
        self.temp = f.name
        return f.name

    def __exit__(self, *exc):
        if self.temp:
            os.unlink(self.temp)


def run(path, set=None, duration_s=None, seed=None, units=None, out=None):  # noqa: A002
    """Runs the scenario file `path` (or a dict of the same schema) with the
    overrides `set` ({"key.path":
    value}, as --set key.path=value), and `duration_s` and `seed` when given;
    `units` ({unit name: Unit subclass}) puts units written in Python in
    place of the scenario's; `out` (a folder) writes there what `linesim run
    --out` writes (summary.json, signals.csv, the plots, replay.html).
    Returns a Result; raises ScenarioError or RunError (ValueError when the
    folder cannot be written: nothing ran)."""
    sets = ["%s=%s" % (k, _text(v)) for k, v in (set or {}).items()]
    if duration_s is not None:
        sets.append("duration_s=%s" % _text(duration_s))
    if seed is not None:
        sets.append("seed=%s" % _text(seed))
    types = {name: _unit_type(cls) for name, cls in (units or {}).items()}
    with _scenario_file(path) as file:
        raw = _linesim.run(file, sets, types, os.fspath(out) if out is not None else "")
    if "issues" in raw:
        raise ScenarioError(raw["issues"])
    result = Result(raw)
    result.out = os.fspath(out) if out is not None else None
    if result.status != "ok":
        raise RunError(result)
    return result


def _progress(show):
    if not show:
        return None

    def report(done, total):
        sys.stderr.write("\rlinesim: %d of %d runs" % (done, total) + ("\n" if done == total else ""))
        sys.stderr.flush()
    return report


def _table(raw):
    # A pandas DataFrame where pandas is installed, else a dict of columns
    # (numpy arrays where numpy is, lists otherwise), in run order.
    if "issues" in raw:
        raise ScenarioError(raw["issues"])
    try:
        import pandas
        return pandas.DataFrame(raw)
    except ImportError:
        pass
    if numpy is None:
        return dict(raw)
    return {k: numpy.asarray(v) for k, v in raw.items()}


def _jobs(jobs):
    # As the command line's --jobs: 1 to 4096 runs at a time.
    if not 1 <= int(jobs) <= 4096:
        raise ValueError("jobs: expected 1 to 4096 runs at a time, got %r" % (jobs,))
    return int(jobs)


def runs(path, n, jobs=1, set=None, progress=True):  # noqa: A002
    """`n` runs of the scenario (`linesim run --runs N`: each its own seed
    derived from the scenario's), on `jobs` threads. A table, one row per
    run: id, seed, status, every metric, error, wall_s. Failed runs are rows
    with their error; a refused scenario raises ScenarioError."""
    if not 2 <= int(n) <= 1_000_000:
        raise ValueError("n: expected 2 to 1000000 runs (linesim.run for one), got %r" % (n,))
    sets = ["%s=%s" % (k, _text(v)) for k, v in (set or {}).items()]
    return _table(_linesim.runs(os.fspath(path), sets, int(n), _jobs(jobs), _progress(progress)))


def sweep(path_or_dict, jobs=1, progress=True):
    """A sweep (a sweep file, or a dict with the same keys; its `scenario`
    relative to the current folder) on `jobs` threads: a table, one row per
    run, as `linesim sweep` writes results.csv."""
    if isinstance(path_or_dict, dict):
        spec = dict(path_or_dict)
        if "scenario" in spec:
            spec["scenario"] = os.path.abspath(os.fspath(spec["scenario"]))
        with tempfile.NamedTemporaryFile("w", suffix=".yaml", prefix="linesim_sweep_",
                                         delete=False) as f:
            json.dump(spec, f)  # JSON is YAML
        try:
            return _table(_linesim.sweep(f.name, _jobs(jobs), _progress(progress)))
        finally:
            os.unlink(f.name)
    return _table(_linesim.sweep(os.fspath(path_or_dict), _jobs(jobs), _progress(progress)))


def inspect(type_or_path, set=None):  # noqa: A002
    """A unit type's variables (a list of dicts: name, causality, type, size,
    unit, start, rule, description), as `linesim inspect TYPE` prints them;
    or, for a scenario (a path, or a dict of the files' schema), the system
    it builds: {"name", "units": {name: {"type", "step_s", "variables"}},
    "connections": [(from, to)], "step_order"}."""
    if isinstance(type_or_path, str) and not os.path.exists(type_or_path) and \
            type_or_path in unit_types():
        return _linesim.inspect(type_or_path)
    if isinstance(type_or_path, (dict, os.PathLike)) or os.path.exists(type_or_path):
        sets = ["%s=%s" % (k, _text(v)) for k, v in (set or {}).items()]
        with _scenario_file(type_or_path) as file:
            raw = _linesim.inspect_scenario(file, sets)
        if "issues" in raw:
            raise ScenarioError(raw["issues"])
        return raw
    return _linesim.inspect(type_or_path)  # an unknown type: ValueError naming the closest


def unit_types():
    """Every registered unit type's name."""
    return _linesim.unit_types()


def math_library():
    """The transcendental functions the runs use (provenance)."""
    return _linesim.math_library()
