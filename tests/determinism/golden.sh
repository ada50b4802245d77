#!/usr/bin/env bash
# golden.sh check|update LINESIM: the SHA-256 of signals.csv of a short run of
# every shipped scenario (cases.txt) against golden.sha256, or rewrite it.
# Update only when a change of the results is intended, and say why in the
# commit message (tools/update_golden_hashes.sh).
set -euo pipefail
mode=${1:?usage: golden.sh check|update LINESIM}
LINESIM=$(realpath "${2:?usage: golden.sh check|update LINESIM}")
source "$(dirname "$0")/run_cases.sh"
work=$(mktemp -d "${TMPDIR:-/tmp}/linesim-golden-XXXXXX")
trap 'rm -rf "$work"' EXIT
golden="$here/golden.sha256"
new="$work/golden.sha256"
failed=0

one() {
  local name=$1 scenario=$2 sets=$3 hash
  hash=$(run_case "$scenario" "$sets" "$work/$name") || { failed=1; return; }
  echo "$hash  $name" >>"$new"
}
for_each_case one
[ "$failed" -eq 0 ] || { echo "golden: a run failed" >&2; exit 1; }

if [ "$mode" = update ]; then
  cp "$new" "$golden"
  echo "golden: wrote $golden"
  exit 0
fi
if ! diff -u "$golden" "$new"; then
  echo "golden: signals.csv differs from tests/determinism/golden.sha256 (above: - expected, + got)." >&2
  echo "If the change of results is intended, run tools/update_golden_hashes.sh and say why in the commit." >&2
  exit 1
fi
echo "golden: $(wc -l <"$new") scenarios, signals.csv as pinned"
