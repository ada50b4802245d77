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

import json
import os
import sys

import numpy  # noqa: F401  (the native part returns numpy arrays)

# The native part brings its own transcendental functions (SLEEF, as every
# linesim executable): loaded with RTLD_DEEPBIND, it and the libraries it
# loads (ODE, SUNDIALS, FCL, Embree) bind to them before the libm the Python
# process has already loaded, whose results depend on the CPU.
_flags = sys.getdlopenflags()
sys.setdlopenflags(_flags | os.RTLD_DEEPBIND)
try:
    from . import _linesim
finally:
    sys.setdlopenflags(_flags)

__all__ = ["run", "inspect", "unit_types", "Result", "ScenarioError", "RunError"]


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
    `signals` (column -> numpy array, with "time_s"), `units` (column -> unit
    of measure), `errors` (dicts), `summary` (summary.json as a dict)."""

    def __init__(self, raw):
        self.status = raw["status"]
        self.metrics = dict(raw["metrics"])
        self.signals = dict(zip(raw["signal_names"], raw["signal_columns"]))
        self.units = dict(zip(raw["signal_names"], raw["signal_units"]))
        self.errors = raw["errors"]
        self.summary = json.loads(raw["summary"])

    def __repr__(self):
        return "linesim.Result(status=%r, %d metrics, %d signals of %d rows)" % (
            self.status, len(self.metrics), len(self.signals), len(self.signals["time_s"]))


def _text(value):
    # A --set value: YAML text. JSON is YAML, so lists and maps go as JSON.
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return value
    return json.dumps(value)


def run(path, set=None, duration_s=None, seed=None):  # noqa: A002 (the CLI's --set)
    """Runs the scenario file `path` with the overrides `set` ({"key.path":
    value}, as --set key.path=value), and `duration_s` and `seed` when given.
    Returns a Result; raises ScenarioError or RunError."""
    sets = ["%s=%s" % (k, _text(v)) for k, v in (set or {}).items()]
    if duration_s is not None:
        sets.append("duration_s=%s" % _text(duration_s))
    if seed is not None:
        sets.append("seed=%s" % _text(seed))
    raw = _linesim.run(os.fspath(path), sets)
    if "issues" in raw:
        raise ScenarioError(raw["issues"])
    result = Result(raw)
    if result.status != "ok":
        raise RunError(result)
    return result


def inspect(unit_type):
    """A unit type's variables (name, causality, type, size, unit, start, rule,
    description), as `linesim inspect TYPE` prints them."""
    return _linesim.inspect(unit_type)


def unit_types():
    """Every registered unit type's name."""
    return _linesim.unit_types()


def math_library():
    """The transcendental functions the runs use (provenance)."""
    return _linesim.math_library()
