# Sourced by golden.sh and masks.sh: run_case NAME OUT runs one line of
# cases.txt with $LINESIM into folder OUT; for_each_case CALLBACK calls
# CALLBACK NAME SCENARIO SETS MASKED for each line.
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)

trim() { local s="$1"; s="${s#"${s%%[![:space:]]*}"}"; printf '%s' "${s%"${s##*[![:space:]]}"}"; }

for_each_case() {
  local callback=$1 line name scenario sets masked
  while IFS= read -r line; do
    [[ -z "$line" || "$line" == \#* ]] && continue
    IFS='|' read -r name scenario sets masked <<<"$line"
    "$callback" "$(trim "$name")" "$(trim "$scenario")" "$(trim "$sets")" "$(trim "$masked")"
  done <"$here/cases.txt"
}

# run_case SCENARIO SETS OUT: the run's signals.csv SHA-256 on stdout.
run_case() {
  local scenario=$1 sets=$2 out=$3 args=() s
  for s in $sets; do args+=(--set "$s"); done
  rm -rf "$out"
  if ! (cd "$root" && "$LINESIM" run "$scenario" --out "$out" "${args[@]}" >"$out.log" 2>&1); then
    echo "run failed: $scenario $sets (log: $out.log)" >&2
    return 1
  fi
  sha256sum "$out/signals.csv" | cut -d' ' -f1
}
