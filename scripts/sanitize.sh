#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer (with float-cast-overflow)
# check: builds the unit tests of the readers, numerics and renderer, and the
# program, in BUILD_DIR (-O1, MJSLAM_SANITIZE=ON; ccache when installed), then
# runs those tests and a short run, replay, evaluate and render under the
# sanitizers. Any report fails (halt_on_error, no recovery). The test suite
# runs it as the ctest test `sanitize` (label sanitize) in build/sanitize/;
# docs/reliability.md#sanitizers. Prints the build's and the runs' times.
# Usage: scripts/sanitize.sh [BUILD_DIR]   (default build-asan)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-asan}
tests=(common_params_test common_grid2_test common_segments_test config_test
       config_round_trip_test rundir_csv_test rundir_map_csv_test rundir_rows_test
       rundir_layout_test eval_ground_truth_test eval_metrics_test eval_map_divergence_test
       slam_ekf_slam_test slam_feature_extraction_test sim_scene_test
       renders_scene_renderer_test fuzz_mutation_test)

launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" \
  -DMJSLAM_SANITIZE=ON "${launcher[@]}" >/dev/null
TIMEFORMAT="sanitize: build %0R s (CPU %0U s user, %0S s system)"
time cmake --build "$build" -j"$(nproc)" --target mjslam "${tests[@]}" >"$build/sanitize_build.log" ||
  { tail -60 "$build/sanitize_build.log"; exit 1; }

export ASAN_OPTIONS=halt_on_error=1:detect_leaks=1:abort_on_error=0
# Leaks inside Debian's libraries (OSMesa), each documented in the file.
export LSAN_OPTIONS=suppressions=$PWD/scripts/lsan.supp:print_suppressions=0
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
SECONDS=0
# The unit tests above, by executable (ctest would list the ones not built).
for test in "${tests[@]}"; do
  path=$(find "$build/tests" -name "$test" -type f -executable | head -1)
  (cd "$(dirname "$path")" && "./$test" --gtest_brief=1 >"$test.log" 2>&1) ||
    { echo "sanitize: $test FAILED"; tail -60 "$(dirname "$path")/$test.log"; exit 1; }
done

# A short closed-loop run, its replay, evaluation and render (no video).
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
program="$build/mjslam"
"$program" run --duration 8 --quiet --no-render --out "$out/run"
"$program" replay --scans "$out/run/scans.csv" --out "$out/replay" >/dev/null
"$program" evaluate "$out/run" --divergence-points 200 >/dev/null
"$program" render "$out/run" --no-video --no-plots --quiet
echo "sanitize: ${#tests[@]} test programs and 4 commands clean in ${SECONDS} s"
