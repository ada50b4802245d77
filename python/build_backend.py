"""The PEP 517 build backend of the `linesim` Python package: `pip install .`
from the repository's root, without network (pyproject.toml names no build
requirement: pip needs nothing from an index). It builds the native part
with the project's CMake (in build/, as tools/build.sh does; configured
there first if needed) and packs linesim/__init__.py and the module into a
wheel. Written here because the stock backends (setuptools,
scikit-build-core) would have to come from PyPI into pip's isolated build
environment."""

import base64
import hashlib
import importlib.machinery
import os
import subprocess
import sysconfig
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NAME, VERSION = "linesim", "0.1.0"


def _native():
    build = os.path.join(ROOT, "build")
    if not os.path.exists(os.path.join(build, "CMakeCache.txt")):
        subprocess.run(["cmake", "-S", ROOT, "-B", build, "-G", "Ninja",
                        "-DCMAKE_BUILD_TYPE=Release"], check=True)
    subprocess.run(["cmake", "--build", build, "--target", "linesim_python",
                    "linesim_python_package"], check=True)
    folder = os.path.join(build, "python", NAME)
    suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
    modules = [f for f in os.listdir(folder) if f.startswith("_linesim") and f.endswith(suffix)]
    if not modules:
        raise RuntimeError("the native part was not built for this Python (%s) in %s"
                           % (suffix, folder))
    return os.path.join(folder, modules[0])


def _tag():
    # The module's ABI: this CPython's, on this platform.
    version = "cp%d%d" % tuple(map(int, sysconfig.get_python_version().split(".")))
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return "%s-%s-%s" % (version, version, platform)


def _metadata():
    return ("Metadata-Version: 2.1\nName: %s\nVersion: %s\n"
            "Summary: Co-simulation of mobile robots on moving-floor assembly lines\n"
            "Requires-Python: >=3.11\n" % (NAME, VERSION))


def get_requires_for_build_wheel(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    info = "%s-%s.dist-info" % (NAME, VERSION)
    os.makedirs(os.path.join(metadata_directory, info), exist_ok=True)
    with open(os.path.join(metadata_directory, info, "METADATA"), "w") as f:
        f.write(_metadata())
    return info


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    module = _native()
    tag = _tag()
    info = "%s-%s.dist-info" % (NAME, VERSION)
    files = {
        NAME + "/__init__.py": open(os.path.join(ROOT, NAME, "__init__.py"), "rb").read(),
        NAME + "/" + os.path.basename(module): open(module, "rb").read(),
        info + "/METADATA": _metadata().encode(),
        info + "/WHEEL": ("Wheel-Version: 1.0\nGenerator: linesim build_backend\n"
                          "Root-Is-Purelib: false\nTag: %s\n" % tag).encode(),
    }
    record = []
    for path, data in files.items():
        digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
        record.append("%s,sha256=%s,%d" % (path, digest, len(data)))
    record.append(info + "/RECORD,,")
    files[info + "/RECORD"] = ("\n".join(record) + "\n").encode()
    name = "%s-%s-%s.whl" % (NAME, VERSION, tag)
    with zipfile.ZipFile(os.path.join(wheel_directory, name), "w", zipfile.ZIP_DEFLATED) as z:
        for path, data in files.items():
            z.writestr(path, data)
    return name
