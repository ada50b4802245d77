#!/usr/bin/env bash
# Rewrites tests/determinism/golden.sha256 from the current build: only when a
# change of the results is intended (a physics, sensor or estimator change);
# the commit that changes it says why.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
bash tests/determinism/golden.sh update build/app/linesim
git --no-pager diff --stat -- tests/determinism/golden.sha256 || true
