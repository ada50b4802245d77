#!/usr/bin/env bash
# Installs the Debian packages linesim needs. Idempotent: when every package
# is already installed it touches nothing (no apt-get update either).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libode-dev libeigen3-dev libsundials-dev libfcl-dev libembree-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libtbb-dev
  libopenmpi-dev openmpi-bin gnuplot-nox
  libzip-dev libpugixml-dev
  # SLEEF: the CPU-independent transcendental functions of every linesim
  # executable (platform/deterministic_math.cc); OpenSSL's libcrypto: SHA-256
  # for provenance and the golden hashes.
  libsleef-dev libssl-dev
  # clang and its runtimes (libFuzzer, ASan, UBSan; libclang-rt-14-dev is only
  # recommended by clang): the sanitizer and fuzz build (tools/sanitize.sh).
  clang libclang-rt-14-dev
  # Headless Chromium: the browser test of replay.html (tests/replay) loads
  # the page from file:// and drives it over the DevTools protocol.
  chromium
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

echo "setup: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
