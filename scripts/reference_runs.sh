#!/usr/bin/env bash
# scripts/reference_runs.sh BINARY SRC OUTDIR: a fixed set of runs for checking that a change
# keeps behaviour bit for bit (record with the binary before the change, again after, then
# scripts/compare_run_dirs.py BEFORE AFTER SRC_BEFORE SRC_AFTER). SRC is the source tree whose
# configs/, worlds/ and models/ are used. Every shipped world explored to the end with seeds 1
# and 2, a tour-driver run, a replay, a rendered run and a divergence study; about 15 s.
set -euo pipefail
bin=$(realpath "$1"); src=$(realpath "$2"); out=$3
mkdir -p "$out"; out=$(realpath "$out")
cd "$src"
for w in room corridor_loop office pillars; do
  for s in 1 2; do
    "$bin" run --config configs/default.yaml --world worlds/$w.xml --seed $s --no-render --quiet --out "$out/$w-s$s" >/dev/null
  done
done
# the tour driver and the measured-free model path
"$bin" run --config configs/default.yaml --world worlds/office.xml --seed 3 --duration 30 --no-render --quiet \
   --set control.driver=tour --out "$out/office-tour-s3" >/dev/null
# replay of a recorded run
"$bin" replay --config "$out/room-s1/config.yaml" --scans "$out/room-s1/scans.csv" --out "$out/room-s1-replay" >/dev/null
# a rendered short run
"$bin" run --config configs/default.yaml --world worlds/room.xml --seed 4 --duration 12 --quiet --out "$out/room-render-s4" >/dev/null
# divergence of a run
"$bin" divergence "$out/corridor_loop-s1" --points 100 200 --realisations 10 >/dev/null
