"""The Python package (python/linesim): runs through the same session as the
command line, with the same numbers to the bit, and says what went wrong as
exceptions carrying the same fields."""

import csv
import json
import os
import subprocess
import tempfile

import numpy as np
import pytest

import linesim

SOURCE = os.environ["LINESIM_SOURCE_DIR"]
CLI = os.environ["LINESIM_CLI"]


def scenario(name):
    return os.path.join(SOURCE, "scenarios", name)


def cli_run(path, sets):
    out = tempfile.mkdtemp(prefix="linesim_py_")
    args = [CLI, "run", path, "--out", out, "--no-replay"]
    for s in sets:
        args += ["--set", s]
    subprocess.run(args, check=True, capture_output=True)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(out, "signals.csv")) as f:
        rows = list(csv.reader(f))
    return summary, rows


# Guards determinism through Python: the package loads its own math library
# (SLEEF, linesim/__init__.py) so that ODE, SUNDIALS and the units bind to it
# and not to the CPU-dispatched libm Python has loaded; a closed loop turns
# one bit into millimetres (without it, cross_line's signals differ from the
# command line's by 1 mm on an AVX-512 machine, measured), so every metric
# and every recorded value must be the command line's exactly.
@pytest.mark.parametrize("name,sets", [
    ("cross_line.yaml", ["duration_s=4"]),
    ("fleet_line.yaml", ["duration_s=1"]),
])
def test_run_gives_the_command_lines_numbers(name, sets):
    assert linesim.math_library().startswith("sleef")
    overrides = dict(s.split("=", 1) for s in sets)
    r = linesim.run(scenario(name), set=overrides)
    summary, rows = cli_run(scenario(name), sets)
    assert r.status == "ok"
    assert r.metrics == summary["metrics"]
    header = rows[0]
    assert [("time_s" if h == "time" else h) for h in header] == list(r.signals)
    table = np.array([[float(x) for x in row] for row in rows[1:]])
    for i, h in enumerate(header):
        column = r.signals["time_s" if h == "time" else h]
        assert np.array_equal(column, table[:, i]), h
    assert r.summary["provenance"]["scenario_sha256"] == summary["provenance"]["scenario_sha256"]


# Guards the signals' units of measure (from the variable tables).
def test_signals_carry_their_units():
    r = linesim.run(scenario("cross_line.yaml"), duration_s=0.5, seed=3)
    assert r.units["time_s"] == "s"
    assert r.units["deviation.deviation"] == "m"
    assert r.summary["settings"]["seed"] == 3
    assert len(r.signals["time_s"]) == 51  # 0.5 s at cross_line's 10 ms recording
    assert r.signals["time_s"][-1] == 0.5


# Guards the refusal: every problem, each with file, line and key.
def test_bad_scenario_raises_scenario_error():
    with pytest.raises(linesim.ScenarioError) as e:
        linesim.run(scenario("cross_line.yaml"), set={"task.speed_mps": -1, "seed": "x"})
    keys = [p["key"] for p in e.value.problems]
    assert "task.speed_mps" in keys and "seed" in keys
    assert e.value.file.endswith("cross_line.yaml")
    assert all(p["from_command_line"] for p in e.value.problems)
    with pytest.raises(linesim.ScenarioError) as e:
        linesim.run(os.path.join(SOURCE, "scenarios", "no_such_file.yaml"))
    assert "no_such_file.yaml" in str(e.value)


# Guards a numerical failure: RunError names the unit, the variable and the
# time (the command line's blow-up case: 1e308 V on a dc_motor).
def test_failed_run_raises_run_error(tmp_path):
    f = tmp_path / "blowup.yaml"
    f.write_text("""duration_s: 0.1
master: {algorithm: jacobi}
units:
  supply:
    type: step_signal
    parameters: {unit: V, steps: [{time_s: 0.01, value: 1.0e308}]}
  motor:
    type: dc_motor
connections:
  - {from: supply.value, to: motor.voltage}
""")
    with pytest.raises(linesim.RunError) as e:
        linesim.run(f)
    assert e.value.unit == "motor"
    assert e.value.time_s == 0.01
    assert e.value.phase == "step"
    assert "the derivative of current[0] is inf" in e.value.cause
    assert "unit 'motor'" not in e.value.cause  # the unit is named once, in .unit
    assert e.value.result.status == "failed"
    # What was recorded before the failure is kept: Jacobi, the motor sees
    # the voltage from the step starting at 0.01 s, so the rows 0 .. 0.01 s
    # at 1 ms (11) were recorded before, as in signals.csv.
    assert len(e.value.result.signals["time_s"]) == 11


# Guards inspect: the variable table as data, as `linesim inspect TYPE`.
def test_inspect_gives_the_variable_table():
    rows = {v["name"]: v for v in linesim.inspect("dc_motor")}
    assert rows["voltage"]["causality"] == "input"
    assert rows["voltage"]["unit"] == "V"
    assert "dc_motor" in linesim.unit_types()
    with pytest.raises(ValueError):
        linesim.inspect("no_such_type")
