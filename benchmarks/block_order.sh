#!/usr/bin/env bash
# The blocks' order against the thread count: one UCS run (default: 90 deg on the 0.7 mm mesh, 27 558 blocks) in
# gmsh's order and along the Hilbert curve (mesh.block_order), at each thread count asked for, the two orders
# alternating, with the engine's stage times (docs/performance.md, "The order of the blocks").
#
#   benchmarks/block_order.sh [BUILD_DIR] [THREADS...]      # defaults: build, 2
#   REPETITIONS=3 BETA=90 MESH_SIZE=0.0007 benchmarks/block_order.sh build 2 8 16
#
# Prints one line per run (order, threads, wall s, steps, us per step, peak MPa, cracks) and the busy time per step
# of each phase (mean / busiest thread), then the median wall time per order and thread count. The mesh is made
# once per order before the timed runs (RBDEM_MESH_CACHE=on). Run it on an idle machine.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
threads=("$@")
[ ${#threads[@]} -gt 0 ] || threads=(2)
reps=${REPETITIONS:-3}
beta=${BETA:-90}
size=${MESH_SIZE:-0.0007}
rbdem="$build/bin/rbdem"
[ -x "$rbdem" ] || { echo "block_order: $rbdem not built (scripts/setup.sh build)" >&2; exit 2; }
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
export RBDEM_MESH_CACHE=on RBDEM_STAGE_TIMES=1

run() {  # order threads -> one line
  local order=$1 t=$2 t0 t1
  rm -rf "$work/out"
  t0=$(date +%s.%N)
  "$rbdem" ucs --beta "$beta" --set mesh.size="$size" --set numerics.threads="$t" --set mesh.block_order="$order" \
    -q --skip-elastic-gate -o "$work/out" > "$work/log" 2>&1 || { cat "$work/log" >&2; exit 1; }
  t1=$(date +%s.%N)
  python3 - "$order" "$t" "$t0" "$t1" "$work/out/summary.json" <<'PY'
import json, sys
order, threads, t0, t1, path = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), sys.argv[5]
s = json.load(open(path))
wall = t1 - t0
print(f"{order:8s} {threads:3d} threads {wall:8.2f} s {s['steps']:7d} steps {1e6 * wall / s['steps']:8.1f} us/step "
      f"peak {s['peak_stress_pa'] / 1e6:.2f} MPa {s['cracks']['total']} cracks")
PY
  grep "busy per step" "$work/log" | sed 's/^ucs: time: /         /' || true
}

for order in mesh hilbert; do  # the meshes into the cache, untimed
  "$rbdem" ucs --beta "$beta" --set mesh.size="$size" --set mesh.block_order="$order" --set loading.max_strain=1e-6 \
    -q --skip-elastic-gate -o "$work/warm" > /dev/null 2>&1 || true
done
for r in $(seq 1 "$reps"); do
  for t in "${threads[@]}"; do
    for order in mesh hilbert; do run "$order" "$t"; done
  done
done | tee "$work/lines"
python3 - "$work/lines" <<'PY'
import statistics, sys
walls = {}
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) > 4 and f[2] == "threads":
        walls.setdefault((f[0], int(f[1])), []).append(float(f[3]))
for (order, t), w in sorted(walls.items(), key=lambda kv: (kv[0][1], kv[0][0])):
    print(f"median {order:8s} {t:3d} threads {statistics.median(w):8.2f} s of {len(w)} runs")
PY
