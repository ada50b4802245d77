"""The README's commands as a user types them: the MPI sweep runs as
written on this machine, whatever its core count (CI's has 2)."""

import csv
import os
import re
import shutil
import subprocess

SOURCE = os.environ["LINESIM_SOURCE_DIR"]
CLI = os.environ["LINESIM_CLI"]


def readme_command(start):
    # The README's command line that starts with `start`, without its
    # comment.
    with open(os.path.join(SOURCE, "README.md")) as f:
        lines = [re.sub(r"\s+#.*$", "", line).strip() for line in f]
    found = [line for line in lines if line.startswith(start)]
    assert len(found) == 1, found
    return found[0]


# Guards the README's MPI example (issue: `mpirun -n 3` fails on a 2-core
# machine, "not enough slots"): the command as written, in a folder with the
# scenarios and `linesim` on PATH, runs every run of the sweep on MPI worker
# ranks. As root, Open MPI also wants --allow-run-as-root, which the README
# says; here it is given the equivalent way (its environment variables), so
# that the command stays exactly the README's.
def test_readme_mpirun_sweep_runs_as_written(tmp_path):
    command = readme_command("mpirun ")
    assert "linesim sweep scenarios/sweeps/master_step.yaml" in command
    shutil.copytree(os.path.join(SOURCE, "scenarios"), tmp_path / "scenarios")
    env = dict(os.environ)
    env["PATH"] = os.path.dirname(CLI) + os.pathsep + env["PATH"]
    if os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    done = subprocess.run(["bash", "-c", command], cwd=tmp_path, env=env, capture_output=True,
                          text=True)
    assert done.returncode == 0, "%s\n%s%s" % (command, done.stdout, done.stderr)
    assert "MPI worker rank(s)" in done.stdout, done.stdout
    out = re.search(r"--out (\S+)", command).group(1)
    with open(tmp_path / out / "results.csv") as f:
        rows = list(csv.DictReader(f))
    # master_step.yaml: 6 steps x 2 algorithms.
    assert len(rows) == 12
    assert all(r["status"] == "ok" for r in rows), rows
