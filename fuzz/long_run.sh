#!/usr/bin/env bash
# The long libFuzzer run (fuzz/README.md): each target of BUILD_DIR (built
# with -DMJSLAM_FUZZ=ON) in turn for SECONDS, at nice 10, from a copy of its
# seed corpus in WORK_DIR/TARGET/; findings (crash-*, leak-*, timeout-*,
# oom-*) land in WORK_DIR/findings/. Prints each target's last status line
# and libFuzzer's summary. Exit status 1 when any target found something.
# Usage: fuzz/long_run.sh BUILD_DIR [SECONDS] [WORK_DIR] [TARGET ...]
#        (default 300 s, /tmp/mjslam-fuzz, all five targets)
set -euo pipefail
cd "$(dirname "$0")/.."
build=$1
seconds=${2:-300}
work=${3:-/tmp/mjslam-fuzz}
shift $(($# < 3 ? $# : 3))
targets=("$@")
if ((${#targets[@]} == 0)); then targets=(config trajectory scans map explorer); fi
mkdir -p "$work/findings"
found=0
for target in "${targets[@]}"; do
  mkdir -p "$work/$target"
  cp -n fuzz/corpus/"$target"/* "$work/$target/"
  log=$work/$target.log
  # -timeout: seconds per input before it counts as a hang (generous: the
  # machine may be shared); -rss_limit_mb: memory before it counts as a leak.
  status=0
  nice -n 10 "$build/fuzz/fuzz_$target" -max_total_time="$seconds" -timeout=20 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$work/findings/$target-" \
    "$work/$target" >"$log" 2>&1 || status=$?
  echo "fuzz_$target (exit $status): $(grep -E '^#[0-9]+' "$log" | tail -1)"
  grep -E '^stat::(number_of_executed_units|peak_rss_mb|new_units_added)' "$log" | tr '\n' ' '
  echo
  if ((status != 0)); then found=1; grep -E 'ERROR|SUMMARY|Test unit written' "$log" | head -5; fi
done
ls "$work/findings"
exit $found
