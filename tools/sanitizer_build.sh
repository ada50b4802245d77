#!/usr/bin/env bash
# Configures and builds ./build-asan: clang, Debug at -O1 with line tables
# (all a sanitizer's stack trace needs; full -g compiles slower) and frame
# pointers, AddressSanitizer + UndefinedBehaviorSanitizer on every target
# (undefined behaviour aborts), and the libFuzzer harnesses (fuzz/). Sourced
# by tools/sanitize.sh and tools/fuzz.sh, from the repository root, after
# tools/setup.sh. Arguments: the targets to build (none: all).
# Warnings are not errors here (clang's set differs from GCC's; the normal
# build enforces them).
root=$(pwd)
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:check_initialization_order=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=${root}/tools/sanitizers/lsan.supp:print_suppressions=0"
cmake -S . -B build-asan -G Ninja \
  -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS_DEBUG="-O1 -gline-tables-only" \
  -DLINESIM_SANITIZE=address,undefined \
  -DLINESIM_FUZZ=ON \
  -DLINESIM_WERROR=OFF \
  -DLINESIM_BUILD_BENCH=OFF
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build build-asan --parallel "$(nproc)" "${targets[@]}"
