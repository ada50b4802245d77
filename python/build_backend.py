"""The PEP 517 build backend of the `linesim` Python package, without
network (pyproject.toml names no build requirement: pip needs nothing from
an index). The stock backends (setuptools, scikit-build-core) would have to
come from PyPI into pip's isolated build environment.

Two places use it:

- the repository (`pip install .` from its root): it builds the native
  part with the project's CMake in an existing build tree when there is one
  (`build/`, as tools/build.sh made it, or $LINESIM_BUILD_DIR), building
  only the module's targets; else it first says which Debian packages are
  missing (tools/setup.sh --missing) and configures `build/` without the
  tests and benchmarks. Ninja's status line ([n/m] per step) goes to pip's
  output (`pip install -v .` shows it).
- an installed linesim (`pip install PREFIX/share/linesim/python`, next to
  which `cmake --install` or the .deb put layout.json): it packs the
  installed package, which is built already.

Either way the wheel holds the package (its Python files, the native
module, the type stub and py.typed) and the model files in linesim/models,
where the native part finds them (models/models_dir.h): the installed
package needs neither the source tree nor the prefix it came from."""

import base64
import hashlib
import importlib.machinery
import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
NAME = "linesim"
# The package's files besides the native module (python/CMakeLists.txt
# installs the same).
PACKAGE_FILES = ("__init__.py", "_linesim.pyi", "py.typed")


def _say(text):
    # pip shows the backend's output with -v (and when it fails).
    print("linesim: " + text, file=sys.stderr, flush=True)


def _layout():
    # An installed linesim's: where the package and the models are,
    # relative to this file, and the version.
    path = os.path.join(HERE, "layout.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        layout = json.load(f)
    return {"version": layout["version"],
            "package": os.path.normpath(os.path.join(HERE, layout["package"])),
            "models": os.path.normpath(os.path.join(HERE, layout["models"]))}


def _root():
    return os.path.dirname(HERE)


def _version():
    layout = _layout()
    if layout:
        return layout["version"]
    # The project's one version: CMakeLists.txt's project(... VERSION x.y.z).
    with open(os.path.join(_root(), "CMakeLists.txt")) as f:
        found = re.search(r"project\(\s*linesim\s+VERSION\s+([0-9.]+)", f.read())
    if not found:
        raise RuntimeError("no project(linesim VERSION ...) in CMakeLists.txt")
    return found.group(1)


def _missing_packages():
    # The Debian packages the build needs that are not installed, as
    # tools/setup.sh lists them; [] where dpkg is not there to ask.
    if shutil.which("dpkg-query") is None:
        return []
    done = subprocess.run(["bash", os.path.join(_root(), "tools", "setup.sh"), "--missing"],
                          check=True, capture_output=True, text=True)
    return done.stdout.split()


def _build_dir():
    given = os.environ.get("LINESIM_BUILD_DIR")
    if given:
        return os.path.abspath(given)
    return os.path.join(_root(), "build")


def _configure(build):
    missing = _missing_packages()
    if missing:
        raise RuntimeError(
            "linesim needs these Debian packages to build: %s\n"
            "  install them with: sudo apt-get install %s\n"
            "  (or run: sudo bash tools/setup.sh, which installs everything the tests need too)"
            % (" ".join(missing), " ".join(missing)))
    _say("configuring %s (Release, Ninja; without the tests and benchmarks)" % build)
    command = ["cmake", "-S", _root(), "-B", build, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
               "-DLINESIM_BUILD_TESTS=OFF", "-DLINESIM_BUILD_BENCH=OFF"]
    if shutil.which("ccache"):
        command += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache", "-DCMAKE_C_COMPILER_LAUNCHER=ccache"]
    subprocess.run(command, check=True, stdout=sys.stderr)


def _native_from_source():
    # The module built in the build tree (only its targets and what they
    # need), and the folder of the package's Python files.
    build = _build_dir()
    if os.path.exists(os.path.join(build, "CMakeCache.txt")):
        _say("reusing the build tree %s" % build)
    else:
        _configure(build)
    _say("building the native part (cmake --build %s --target linesim_python)" % build)
    subprocess.run(["cmake", "--build", build, "--parallel", str(os.cpu_count() or 1),
                    "--target", "linesim_python", "linesim_python_package"],
                   check=True, stdout=sys.stderr)
    return os.path.join(build, "python", NAME), os.path.join(_root(), "models")


def _package_and_models():
    layout = _layout()
    if layout:
        return layout["package"], layout["models"]
    return _native_from_source()


def _native_module(folder):
    suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
    modules = [f for f in os.listdir(folder) if f.startswith("_linesim") and f.endswith(suffix)]
    if not modules:
        raise RuntimeError("the native part was not built for this Python (%s) in %s"
                           % (suffix, folder))
    return modules[0]


def _tag():
    # The module's ABI: this CPython's, on this platform.
    version = "cp%d%d" % tuple(map(int, sysconfig.get_python_version().split(".")))
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return "%s-%s-%s" % (version, version, platform)


def _metadata():
    return ("Metadata-Version: 2.1\nName: %s\nVersion: %s\n"
            "Summary: Co-simulation of mobile robots on moving-floor assembly lines\n"
            "Requires-Python: >=3.11\n" % (NAME, _version()))


def _info():
    return "%s-%s.dist-info" % (NAME, _version())


def get_requires_for_build_wheel(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    os.makedirs(os.path.join(metadata_directory, _info()), exist_ok=True)
    with open(os.path.join(metadata_directory, _info(), "METADATA"), "w") as f:
        f.write(_metadata())
    return _info()


def _wheel_files(package, models):
    # Path in the wheel -> file on disk.
    files = {}
    for name in PACKAGE_FILES + (_native_module(package),):
        files[NAME + "/" + name] = os.path.join(package, name)
    for folder, _, names in os.walk(models):
        for name in sorted(names):
            if name.endswith(".yaml"):
                path = os.path.join(folder, name)
                files[NAME + "/models/" + os.path.relpath(path, models).replace(os.sep, "/")] = path
    return files


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    package, models = _package_and_models()
    tag = _tag()
    info = _info()
    contents = {}
    for path, source in sorted(_wheel_files(package, models).items()):
        with open(source, "rb") as f:
            contents[path] = f.read()
    contents[info + "/METADATA"] = _metadata().encode()
    contents[info + "/WHEEL"] = ("Wheel-Version: 1.0\nGenerator: linesim build_backend\n"
                                 "Root-Is-Purelib: false\nTag: %s\n" % tag).encode()
    record = []
    for path, data in contents.items():
        digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
        record.append("%s,sha256=%s,%d" % (path, digest, len(data)))
    record.append(info + "/RECORD,,")
    contents[info + "/RECORD"] = ("\n".join(record) + "\n").encode()
    name = "%s-%s-%s.whl" % (NAME, _version(), tag)
    _say("packing %s (%d files)" % (name, len(contents)))
    with zipfile.ZipFile(os.path.join(wheel_directory, name), "w", zipfile.ZIP_DEFLATED) as z:
        for path, data in contents.items():
            z.writestr(path, data)
    return name
