#!/usr/bin/env bash
# How much faster `mjslam sweep` is with 2 jobs than with 1, measured side by
# side in one command, with the figures that say where the rest goes.
#
#   scripts/sweep_speedup.sh [--program build/mjslam] [--runs 16] [--duration 60] [--trials 2]
#
# Each trial runs the same sweep (the corridor loop's tour, runs of DURATION
# simulated seconds, evaluated without divergence) with --jobs 1 and then
# --jobs 2, into fresh folders under a temporary directory. Printed per trial
# and summed over trials:
#   wall       elapsed seconds of the sweep command
#   cpu        CPU seconds (user + system) of the sweep and all its processes
#   cpu/run    cpu / runs: a run's cost; higher with 2 jobs = the two runs slow
#              each other down (shared cache, memory bandwidth, clock)
#   idle       core-seconds the jobs left unused: jobs * wall - cpu (waiting
#              for disk, starting processes, the serial aggregate at the end)
# then the speed-up wall(1) / wall(2), the speed-up the CPU cost alone allows
# (2 * cpu(1) / cpu(2)), the aggregate's own time (`mjslam sweep --aggregate`
# on the finished sweep; a serial part), the machine's own ceiling (one
# CPU-bound loop alone against two at once: what 2 cores give a program that
# shares nothing) and the load average before and after: a speed-up is only
# meaningful on a machine with nothing else running.
set -euo pipefail
cd "$(dirname "$0")/.."

program=build/mjslam
runs=16
duration=60
trials=2
while (($# > 0)); do
  case $1 in
    --program) program=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --duration) duration=$2; shift 2 ;;
    --trials) trials=$2; shift 2 ;;
    *) echo "sweep_speedup: unknown option '$1'" >&2; exit 2 ;;
  esac
done
[[ -x $program ]] || { echo "sweep_speedup: no program '$program' (build it first)" >&2; exit 2; }
work=$(mktemp -d /tmp/mjslam_speedup.XXXXXX)
trap 'rm -rf "$work"' EXIT

# One sweep; prints "wall cpu".
sweep() {
  local jobs=$1 out=$2
  local TIMEFORMAT='%R %U %S'
  { time "$program" sweep --config configs/default.yaml --runs "$runs" --jobs "$jobs" \
      --out "$out" --divergence-points 0 --quiet --set control.driver=tour \
      --set render.enabled=false --set run.duration_s="$duration" >/dev/null 2>"$out.log"; } 2>&1 |
    awk '{printf "%.3f %.3f\n", $1, $2 + $3}'
}

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg); $(nproc) cores; $program"
printf "%-6s %4s %9s %9s %9s %9s\n" trial jobs wall_s cpu_s cpu/run idle_s
declare -A wall cpu
for jobs in 1 2; do wall[$jobs]=0; cpu[$jobs]=0; done
for trial in $(seq "$trials"); do
  for jobs in 1 2; do
    read -r w c < <(sweep "$jobs" "$work/t${trial}_j$jobs")
    wall[$jobs]=$(awk -v a="${wall[$jobs]}" -v b="$w" 'BEGIN {print a + b}')
    cpu[$jobs]=$(awk -v a="${cpu[$jobs]}" -v b="$c" 'BEGIN {print a + b}')
    awk -v t="$trial" -v j="$jobs" -v w="$w" -v c="$c" -v r="$runs" \
      'BEGIN {printf "%-6s %4d %9.3f %9.3f %9.4f %9.3f\n", t, j, w, c, c / r, j * w - c}'
  done
done
TIMEFORMAT='%R'
aggregate_s=$( { time "$program" sweep --aggregate "$work/t1_j2" >/dev/null 2>&1 || true; } 2>&1)
# The machine: the same fixed CPU-bound work once alone, then twice at once.
loop() { awk 'BEGIN { for (i = 0; i < 4e7; i++) s += i * 0.5; print s > "/dev/null" }'; }
alone_s=$( { time loop; } 2>&1)
both_s=$( { time { loop & loop & wait; }; } 2>&1)
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
awk -v w1="${wall[1]}" -v w2="${wall[2]}" -v c1="${cpu[1]}" -v c2="${cpu[2]}" -v a="$aggregate_s" \
  -v n="$trials" -v alone="$alone_s" -v both="$both_s" 'BEGIN {
    printf "all trials: jobs 1 %.3f s (cpu %.3f), jobs 2 %.3f s (cpu %.3f)\n", w1, c1, w2, c2
    printf "speed-up of 2 jobs: %.3f (the CPU cost alone allows %.3f); idle with 2 jobs: %.3f core-s per trial\n",
           w1 / w2, 2 * c1 / c2, (2 * w2 - c2) / n
    printf "the aggregate alone (mjslam sweep --aggregate): %.3f s\n", a
    printf "the machine: a CPU-bound loop alone %.3f s, two at once %.3f s: ceiling %.3f\n",
           alone, both, 2 * alone / both
  }'
