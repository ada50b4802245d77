#!/usr/bin/env bash
# The GoogleTest suite under AddressSanitizer + UndefinedBehaviorSanitizer
# (and LeakSanitizer): builds ./build-asan (tools/sanitizer_build.sh: clang,
# -O1 -g -fno-omit-frame-pointer, -fsanitize=address,undefined
# -fno-sanitize-recover=undefined) and runs ctest in it. Any report fails the
# test it happens in. tools/sanitizers/lsan.supp suppresses only the one known
# leak it documents.
#   bash tools/sanitize.sh                  the suite less the tests labelled `slow`
#   LINESIM_SANITIZE_ALL=1 bash tools/sanitize.sh   every test
#   bash tools/sanitize.sh -R test_loader   extra arguments go to ctest
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
source tools/sanitizer_build.sh
selection=(-LE slow)
[ "${LINESIM_SANITIZE_ALL:-0}" = 1 ] && selection=()
ctest --test-dir build-asan --output-on-failure -j"$(nproc)" "${selection[@]}" "$@"
