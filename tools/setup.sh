#!/usr/bin/env bash
# Installs the Debian packages linesim needs. Idempotent: when every package
# is already installed it touches nothing (no apt-get update either).
#   bash tools/setup.sh             install what is missing (and the MCAP test's npm reader)
#   bash tools/setup.sh --missing   print the missing packages that building linesim and
#                                   its Python package needs (python/build_backend.py asks
#                                   before compiling); install nothing
set -euo pipefail

# What building linesim, its command line and its Python package needs
# (CMake finds each of them when configuring).
build_packages=(
  build-essential cmake ninja-build pkg-config git
  libode-dev libeigen3-dev libsundials-dev libfcl-dev libembree-dev
  libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libtbb-dev
  libopenmpi-dev openmpi-bin gnuplot-nox
  libzip-dev libpugixml-dev
  # SLEEF: the CPU-independent transcendental functions of every linesim
  # executable (platform/deterministic_math.cc); OpenSSL's libcrypto: SHA-256
  # for provenance and the golden hashes.
  libsleef-dev libssl-dev
  # lz4 and zstd: the compression of run.mcap's chunks, zlib its CRC-32
  # (mcap/writer.cc).
  liblz4-dev libzstd-dev zlib1g-dev
  # The Python package (python/): pybind11 for its native part, built for
  # Debian's python3 (python3-dev), numpy for the signals.
  python3-dev pybind11-dev python3-numpy
)
# What the tests, benchmarks and checks need besides.
test_packages=(
  libgtest-dev libgmock-dev libbenchmark-dev
  # clang and its runtimes (libFuzzer, ASan, UBSan; libclang-rt-14-dev is only
  # recommended by clang): the sanitizer and fuzz build (tools/sanitize.sh).
  clang libclang-rt-14-dev
  # Headless Chromium: the browser test of replay.html (tests/replay) loads
  # the page from file:// and drives it over the DevTools protocol.
  chromium
  # Node.js: the independent MCAP reader of the run.mcap test
  # (tests/mcap/check_mcap.mjs).
  nodejs
  # pytest: the Python package's tests (tests/python); mypy: its type hints
  # checked with --strict on the package and the examples (python.mypy), so
  # that the types users' own checkers read stay true.
  python3-pytest mypy
)

missing_of() {
  for p in "$@"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
      echo "$p"
    fi
  done
}

if [ "${1:-}" = "--missing" ]; then
  missing_of "${build_packages[@]}"
  exit 0
fi

packages=("${build_packages[@]}" "${test_packages[@]}")
mapfile -t missing < <(missing_of "${packages[@]}")

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
else
  echo "setup: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The MCAP reader the run.mcap test uses (@mcap/core and fzstd from the npm
# registry, the versions of tests/mcap/package-lock.json), into
# tests/mcap/node_modules; nothing when it is there already.
mcap_check="$(cd "$(dirname "$0")/.." && pwd)/tests/mcap"
if [ ! -f "$mcap_check/node_modules/@mcap/core/package.json" ] ||
   [ ! -f "$mcap_check/node_modules/fzstd/package.json" ] ||
   [ ! -f "$mcap_check/node_modules/lz4js/package.json" ]; then
  echo "setup: installing the MCAP reader into $mcap_check/node_modules"
  (cd "$mcap_check" && npm ci --ignore-scripts --no-audit --no-fund)
fi
