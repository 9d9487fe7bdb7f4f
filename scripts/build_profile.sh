#!/usr/bin/env bash
# Where the build's time goes: a cold build (no ccache) of BUILD_DIR with
# every compile and link timed by scripts/timed_tool.sh, then the CPU seconds
# by kind of target, the most expensive targets and the most expensive
# objects. Extra arguments go to the CMake configure step.
# Usage: [JOBS=N] scripts/build_profile.sh [BUILD_DIR] [-DOPTION=VALUE ...]
#        (default build-profile; it is deleted and rebuilt)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-profile}
shift || true
rm -rf "$build"
log=$PWD/$build.times
: > "$log"
tool=$PWD/scripts/timed_tool.sh
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER_LAUNCHER="$tool" \
  -DCMAKE_CXX_LINKER_LAUNCHER="$tool" "$@" >/dev/null
export CCACHE_DISABLE=1 MJSLAM_BUILD_PROFILE_LOG=$log
start=$(date +%s.%N)
cmake --build "$build" -j"${JOBS:-$(nproc)}" >/dev/null
end=$(date +%s.%N)
echo "build_profile: $build built in $(echo "$end - $start" | bc) s of wall time (-j${JOBS:-$(nproc)}); per step: $log"
python3 - "$log" "$PWD/$build/" <<'PY'
import collections, sys
log, root = sys.argv[1], sys.argv[2]
rows = []
for line in open(log):
    user, system, wall, output = line.split(maxsplit=3)
    rows.append((float(user) + float(system), output.strip().replace(root, "")))
def kind(path):
    if path.endswith(".o"):
        top = path.split("/")[0]
        return ("compile", "tests" if top == "tests" else top if top in ("bench", "fuzz") else "libraries+app")
    return ("link", "tests" if path.startswith("tests/") else path.split("/")[0])
def target(path):
    for part in path.split("/"):
        if part.endswith(".dir"):
            return part[:-4]
    return path.split("/")[-1]
by_kind, by_target = collections.Counter(), collections.Counter()
for cpu, path in rows:
    by_kind[kind(path)] += cpu
    by_target[target(path)] += cpu
total = sum(cpu for cpu, _ in rows)
print(f"total {total:.0f} CPU-s in {len(rows)} steps")
for (step, what), cpu in sorted(by_kind.items(), key=lambda kv: -kv[1]):
    print(f"  {step:8s}{what:16s}{cpu:8.0f} CPU-s")
print("most expensive targets (compile + link):")
for name, cpu in by_target.most_common(15):
    print(f"  {cpu:7.1f}  {name}")
print("most expensive steps:")
for cpu, path in sorted(rows, reverse=True)[:15]:
    print(f"  {cpu:7.1f}  {path}")
PY
