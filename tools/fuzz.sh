#!/usr/bin/env bash
# Builds the libFuzzer harnesses of fuzz/ (in ./build-asan, the sanitizer
# build: tools/sanitizer_build.sh) and runs each for SECONDS (default 60)
# from a corpus seeded with the shipped files:
#   fuzz_scenario           scenarios/*.yaml (and variants with --set lines)
#   fuzz_robot_scenario     the fleet and worker scenarios (and variants with
#                           --set lines), loaded and run for 0.1 s
#   fuzz_description        models/robots/*.yaml, models/scenes/*.yaml
#   fuzz_sweep_file         scenarios/sweeps/*.yaml
#   fuzz_results_file       a results.csv of scenarios/sweeps/master_step.yaml
#   fuzz_model_description  tests/units/fmu/fmus/*.xml
#   fuzz_fmu_loader         the test FMUs (build-asan/tests/units/fmu/*.fmu,
#                           when the sanitizer build made them)
#   fuzz_replay_data        replay.html's data of 0.2 s runs of cross_line,
#                           fleet_line and worker_crossing
#     bash tools/fuzz.sh [SECONDS] [HARNESS ...]
# The corpora grow in build-asan/fuzz/corpus/HARNESS; an input that crashes,
# leaks, runs over 30 s, allocates over 2 GB at once or trips a sanitizer is saved as
# build-asan/fuzz/findings/HARNESS-crash-... and fails the script (after every
# harness ran). Reproduce one: build-asan/fuzz/HARNESS FILE.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
harnesses=("$@")
[ ${#harnesses[@]} -gt 0 ] || harnesses=(fuzz_scenario fuzz_robot_scenario fuzz_description
                                         fuzz_sweep_file
                                         fuzz_results_file fuzz_model_description
                                         fuzz_fmu_loader fuzz_replay_data)
bash tools/setup.sh
source tools/sanitizer_build.sh "${harnesses[@]}"

out=build-asan/fuzz
mkdir -p "$out/findings"
wanted() { [[ " ${harnesses[*]} " == *" $1 "* ]]; }
seed() {  # seed HARNESS FILE...: copies the shipped files into its corpus
  local h=$1; shift
  mkdir -p "$out/corpus/$h"
  for f in "$@"; do cp -n "$f" "$out/corpus/$h/$(basename "$f")"; done
}
seed fuzz_scenario scenarios/*.yaml
# --set lines ("#set PATH=VALUE") on the main scenario and a system-level one.
{ cat scenarios/cross_line.yaml
  printf '#set master.step_s=0.002\n#set task.waypoints.1.1=-2.0\n#set robot.model=husky\n'
} > "$out/corpus/fuzz_scenario/cross_line_set.yaml"
{ cat scenarios/motor_step.yaml
  printf '#set units.motors.parameters.gear_ratio.0=15\n#set duration_s=1\n'
} > "$out/corpus/fuzz_scenario/motor_step_set.yaml"
seed fuzz_robot_scenario scenarios/worker_crossing.yaml scenarios/fleet_line.yaml
# The safety function's times, the workers' starts and the field shapes.
{ cat scenarios/worker_crossing.yaml
  printf '#set safety.parameters.restart_delay=0.5\n#set workers.0.start_time_s=0\n'
} > "$out/corpus/fuzz_robot_scenario/worker_crossing_set.yaml"
{ cat scenarios/fleet_line.yaml
  printf '#set robots.0.safety.parameters.restart_delay=1\n#set workers.1.pause_s=0\n'
} > "$out/corpus/fuzz_robot_scenario/fleet_line_set.yaml"
seed fuzz_description models/robots/*.yaml models/scenes/*.yaml
seed fuzz_sweep_file scenarios/sweeps/*.yaml
mkdir -p "$out/corpus/fuzz_results_file"
if wanted fuzz_results_file; then  # a harness is built only when asked for
  LINESIM_FUZZ_SEED_DIR="$out/corpus/fuzz_results_file" build-asan/fuzz/fuzz_results_file
fi
seed fuzz_model_description tests/units/fmu/fmus/*.xml
mkdir -p "$out/corpus/fuzz_fmu_loader"
for f in build-asan/tests/units/fmu/*.fmu; do
  [ -e "$f" ] && seed fuzz_fmu_loader "$f"
done

mkdir -p "$out/corpus/fuzz_replay_data"
if wanted fuzz_replay_data; then  # real runs' page data (a few seconds)
  LINESIM_FUZZ_SEED_DIR="$out/corpus/fuzz_replay_data" build-asan/fuzz/fuzz_replay_data
fi

status=0
for h in "${harnesses[@]}"; do
  echo "== $h: ${seconds} s"
  log="$out/$h.log"
  start=$(date +%s)
  # -rss_limit_mb=0: libFuzzer's RSS-limit handler prints an ASan heap
  # profile first, which took over 15 minutes on a 2 GB heap without saving
  # the input; a runaway input is caught by -timeout (saved as timeout-...),
  # one huge allocation by -malloc_limit_mb.
  # A harness's dictionary of keys and values, when it has one.
  dict=()
  [ -f "fuzz/$h.dict" ] && dict=(-dict="fuzz/$h.dict")
  if build-asan/fuzz/"$h" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=0 \
       -malloc_limit_mb=2048 "${dict[@]}" \
       -print_final_stats=1 -artifact_prefix="$out/findings/$h-" \
       "$out/corpus/$h" > "$log" 2>&1; then
    result=clean
  else
    result=FINDING
    status=1
    tail -60 "$log"
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)
  echo "$h: $result, $runs executions in $(( $(date +%s) - start )) s, $cov, corpus $(ls "$out/corpus/$h" | wc -l) files"
done
exit $status
