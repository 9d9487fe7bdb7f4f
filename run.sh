#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job on the default world:
# writes runs/demo/. Extra arguments go to `mjslam run` (e.g. --duration 30).
set -euo pipefail
cd "$(dirname "$0")"
scripts/setup.sh
build/mjslam run --config configs/default.yaml --out runs/demo "$@"
