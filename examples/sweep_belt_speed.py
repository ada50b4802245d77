"""Paper 1, Sec. VI-B as a curve, from Python: the Rob@Work 3 crosses the
running line at belt speeds from 0.05 to 0.25 m/s with the per-wheel
compensation (Algorithm 1) on and off; the largest deviation from the path
against the belt speed, the mean of two repeats per point
(scenarios/sweeps/belt_speed_compensation.yaml, as `linesim sweep` runs it).

    python3 examples/sweep_belt_speed.py [OUT_FOLDER]     # from the repository's root

Writes OUT_FOLDER/sweep_belt_speed.csv and .png (gnuplot) and prints the
table. Each block below is a notebook cell."""

import os
import subprocess
import sys
from typing import Dict, List, Tuple

# From the repository (the package beside this folder, its native part in
# build/), or installed (share/linesim/examples: the package is on Python's
# path, the scenarios beside this folder).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import linesim  # noqa: E402

# %% The sweep: 5 belt speeds x compensation on/off x 2 repeats = 20 runs.
out = sys.argv[1] if len(sys.argv) > 1 else "out/sweep_belt_speed"
os.makedirs(out, exist_ok=True)
here = os.path.dirname(os.path.abspath(__file__))
table = linesim.sweep(os.path.join(here, "..", "scenarios", "sweeps",
                                   "belt_speed_compensation.yaml"), jobs=2)

# %% The mean over the repeats, per belt speed (a float column) and
# compensation (a bool column).
speed, compensation = table["line.belts.0.speed_mps"], table["control.compensation"]
deviation = table["max_path_deviation_m"]
points: Dict[Tuple[float, bool], List[float]] = {}
for s, c, d in zip(speed, compensation, deviation):
    points.setdefault((float(s), bool(c)), []).append(float(d))


def mean(values: List[float]) -> float:
    return sum(values) / len(values)


speeds = sorted({s for s, _ in points})
rows = [(s, mean(points[(s, True)]), mean(points[(s, False)])) for s in speeds]
csv_path = os.path.join(out, "sweep_belt_speed.csv")
with open(csv_path, "w") as f:
    f.write("belt_speed_mps,max_deviation_compensated_m,max_deviation_nominal_m\n")
    for r in rows:
        f.write("%r,%r,%r\n" % r)
print("belt speed (m/s)   compensated (mm)   nominal (mm)")
for s, on, off in rows:
    print("%16.2f %18.1f %14.1f" % (s, 1000 * on, 1000 * off))

# %% The figure (gnuplot, as linesim's own plots), with paper 1's 4 cm bound.
png = os.path.join(out, "sweep_belt_speed.png")
script = """set terminal pngcairo size 900,560
set output '%s'
set datafile separator ','
set key top left
set xlabel 'belt speed (m/s)'
set ylabel 'largest deviation from the path (mm)'
set title 'cross\\_line: compensation on and off (mean of 2 runs per point)'
plot '%s' using 1:($2*1000) skip 1 with linespoints title 'compensated (Algorithm 1)', \\
     '' using 1:($3*1000) skip 1 with linespoints title 'nominal', \\
     40 with lines dashtype 2 title '4 cm (paper 1, Sec. VI-B)'
""" % (png, csv_path)
subprocess.run(["gnuplot"], input=script, text=True, check=True)
print("wrote", csv_path, "and", png)
