"""linesim from Python: run a scenario and get its status, metrics, signals
(numpy arrays) and summary as data, in their types.

    import linesim
    r = linesim.run("scenarios/cross_line.yaml", set={"task.speed_mps": 0.2})
    print(r.status, r.metrics["max_path_deviation_m"], r.metrics["collisions"])
    print(r.signals["deviation.deviation"].max(), r.units["deviation.deviation"])

A refused scenario raises ScenarioError (file, line, key and every problem);
a run that fails raises RunError (unit, variable, time and cause; the
partial result as .result); Ctrl-C stops a run within a step and raises
KeyboardInterrupt. The numbers are the command line's, to the bit: the run
goes through the same session (session/session.h) with the same math
library. Every public function's help() is its reference; docs/python.md
is the guide.
"""

from __future__ import annotations

import array
import glob
import importlib.machinery
import importlib.util
import os
import json
import sys
from types import ModuleType
from typing import (TYPE_CHECKING, Any, Callable, ClassVar, Dict, List, Mapping, Optional, Tuple,
                    TypedDict, Union, cast)

if TYPE_CHECKING:
    import numpy.typing

    from . import _linesim

try:
    import numpy
except ImportError:  # signals as array.array('d') then
    numpy = None  # type: ignore[assignment]


def _load_native() -> ModuleType:
    # Next to this file (an installed package, or the copy in build/python),
    # else in the build tree of the repository this file is in.
    here = os.path.dirname(os.path.abspath(__file__))
    suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
    found: List[str] = []
    for folder in (here, os.path.join(here, "..", "build", "python", "linesim")):
        found = glob.glob(os.path.join(folder, "_linesim*" + suffix))
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
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        sys.setdlopenflags(flags)
    return module


if not TYPE_CHECKING:
    _linesim = _load_native()

__version__: str = _linesim.__version__
"""The version of linesim this package is (the project's, CMakeLists.txt)."""

__all__ = ["run", "runs", "sweep", "inspect", "unit_types", "math_library", "Unit", "Result",
           "ScenarioError", "RunError", "Problem", "Failure", "Variable", "UnitSystem",
           "SystemDescription", "Scenario", "Table", "Value", "Metric", "Column"]

#: A scenario: the path of a scenario file, or a dict of the files' schema
#: (a system's `units` and `connections`, or a robot scenario).
Scenario = Union[str, "os.PathLike[str]", Mapping[str, Any]]
#: A variable's value: a float (Real), an int (Integer), a bool (Boolean),
#: a str (String) or a list of floats (a Real array).
Value = Union[float, int, bool, str, List[float]]
#: A recorded signal: a numpy float64 array, or array.array('d') without
#: numpy.
Column = Union["numpy.typing.NDArray[numpy.float64]", "array.array[float]"]
#: A table of runs (runs(), sweep()): a pandas.DataFrame where pandas is
#: installed, else a dict of columns (column name -> numpy array, or list
#: without numpy), one row per run. Typed as Any: which of the two depends
#: on the installation.
Table = Any
#: A metric's value: an int for a count (the final, smallest or largest
#: value of an Integer variable, e.g. `collisions`), a bool for a flag, a
#: float otherwise; None for a count of a run that failed before it had one.
Metric = Union[float, int, bool, None]


class Problem(TypedDict):
    """One reason a scenario was refused."""

    file: str
    """The scenario's file, the file it reads (a robot file), or "<dict>"
    for a scenario given as a dict."""
    line: int
    """1-based; 0 when unknown (a --set value, a dict)."""
    key: str
    """The key path ("units.motor.parameters.resistance")."""
    message: str
    """The bad value and what was expected."""
    from_command_line: bool
    """The value came from `set`."""


class Failure(TypedDict):
    """One failure of a run."""

    unit: str
    unit_type: str
    time_s: Optional[float]
    """When it failed; None when not at a time (the recording)."""
    phase: str
    """"setup", "initialize", "step", ..., "metric", "recording"."""
    variable: str
    """The variable it concerns ("" for none)."""
    cause: str
    message: str
    """All of the above in one sentence."""


class Variable(TypedDict):
    """One variable of a unit (inspect())."""

    name: str
    causality: str
    """"parameter", "input", "output" or "local"."""
    type: str
    """"Real", "Integer", "Boolean", "String" or "Real[n]"."""
    size: int
    unit: str
    """Its unit of measure ("" for none)."""
    start: Value
    """Its start value, in its type: declared, or as the scenario set it."""
    rule: str
    """What values it takes ("> 0", "(0, 1]", "one of: a, b", "required";
    "" for none)."""
    description: str
    depends_on: List[str]


class UnitSystem(TypedDict):
    """A unit of a scenario's system (inspect() of a scenario)."""

    type: str
    step_s: float
    variables: List[Variable]


class SystemDescription(TypedDict):
    """The system a scenario builds (inspect() of a scenario)."""

    name: str
    units: Dict[str, UnitSystem]
    connections: List[Tuple[str, str]]
    """(from, to) as "unit.variable" or "unit.variable[i]"."""
    step_order: List[str]


class Unit:
    """A unit written in Python, to put in a scenario in place of a shipped
    one: run(..., units={"path_follower": MyFollower}). Declare

        inputs = {"position": ("m", 2), "yaw": ("rad", 1)}    # name: (unit, size)
        outputs = {"velocity_command": ("m/s", 2)}            # name: (unit, size)
        parameters = {"speed": ("m/s", 0.3)}                  # name: (unit, default)

    and define setup(self), initialize(self) and do_step(self, t, dt)
    (seconds), each optional. Names are letters, digits and '_', as every
    unit's variables. Variables are attributes: a float, or a list of
    `size` floats; inputs are set before each call, outputs read after (a
    number, or a sequence of `size` numbers: anything else fails the run
    naming the variable, what it got and what it takes). Each call holds
    the GIL; the native units step without it. The unit replaced keeps its
    connections and those of its parameters this class declares; a
    master.retry restores its declared variables, not the object's other
    attributes. KeyboardInterrupt and SystemExit raised in a call stop the
    run and are raised by linesim.run; any other exception fails the run
    (RunError naming the unit)."""

    inputs: ClassVar[Dict[str, Tuple[str, int]]] = {}
    outputs: ClassVar[Dict[str, Tuple[str, int]]] = {}
    parameters: ClassVar[Dict[str, Tuple[str, Union[float, List[float]]]]] = {}

    if TYPE_CHECKING:
        # The declared variables are attributes set by the run: a float or
        # a list of floats.
        def __getattr__(self, name: str) -> Any: ...


_registered: Dict[type, str] = {}


def _unit_type(cls: type) -> str:
    # One registered type per class object (a class defined again in a
    # notebook is another type).
    if not (isinstance(cls, type) and issubclass(cls, Unit)):
        raise TypeError("units: expected linesim.Unit subclasses, got %r" % (cls,))
    if cls not in _registered:
        name = "python.%s.%s_%x" % (cls.__module__, cls.__qualname__, id(cls))
        _linesim.register_unit(name, cls)
        _registered[cls] = name
    return _registered[cls]


class ScenarioError(Exception):
    """The scenario was refused before anything ran. `problems` lists each
    (Problem: file, line, key, message, from_command_line); `file`, `line`
    and `key` are the first one's. A scenario given as a dict has file
    "<dict>" and the key path in the dict."""

    def __init__(self, problems: List[Problem]) -> None:
        self.problems = problems
        first: Mapping[str, Any] = {}
        if problems:
            first = problems[0]
        self.file: str = first.get("file", "")
        self.line: int = first.get("line", 0)
        self.key: str = first.get("key", "")
        lines = []
        for p in problems:
            where = p["file"] + (":" + str(p["line"]) if p["line"] else "")
            lines.append(where + ": " + (p["key"] + ": " if p["key"] else "") + p["message"])
        super().__init__("\n".join(lines))


class RunError(Exception):
    """The run failed: `unit`, `variable`, `time_s`, `cause` and `phase` of
    the first failure, every failure in `errors`, what was recorded in
    `result`."""

    def __init__(self, result: Result) -> None:
        self.result = result
        self.errors: List[Failure] = result.errors
        first = result.errors[0]
        self.unit: str = first["unit"]
        self.variable: str = first["variable"]
        self.time_s: Optional[float] = first["time_s"]
        self.cause: str = first["cause"]
        self.phase: str = first["phase"]
        super().__init__(first["message"])


class Result:
    """What a run gave.

    status: "ok" or "failed".
    metrics: name -> value, in the scenario's order: a float, or an int for
        a count (`collisions`), a bool for a flag.
    signals: column -> numpy float64 array (array.array('d') without
        numpy), with "time_s" first.
    units: column -> unit of measure ("m", "rad/s", ...).
    errors: every failure (Failure dicts); empty when ok.
    summary: summary.json as a dict (settings, provenance, timing).
    out: the folder written (run(out=...)), or None.
    """

    def __init__(self, raw: Mapping[str, Any]) -> None:
        self.status: str = raw["status"]
        self.metrics: Dict[str, Metric] = dict(raw["metrics"])
        self.signals: Dict[str, Column] = {
            name: _column(data) for name, data in zip(raw["signal_names"], raw["signal_columns"])}
        self.units: Dict[str, str] = dict(zip(raw["signal_names"], raw["signal_units"]))
        self.errors: List[Failure] = raw["errors"]
        self.summary: Dict[str, Any] = json.loads(raw["summary"])
        self.out: Optional[str] = None

    def __repr__(self) -> str:
        return "linesim.Result(status=%r, %d metrics, %d signals of %d rows)" % (
            self.status, len(self.metrics), len(self.signals), len(self.signals["time_s"]))


def _column(data: bytes) -> Column:
    if numpy is not None:
        return numpy.frombuffer(data, dtype=numpy.float64)
    column = array.array("d")
    column.frombytes(data)
    return column


def _text(value: object) -> str:
    # A --set value: YAML text. JSON is YAML, so lists and maps go as JSON.
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and value != value:
        return ".nan"
    if isinstance(value, float) and value in (float("inf"), float("-inf")):
        return ".inf" if value > 0 else "-.inf"  # as YAML writes them (and the dicts go)
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return value
    return json.dumps(value)


def _sets(overrides: Optional[Mapping[str, object]]) -> List[str]:
    return ["%s=%s" % (k, _text(v)) for k, v in (overrides or {}).items()]


def _given(scenario: Scenario) -> Union[str, Dict[str, Any]]:
    # A dict goes to the native part as data (no file in between); a path
    # as text.
    if isinstance(scenario, Mapping):
        return dict(scenario)
    return os.fspath(scenario)


def run(scenario: Scenario, set: Optional[Mapping[str, object]] = None,  # noqa: A002
        duration_s: Optional[float] = None, seed: Optional[int] = None,
        units: Optional[Mapping[str, type]] = None,
        out: Union[str, "os.PathLike[str]", None] = None) -> Result:
    """Runs one scenario, as `linesim run` does, in this process.

    Args:
        scenario: the path of a scenario file, or a dict of the files'
            schema (a system's `units` and `connections`, or a robot
            scenario), passed to the loader as data: models are named as in
            a file (`raw3`, `factory_line`), relative paths are relative to
            the current folder, and a problem is reported at the dict's key
            path (file "<dict>").
        set: overrides {"dotted.key.path": value}, as --set key.path=value:
            numbers, bools, text (YAML), or lists and dicts.
        duration_s: the simulated time in seconds, when given (else the
            scenario's).
        seed: the scenario's seed, when given.
        units: {unit name: Unit subclass}: units written in Python in place
            of the scenario's; each keeps its connections and those of its
            parameters the class declares.
        out: a folder to write what `linesim run --out` writes
            (summary.json, signals.csv, the plots, replay.html); None
            writes nothing.

    Returns:
        A Result: status, metrics (floats; ints for counts), signals (numpy
        arrays), units of measure, errors, summary.

    Raises:
        ScenarioError: the scenario was refused before anything ran (every
            problem, each with file, line and key path).
        RunError: the run failed (unit, variable, time, cause; what was
            recorded in .result).
        KeyboardInterrupt: Ctrl-C during the run (it stops within a step;
            with `out`, the folder's summary.json says "interrupted"), or
            raised by a unit written in Python; SystemExit likewise.
        ValueError: `out` cannot be written (nothing ran).
        TypeError: a `units` value is not a Unit subclass.
    """
    sets = _sets(set)
    if duration_s is not None:
        sets.append("duration_s=%s" % _text(duration_s))
    if seed is not None:
        sets.append("seed=%s" % _text(seed))
    types = {name: _unit_type(cls) for name, cls in (units or {}).items()}
    raw = _linesim.run(_given(scenario), sets, types, os.fspath(out) if out is not None else "")
    if "issues" in raw:
        raise ScenarioError(raw["issues"])
    result = Result(raw)
    result.out = os.fspath(out) if out is not None else None
    if result.status != "ok":
        raise RunError(result)
    return result


def _progress(show: bool) -> Optional[Callable[[int, int], None]]:
    if not show:
        return None

    def report(done: int, total: int) -> None:
        sys.stderr.write("\rlinesim: %d of %d runs" % (done, total) + ("\n" if done == total else ""))
        sys.stderr.flush()
    return report


def _array(values: List[Any]) -> Any:
    # A column as numpy makes it; a missing number (a failed run's) as NaN,
    # as pandas has it.
    if all(v is not None for v in values):
        return numpy.asarray(values)
    if all(v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) for v in values):
        return numpy.asarray([numpy.nan if v is None else v for v in values], dtype=numpy.float64)
    return numpy.asarray(values, dtype=object)


def _table(raw: Mapping[str, Any]) -> Table:
    # A pandas DataFrame where pandas is installed, else a dict of columns
    # (numpy arrays where numpy is, lists otherwise), in run order.
    if "issues" in raw:
        raise ScenarioError(raw["issues"])
    try:
        import pandas  # type: ignore[import]
        return pandas.DataFrame(raw)
    except ImportError:
        pass
    if numpy is None:
        return dict(raw)
    return {k: _array(v) for k, v in raw.items()}


def _jobs(jobs: int) -> int:
    # As the command line's --jobs: 1 to 4096 runs at a time.
    if not 1 <= int(jobs) <= 4096:
        raise ValueError("jobs: expected 1 to 4096 runs at a time, got %r" % (jobs,))
    return int(jobs)


def runs(scenario: Union[str, "os.PathLike[str]"], n: int, jobs: int = 1,
         set: Optional[Mapping[str, object]] = None,  # noqa: A002
         progress: bool = True) -> Table:
    """Runs a scenario file `n` times, as `linesim run FILE --runs N` does:
    each run with its own seed derived from the scenario's, collecting every
    metric, to the bit the command line's rows whatever `jobs` is.

    Args:
        scenario: the path of a scenario file.
        n: the number of runs, 2 to 1,000,000 (linesim.run for one).
        jobs: runs at a time on threads, 1 to 4096.
        set: overrides {"dotted.key.path": value} for every run, as run()'s.
        progress: write "linesim: k of n runs" to stderr as runs finish.

    Returns:
        A Table, one row per run in run order: id, point, sample, repeat,
        seed (ints), status ("ok"/"failed"), every metric (floats; ints for
        counts; NaN where a run failed), error (text), wall_s.

    Raises:
        ScenarioError: the scenario was refused before anything ran.
        ValueError: `n` or `jobs` out of range.
        KeyboardInterrupt: Ctrl-C (the running runs stop at their next step).
    """
    if not 2 <= int(n) <= 1_000_000:
        raise ValueError("n: expected 2 to 1000000 runs (linesim.run for one), got %r" % (n,))
    return _table(_linesim.runs(os.fspath(scenario), _sets(set), int(n), _jobs(jobs),
                                _progress(progress)))


def sweep(spec: Union[str, "os.PathLike[str]", Mapping[str, Any]], jobs: int = 1,
          progress: bool = True) -> Table:
    """Runs a sweep, as `linesim sweep` does (without writing results.csv).

    Args:
        spec: the path of a sweep file, or a dict with a sweep file's keys
            (scenario, set, parameters, combine, samples, repeats, seed,
            seeds, metrics), passed as data: its `scenario` is relative to
            the current folder, and a problem is reported at the dict's key
            path (file "<dict>").
        jobs: runs at a time on threads, 1 to 4096.
        progress: write "linesim: k of n runs" to stderr as runs finish.

    Returns:
        A Table, one row per run in run order: id, point, sample, repeat,
        seed (ints), status, each parameter in its type (int, float or bool
        when every value of the column is one, else the YAML text), every
        metric (floats; ints for counts; NaN where a run failed), error,
        wall_s.

    Raises:
        ScenarioError: the sweep or its scenario was refused.
        ValueError: `jobs` out of range.
        KeyboardInterrupt: Ctrl-C (the running runs stop at their next step).
    """
    given: Union[str, Dict[str, Any]]
    if isinstance(spec, Mapping):
        given = dict(spec)
        if isinstance(given.get("scenario"), (str, os.PathLike)):
            given["scenario"] = os.path.abspath(os.fspath(given["scenario"]))
    else:
        given = os.fspath(spec)
    return _table(_linesim.sweep(given, _jobs(jobs), _progress(progress)))


def inspect(what: Scenario, set: Optional[Mapping[str, object]] = None  # noqa: A002
            ) -> Union[List[Variable], SystemDescription]:
    """Describes a unit type, or the system a scenario builds, as `linesim
    inspect` prints them.

    Args:
        what: a unit type's name ("dc_motor"): its variables; or a scenario
            (a path, or a dict of the files' schema): the system it builds.
        set: overrides for a scenario, as run()'s.

    Returns:
        For a type, a list of Variable dicts (name, causality, type, size,
        unit, start in its type, rule, description, depends_on). For a
        scenario, a SystemDescription: {"name", "units": {name: {"type",
        "step_s", "variables"}}, "connections": [(from, to)],
        "step_order"}.

    Raises:
        ScenarioError: the scenario was refused.
        ValueError: no such unit type (the message names the closest).
    """
    if isinstance(what, str) and not os.path.exists(what) and what in unit_types():
        return cast(List[Variable], _linesim.inspect(what))
    if isinstance(what, (Mapping, os.PathLike)) or os.path.exists(what):
        raw = _linesim.inspect_scenario(_given(what), _sets(set))
        if "issues" in raw:
            raise ScenarioError(raw["issues"])
        return cast(SystemDescription, raw)
    # An unknown type: ValueError naming the closest.
    return cast(List[Variable], _linesim.inspect(what))


def unit_types() -> List[str]:
    """Every registered unit type's name (the shipped ones, and the Python
    classes given to run() so far, as "python.MODULE.CLASS_ID")."""
    return _linesim.unit_types()


def math_library() -> str:
    """The transcendental functions the runs use (provenance): "sleef ..."
    when the package's own deterministic math is bound, as in every linesim
    executable."""
    return _linesim.math_library()
