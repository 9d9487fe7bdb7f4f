#!/usr/bin/env bash
# Prints the envelope's test table: one 25-run sweep of a config per
# condition (a systematic error or a random disturbance inside the envelope of
# docs/method.md, "The envelope", one at a time, and two office buildings
# generated for the test by sim/tools/generate_building.py with seeds no
# config was set on, rotated, with 0.8 and 0.9 m doors, 600 s each), on the
# test seeds (700-724), each row the pooled figures of the sweep's summary.json.
#   scripts/envelope_table.sh [CONFIG [OUT_DIR [RUNS [SEED]]]]
# Defaults: configs/default.yaml, /tmp/mjslam_envelope, 25, 700.
set -euo pipefail
cd "$(dirname "$0")/.."
config=${1:-configs/default.yaml}
out=${2:-/tmp/mjslam_envelope}
runs=${3:-25}
seed=${4:-700}
mkdir -p "$out/worlds"
python3 sim/tools/generate_building.py --out "$out/worlds/test_building_701.xml" --seed 701 \
  --size 22x14 --corridors 1 --cross-corridors 1 --door-width 0.8 --rotation-deg 17 \
  --columns 3 --pillars 3 --free-walls 2 > /dev/null
python3 sim/tools/generate_building.py --out "$out/worlds/test_building_702.xml" --seed 702 \
  --size 26x16 --corridors 2 --cross-corridors 1 --door-width 0.9 --rotation-deg -8 \
  --columns 4 --pillars 2 --free-walls 3 > /dev/null
conditions=(
  "nominal|"
  "pillars|run.world=worlds/pillars.xml"
  "room|run.world=worlds/room.xml"
  "range bias +15 mm|laser.range_bias_m=0.015 laser.range_bias_std_m=0"
  "range bias -15 mm|laser.range_bias_m=-0.015 laser.range_bias_std_m=0"
  "left wheel radius +1 %|odometry.left_wheel_radius_error_fraction=0.01"
  "right wheel radius -1 %|odometry.right_wheel_radius_error_fraction=-0.01"
  "axle track +1 %|odometry.axle_track_error_fraction=0.01"
  "axle track -1 %|odometry.axle_track_error_fraction=-0.01"
  "wheel disturbance 0.5 %|sim.drive_disturbance_std_fraction=0.005"
  "wheel disturbance 2 %|sim.drive_disturbance_std_fraction=0.02"
  "generated building 701 (22 x 14 m, 17 deg, 0.8 m doors)|run.world=$out/worlds/test_building_701.xml run.duration_s=600"
  "generated building 702 (26 x 16 m, -8 deg, 0.9 m doors)|run.world=$out/worlds/test_building_702.xml run.duration_s=600"
  "range scale +0.1 %|laser.range_scale_fraction=0.001"
)
printf '| condition | classical: ANEES inside / above, mean | 2-sigma x / y / th | worst run 2-sigma | selective: ANEES inside / above, mean | 2-sigma x / y / th | worst run 2-sigma | line observations: NIS mean, largest |\n'
printf '|---|---|---|---|---|---|---|---|\n'
i=0
for entry in "${conditions[@]}"; do
  name=${entry%%|*}
  sets=()
  for s in ${entry#*|}; do sets+=(--set "$s"); done
  dir="$out/cond_$i"
  build/mjslam sweep --runs "$runs" --config "$config" --set run.seed="$seed" \
    --set render.enabled=false "${sets[@]}" --out "$dir" > "$dir.log" 2>&1 || true
  /usr/bin/python3 scripts/envelope_row.py "$dir" "$name"
  i=$((i + 1))
done
