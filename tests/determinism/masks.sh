#!/usr/bin/env bash
# masks.sh LINESIM: the closed-loop cases of cases.txt (last column yes) under
# every CPU-feature mask this machine can present, each of which must give
# the bytes of the unmasked run: glibc's hwcaps masks (what its libm and
# string functions dispatch on; glibc.cpu.hwcaps) and Embree's kernels capped
# at each instruction set the CPU has (LINESIM_EMBREE_MAX_ISA). A machine of
# another class runs exactly one of these combinations.
set -euo pipefail
LINESIM=$(realpath "${1:?usage: masks.sh LINESIM}")
source "$(dirname "$0")/run_cases.sh"
work=$(mktemp -d "${TMPDIR:-/tmp}/linesim-masks-XXXXXX")
trap 'rm -rf "$work"' EXIT

has() { grep -qw "$1" /proc/cpuinfo; }
masks=("")
has avx512f && masks+=("GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX512F,-AVX512DQ,-AVX512BW,-AVX512VL")
has fma && masks+=("GLIBC_TUNABLES=glibc.cpu.hwcaps=-FMA,-FMA4")
has avx2 && masks+=("GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA,-FMA4,-AVX512F")
has avx && masks+=("GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX,-AVX2,-FMA,-FMA4,-AVX512F")
masks+=("LINESIM_EMBREE_MAX_ISA=sse2")
has sse4_2 && masks+=("LINESIM_EMBREE_MAX_ISA=sse4.2")
has avx && masks+=("LINESIM_EMBREE_MAX_ISA=avx")
has avx2 && masks+=("LINESIM_EMBREE_MAX_ISA=avx2")
has avx512f && masks+=("LINESIM_EMBREE_MAX_ISA=avx512")
has avx2 && masks+=("GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA,-FMA4,-AVX512F LINESIM_EMBREE_MAX_ISA=sse2")

failed=0
one() {
  local name=$1 scenario=$2 sets=$3 masked=$4 reference hash mask i=0
  [ "$masked" = yes ] || return 0
  for mask in "${masks[@]}"; do
    i=$((i + 1))
    hash=$(env $mask bash -c "$(declare -f run_case); root='$root'; LINESIM='$LINESIM'; run_case '$scenario' '$sets' '$work/$name-$i'") ||
      { failed=1; continue; }
    if [ -z "$mask" ]; then
      reference=$hash
      echo "masks: $name: $hash (no mask)"
    elif [ "$hash" != "$reference" ]; then
      echo "masks: $name: $hash under $mask: DIFFERS from the unmasked $reference" >&2
      failed=1
    else
      echo "masks: $name: same bytes under $mask"
    fi
  done
}
for_each_case one
[ "$failed" -eq 0 ] || { echo "masks: results depend on the CPU's features" >&2; exit 1; }
echo "masks: ${#masks[@]} feature sets, the same bytes"
