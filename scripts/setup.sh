#!/usr/bin/env bash
# rbdem set-up: installs every Debian package the project needs, configures Release, builds, then
#   scripts/setup.sh run     builds the rbdem command only and runs the main job (the default study)
#   scripts/setup.sh test    builds everything (library, command, tests, benchmarks) and runs the test suite
#                            (CTest) and the find_package(rbdem) consumer check
#   scripts/setup.sh build   only installs and builds everything
# clang, libclang-rt-14-dev and libomp-dev are for the fuzz targets (tests/fuzz/run.sh, run by .ci/run);
# pybind11-dev and python3-pytest for the Python module and its tests (docs/python.md).
# Idempotent: packages already present are not reinstalled; the build is incremental.
# Works as root or through sudo. Environment: BUILD_DIR (default build), JOBS (default: all cores).
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-build}
case "$mode" in run|test|build) ;; *) echo "usage: scripts/setup.sh [run|test|build]" >&2; exit 2;; esac

packages=(
  build-essential cmake pkg-config git
  libdeal.ii-dev libeigen3-dev libgmsh-dev libsundials-dev libhdf5-dev libhdf5-openmpi-dev libopenmpi-dev
  libsuitesparse-dev libopenblas0-openmp
  libtomlplusplus-dev libcli11-dev libfmt-dev nlohmann-json3-dev zlib1g-dev
  libgtest-dev libbenchmark-dev
  python3 python3-matplotlib python3-h5py python3-numpy
  pybind11-dev python3-pytest
  openmpi-bin
  clang libclang-rt-14-dev libomp-dev
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
  echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
  "${sudo[@]}" apt-get update
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
fi

build=${BUILD_DIR:-build}
jobs=${JOBS:-$(nproc)}
# Configure once; a rerun only rebuilds what changed (CMake skips the configure step when nothing it reads changed).
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release
fi
if [ "$mode" = run ]; then
  cmake --build "$build" -j "$jobs" --target rbdem  # the main job needs the command line only
else
  cmake --build "$build" -j "$jobs"
fi

case "$mode" in
  run)
    exec "$build/bin/rbdem" ;;
  test)
    ctest --test-dir "$build" --output-on-failure -j "$jobs"
    tools/check-consumer.sh "$build" ;;
esac
