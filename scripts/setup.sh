#!/usr/bin/env bash
# Installs the Debian 12 packages mjslam needs (only those missing), then
# configures and builds it in build/. Idempotent: fast when all is in place.
# Used by ./run.sh and ./test.sh; run as root or with sudo available.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  cmake g++ make git pkg-config
  libmujoco-dev        # MuJoCo 2.2.2: physics and ray casting
  libeigen3-dev        # Eigen 3.4: the filters' linear algebra
  libosmesa6-dev       # OSMesa: off-screen rendering
  libyaml-cpp-dev      # yaml-cpp: run configs
  libcli11-dev         # CLI11: the command line
  nlohmann-json3-dev   # nlohmann-json: manifests and summaries
  libgtest-dev         # GoogleTest: the test suite
  libbenchmark-dev     # Google Benchmark: bench/
  libpng-dev           # libpng: final.png of the renders
  ffmpeg               # ffmpeg/ffprobe: video.mp4 of the renders (H.264), its test
  python3-matplotlib   # matplotlib: the plots of runs and sweeps (renders/report.py)
  python3-yaml         # PyYAML: run directories' config.yaml (python/mjslam, the scripts)
  python3-numpy        # numpy: the columns of run files in Python (python/mjslam, the scripts)
  python3-pytest       # pytest: the tests of the Python package (tests/python)
  python3-dev pybind11-dev python3-pybind11  # pybind11: the module mjslam._mjslam (python/bindings.cc)
  chromium             # headless Chromium: the test that index.html loads
  slurm-wlm munge      # Slurm: the one-node cluster of the sweep's Slurm test (scripts/slurm_localhost.sh)
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if ((${#missing[@]} > 0)); then
  echo "setup: installing ${missing[*]}"
  sudo=()
  if [[ $(id -u) -ne 0 ]]; then sudo=(sudo); fi
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if [[ ! -f build/CMakeCache.txt ]]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
fi
cmake --build build -j"$(nproc)"
