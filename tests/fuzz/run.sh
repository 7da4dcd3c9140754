#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) in build-fuzz/ and runs each for a fixed time from its
# seed corpus. Fails on any crash, sanitizer report, leak or timeout; the reproducer is left in build-fuzz/artifacts/.
#
#   tests/fuzz/run.sh                 # 60 s per target
#   FUZZ_SECONDS=600 tests/fuzz/run.sh
#   build-fuzz/tests/fuzz/fuzz_scene build-fuzz/artifacts/crash-...   # replay one input
#
# Environment: FUZZ_SECONDS (default 60), BUILD_DIR (default build-fuzz), JOBS (default 2).
# New inputs found go to build-fuzz/corpus_*/ (the seeds in tests/fuzz/corpus_*/ are not modified).
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${FUZZ_SECONDS:-60}
build=${BUILD_DIR:-build-fuzz}
jobs=${JOBS:-2}
flags="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g -O1"
mkdir -p "$build"
CXX=${FUZZ_CXX:-clang++} cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRBDEM_FUZZ=ON \
  -DRBDEM_WITH_DEALII=OFF -DRBDEM_BUILD_TESTS=OFF -DRBDEM_BUILD_BENCHMARKS=OFF \
  -DCMAKE_CXX_FLAGS="$flags" >"$build/configure.log" 2>&1 || { cat "$build/configure.log"; exit 1; }
cmake --build "$build" -j "$jobs" --target fuzz_scene fuzz_msh fuzz_mesh_checks fuzz_contact3

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
# gmsh and OpenCASCADE leak their globals (tests/lsan.supp); our own leaks still fail.
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/lsan.supp:print_suppressions=0}
mkdir -p "$build/artifacts"
status=0
summary=()
for target in fuzz_scene fuzz_msh fuzz_mesh_checks fuzz_contact3; do
  seeds=tests/fuzz/corpus_${target#fuzz_}
  work="$build/corpus_${target#fuzz_}"
  mkdir -p "$work"
  log="$build/$target.log"
  echo "fuzz: $target for ${seconds} s (seeds $seeds, log $log)"
  # -rss_limit_mb / -malloc_limit_mb: a single input may not allocate more than 1 GB (a garbage node count).
  if ! "$build/tests/fuzz/$target" "$work" "$seeds" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
      -malloc_limit_mb=1024 -max_len=8192 -print_final_stats=1 -artifact_prefix="$build/artifacts/$target-" \
      >"$log" 2>&1; then
    echo "fuzz: $target FAILED; the end of its log:"
    tail -n 60 "$log"
    status=1
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  summary+=("$target: $runs executions in ${seconds} s")
done
printf 'fuzz: %s\n' "${summary[@]}"
exit $status
