"""The Debian package as a user installs it: CPack builds it from this build
tree, it is extracted into a temporary root (dpkg-deb -x: a clean prefix, no
container needed), and what it ships runs from a folder outside the source
tree, finding its models, its FMU runtime and its Python package's native
part relative to itself (models/models_dir.h), never in the source tree."""

import glob
import os
import re
import shutil
import subprocess
import sys
import zipfile

import pytest

BUILD = os.environ["LINESIM_BUILD_DIR"]
SOURCE = os.environ["LINESIM_SOURCE_DIR"]
CPACK = os.environ.get("LINESIM_CPACK", "cpack")
# A robot file that exists only in the extracted root's models (a copy of
# raw3.yaml under a name the source tree has not): a run that finds it read
# the installed models.
ONLY_INSTALLED = "install_check"
# Appended to the extracted FMU runtime (an ELF file ignores trailing
# bytes): an FMU that carries it was made from the installed runtime.
MARKER = b"linesim install check: the installed FMU runtime\n"


@pytest.fixture(scope="module")
def deb(tmp_path_factory):
    out = tmp_path_factory.mktemp("cpack")
    subprocess.run([CPACK, "--config", os.path.join(BUILD, "CPackConfig.cmake"), "-B", str(out)],
                   check=True, capture_output=True, text=True)
    debs = glob.glob(str(out / "*.deb"))
    assert len(debs) == 1, debs
    return debs[0]


@pytest.fixture(scope="module")
def root(deb, tmp_path_factory):
    root = tmp_path_factory.mktemp("root")
    subprocess.run(["dpkg-deb", "-x", deb, str(root)], check=True)
    robots = root / "usr" / "share" / "linesim" / "models" / "robots"
    shutil.copy(robots / "raw3.yaml", robots / (ONLY_INSTALLED + ".yaml"))
    with open(root / "usr" / "lib" / "linesim" / "liblinesim_fmu_runtime.so", "ab") as f:
        f.write(MARKER)
    return root


@pytest.fixture
def work(tmp_path):
    # A folder outside the source tree with the scenarios the package ships,
    # as the README has a user copy them.
    assert not str(tmp_path).startswith(SOURCE)
    return tmp_path


def installed_env(root):
    env = {k: v for k, v in os.environ.items() if not k.startswith("LINESIM_")}
    env["PATH"] = str(root / "usr" / "bin") + os.pathsep + env.get("PATH", "")
    return env


def depends(deb):
    # Depends as package names, each alternative ("a (>= 1) | b") split.
    field = subprocess.run(["dpkg-deb", "-f", deb, "Depends"], check=True, capture_output=True,
                           text=True).stdout
    return {re.sub(r"\s*\(.*\)", "", alternative).strip()
            for group in field.split(",") for alternative in group.split("|")}, field


def owners(paths):
    # The Debian package that ships each library, tried as ldd names it and
    # with the merged /usr folded either way; one dpkg query for all.
    candidates = {}
    for path in paths:
        real = os.path.realpath(path)
        for candidate in (path, real, re.sub(r"^/usr", "", real), "/usr" + path):
            candidates.setdefault(candidate, path)
    done = subprocess.run(["dpkg", "-S"] + sorted(candidates), capture_output=True, text=True)
    found = {}
    for line in done.stdout.splitlines():
        package, _, shipped = line.partition(": ")
        if shipped in candidates:
            found[candidates[shipped]] = package.split(":")[0]
    return found


# Guards the package's dependencies: every shared library the shipped
# binaries load belongs to a Debian package in Depends (computed by
# dpkg-shlibdeps, not listed by hand), no -dev package is a dependency, and
# what linesim runs besides (gnuplot) and the Python its module is built for
# are there.
def test_depends_are_the_runtime_packages(deb, root):
    names, field = depends(deb)
    print("Depends:", field)
    assert not [n for n in names if n.endswith("-dev")], field
    assert "gnuplot-nox" in names and "python3" in names, field
    assert re.search(r"python3 \(>= 3\.\d+\), python3 \(<< 3\.\d+\)", field), field
    binaries = [root / "usr" / "bin" / "linesim", root / "usr" / "lib" / "linesim" /
                "liblinesim_fmu_runtime.so"]
    binaries += glob.glob(str(root / "usr" / "lib" / "python3" / "dist-packages" / "linesim" /
                              "_linesim*.so"))
    assert len(binaries) == 3
    needed = {}  # library path -> the binary that names it
    for binary in binaries:
        # The libraries it names itself (NEEDED; theirs are their packages'
        # dependencies), found where the loader finds them.
        dynamic = subprocess.run(["readelf", "-d", str(binary)], check=True, capture_output=True,
                                 text=True).stdout
        ldd = subprocess.run(["ldd", str(binary)], check=True, capture_output=True, text=True)
        found = dict(re.findall(r"^\s*(\S+) => (/\S+)", ldd.stdout, re.M))
        found.update({os.path.basename(p): p
                      for p in re.findall(r"^\s*(/\S+) \(", ldd.stdout, re.M)})
        sonames = re.findall(r"\(NEEDED\)\s+Shared library: \[(.+)\]", dynamic)
        assert sonames, binary
        needed.update({found[soname]: binary for soname in sonames})
    packages = owners(needed)
    for path, binary in needed.items():
        assert path in packages, path
        assert packages[path] in names, "%s needs %s (%s), not in Depends: %s" % (
            binary, path, packages[path], field)


def readme_commands():
    # The commands of the README's "The commands, one example each" block,
    # without their comments.
    with open(os.path.join(SOURCE, "README.md")) as f:
        text = f.read()
    block = text.split("## The commands, one example each", 1)[1].split("```sh", 1)[1]
    block = block.split("```", 1)[0].replace("\\\n", " ")
    return [re.sub(r"\s+#.*$", "", line).strip() for line in block.splitlines() if line.strip()]


def run(args, cwd, env, shell=False):
    done = subprocess.run(args, cwd=cwd, env=env, shell=shell, capture_output=True, text=True)
    assert done.returncode == 0, "%s\n%s%s" % (args, done.stdout, done.stderr)
    return done


# Guards the installed command line: the README's quick commands run as
# written from a folder outside the source tree with only the installed
# linesim on PATH (a run with its plots and replay, the inspections, an FMU
# export); the models are the installed ones (a robot only they have), and
# export-fmu ships the installed runtime.
def test_installed_linesim_runs_the_readme_commands(root, work):
    shutil.copytree(root / "usr" / "share" / "linesim" / "scenarios", work / "scenarios")
    env = installed_env(root)
    commands = readme_commands()
    quick = ["linesim run scenarios/cross_line.yaml --out out/cl",
             "linesim inspect chassis",
             "linesim inspect scenarios/cross_line.yaml",
             "linesim export-fmu dc_motor --set model=maxon_re40_148877 --out motor.fmu",
             "linesim inspect motor.fmu"]
    for command in quick:
        assert command in commands, command
        run(command, work, env, shell=True)
    for name in ("summary.json", "signals.csv", "top_view.png", "replay.html"):
        assert (work / "out" / "cl" / name).stat().st_size > 0, name
    with zipfile.ZipFile(work / "motor.fmu") as fmu:
        binaries = [n for n in fmu.namelist() if n.startswith("binaries/") and n.endswith(".so")]
        assert binaries and all(fmu.read(n).endswith(MARKER) for n in binaries), binaries
    run(["linesim", "run", "scenarios/cross_line.yaml", "--out", "out/ic", "--no-replay",
         "--set", "robot.model=" + ONLY_INSTALLED, "--set", "duration_s=0.5"], work, env)


PYTHON_CHECK = """
import sys, linesim
r = linesim.run(sys.argv[1], set={"robot.model": sys.argv[2]}, duration_s=0.5)
print(linesim.__file__, linesim.__version__, linesim.math_library().split()[0], r.status)
"""


# Guards the installed Python package: from the extracted dist-packages
# (PYTHONPATH; /usr/lib/python3/dist-packages where the .deb is installed)
# it imports, and its native part finds the installed models.
def test_installed_python_package_runs(root, work):
    site = root / "usr" / "lib" / "python3" / "dist-packages"
    env = dict(installed_env(root), PYTHONPATH=str(site))
    scenario = root / "usr" / "share" / "linesim" / "scenarios" / "cross_line.yaml"
    done = run([sys.executable, "-c", PYTHON_CHECK, str(scenario), ONLY_INSTALLED], work, env)
    file, version, math, status = done.stdout.split()
    assert file.startswith(str(site)) and status == "ok" and math == "sleef"
    assert re.fullmatch(r"\d+\.\d+\.\d+", version)


# Guards `pip install` of the installed package: pip (offline, nothing from
# an index) makes a wheel of PREFIX/share/linesim/python, which holds the
# built package and the models, and that wheel installed into a folder of
# its own runs without the prefix's models.
def test_pip_wheel_of_the_installed_package(root, work):
    wheels = work / "wheels"
    run([sys.executable, "-m", "pip", "wheel", "--no-index", "--no-deps", "-w", str(wheels),
         str(root / "usr" / "share" / "linesim" / "python")], work, installed_env(root))
    [wheel] = glob.glob(str(wheels / "linesim-*.whl"))
    site = work / "site"
    with zipfile.ZipFile(wheel) as z:
        z.extractall(site)
        names = z.namelist()
    assert "linesim/py.typed" in names and "linesim/_linesim.pyi" in names
    assert "linesim/models/robots/%s.yaml" % ONLY_INSTALLED in names
    # The prefix's models gone: the wheel's own are read.
    shutil.rmtree(root / "usr" / "share" / "linesim" / "models")
    try:
        env = dict(installed_env(root), PYTHONPATH=str(site))
        scenario = work / "cross_line.yaml"
        shutil.copy(os.path.join(SOURCE, "scenarios", "cross_line.yaml"), scenario)
        done = run([sys.executable, "-c", PYTHON_CHECK, str(scenario), ONLY_INSTALLED], work, env)
        assert done.stdout.split()[0].startswith(str(site)) and done.stdout.split()[-1] == "ok"
    finally:
        shutil.copytree(site / "linesim" / "models", root / "usr" / "share" / "linesim" / "models")
