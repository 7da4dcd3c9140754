#!/usr/bin/env bash
# Runs side by side: N copies of one default `rbdem ucs --beta 90` started together, each one's wall time, for
# N = 1, 2 and 3 (docs/performance.md, "Runs side by side and on many cores"). Each copy uses the default
# numerics.threads = 0 (all cores); its log says when its team shrank. About 1.5 minutes on 2 cores.
#
#   benchmarks/side_by_side.sh [BUILD_DIR] [TRIALS]     # defaults: build, 3
#   RBDEM_ADAPT_THREADS=0 benchmarks/side_by_side.sh    # the team kept at its size (the collapse: minutes)
#
# Prints one line per trial: the runs at once and each run's wall seconds. Run it on an otherwise idle machine.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
trials=${2:-3}
rbdem="$build/bin/rbdem"
[ -x "$rbdem" ] || { echo "side_by_side: $rbdem not built (scripts/setup.sh build)" >&2; exit 2; }
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$rbdem" ucs --beta 90 -q --out "$work/warm" > /dev/null  # the mesh and the elastic gate into the cache
for n in 1 2 3; do
  for t in $(seq 1 "$trials"); do
    for i in $(seq 1 "$n"); do
      ( s=$(date +%s.%N); "$rbdem" ucs --beta 90 -q --out "$work/r$i" > "$work/log$i" 2>&1
        e=$(date +%s.%N); awk -v a="$s" -v b="$e" 'BEGIN { printf "%.2f\n", b - a }' > "$work/t$i" ) &
    done
    wait
    echo "$n at once: $(cat "$work"/t[1-$n] | tr '\n' ' ')s"
  done
done
