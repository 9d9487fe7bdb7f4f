#!/usr/bin/env bash
# Prints the envelope's test table: the campaign configs/campaigns/envelope.yaml
# (one 25-run sweep of a config per condition: a systematic error or a random
# disturbance inside the envelope of docs/method.md, "The envelope", one at a
# time, and two office buildings generated for the test, worlds/envelope/) on
# the test seeds (700-724), each row the pooled figures of the cell's
# summary.json (scripts/envelope_row.py).
#   scripts/envelope_table.sh [CONFIG [OUT_DIR [RUNS [SEED]]]]
set -euo pipefail
cd "$(dirname "$0")/.."
config=${1:-configs/default.yaml}
out=${2:-/tmp/mjslam_envelope}
runs=${3:-25}
seed=${4:-700}
mkdir -p "$out"
build/mjslam sweep --campaign configs/campaigns/envelope.yaml --config "$config" --runs "$runs" \
  --set run.seed="$seed" --set render.enabled=false --out "$out" > "$out/campaign.log" 2>&1 || true
printf '| condition | classical: ANEES inside / above, mean | 2-sigma x / y / th | worst run 2-sigma | selective: ANEES inside / above, mean | 2-sigma x / y / th | worst run 2-sigma | line observations: NIS mean, largest |\n'
printf '|---|---|---|---|---|---|---|---|\n'
# The cells in the campaign's order: campaign.csv's first column.
tail -n +2 "$out/campaign.csv" | cut -d, -f1 | while read -r cell; do
  /usr/bin/python3 scripts/envelope_row.py "$out/cells/$cell" "$cell"
done
