#!/usr/bin/env bash
# Compiler and linker launcher of scripts/build_profile.sh: runs the command
# it is given and appends "user_s system_s wall_s output" to the file named by
# MJSLAM_BUILD_PROFILE_LOG (output: the argument after -o).
set -uo pipefail
output=unknown
previous=""
for arg in "$@"; do
  if [[ $previous == -o ]]; then output=$arg; fi
  previous=$arg
done
if [[ $output != /* ]]; then output=$PWD/$output; fi
times=$(mktemp)
/usr/bin/time -f "%U %S %e" -o "$times" "$@"
status=$?
echo "$(tail -1 "$times") $output" >> "${MJSLAM_BUILD_PROFILE_LOG:?MJSLAM_BUILD_PROFILE_LOG is not set}"
rm -f "$times"
exit $status
