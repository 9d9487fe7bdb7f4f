#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite with ctest,
# the sanitizer build included (ctest test `sanitize`, docs/testing.md).
# Extra arguments go to ctest (e.g. -L unit; -LE sanitize leaves out the
# sanitizer build).
set -euo pipefail
cd "$(dirname "$0")"
scripts/setup.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
