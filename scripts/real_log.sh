#!/bin/bash
# One real CARMEN log end to end (docs/real_data.md): import it into a run
# directory and run both filters on it (mjslam import), score it (mjslam
# evaluate: the relation metric of Kuemmerle et al. 2009, and against the
# log's reference trajectory), and draw it (mjslam render: final.png,
# video.mp4). Prints the CPU time of the import and of a replay of it.
#
# Usage: scripts/real_log.sh LOG OUT_DIR [RELATIONS] [mjslam import options...]
#   e.g. scripts/real_log.sh ../shared/data/real/intel-corrected.log.gz runs/intel \
#            ../shared/data/real/intel.relations.txt
set -euo pipefail
if [ $# -lt 2 ]; then
  sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
root=$(cd "$(dirname "$0")/.." && pwd)
mjslam="$root/build/mjslam"
log=$1
out=$2
shift 2
relations=()
if [ $# -gt 0 ] && [ "${1#-}" = "$1" ]; then
  relations=(--relations "$1")
  shift
fi
TIMEFORMAT='  cpu: %U s user + %S s system, %R s wall'
echo "import (parse the log, both filters over every record):"
time "$mjslam" import "$log" --out "$out" "${relations[@]}" "$@"
echo "replay of the imported run (both filters only):"
rm -rf "$out/replay"
time "$mjslam" replay --scans "$out/scans.csv" --out "$out/replay" --config "$out/config.yaml" 2>/dev/null
"$mjslam" evaluate "$out"
"$mjslam" render "$out"
