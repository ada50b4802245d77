#!/usr/bin/env bash
# Installs what is missing (tools/setup.sh), then configures and builds
# linesim in ./build (Release). Safe to run again: it only rebuilds what
# changed.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
# The tests and benchmarks explicitly: a build/ that `pip install .` configured
# has them off.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DLINESIM_BUILD_TESTS=ON -DLINESIM_BUILD_BENCH=ON
cmake --build build --parallel "$(nproc)"
