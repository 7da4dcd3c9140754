#!/usr/bin/env bash
# Growth with size in 3D: the cost of one UCS run of the 3D cylinder (scenes/cylinder.toml) at several mesh sizes,
# with the exponents of power-law fits of the wall time and the step count against the number of blocks.
#
#   benchmarks/size_study3.sh [BUILD_DIR] [OUT_DIR] [BETA] [SIZES_MM...]
#       # defaults: build, runs/benchmarks, 60, 8 6 5 4
#
# BETA = 60 (slip on the joints) takes a few minutes for the four default sizes; BETA = 90 (splitting along the
# layers) longer. Each run skips the elastic gate and uses the scene's default threads; the 3D mesh is made by
# gmsh in every run (the mesh cache is off; its time is in "wall", not in "run"). Writes OUT_DIR/size_study3_beta<BETA>.json and prints
# the table. The load average (uptime) at the start of each run is recorded beside it: run it on an idle machine.
#
# Columns: wall = the whole command (meshing, static start, explicit run, output); run = summary.json's
# wall_seconds; rss = the peak resident memory (GNU time); ns per bond-step = run / (steps x bonds), serial parts
# included.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
out=${2:-runs/benchmarks}
beta=${3:-60}
shift $(( $# < 3 ? $# : 3 ))
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(8 6 5 4)
rbdem="$build/bin/rbdem"
[ -x "$rbdem" ] || { echo "size_study3: $rbdem not built (scripts/setup.sh build)" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "size_study3: needs GNU time (/usr/bin/time; Debian package 'time')" >&2; exit 2; }
mkdir -p "$out"
export RBDEM_MESH_CACHE=off
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
records="$work/records.txt"
: > "$records"

for mm in "${sizes[@]}"; do
  size=$(python3 -c "print($mm / 1000)")
  load=$(cut -d' ' -f1 /proc/loadavg)
  rm -rf "$work/out"
  /usr/bin/time -f "%e %M" -o "$work/time.txt" \
    "$rbdem" ucs scenes/cylinder.toml -q --beta "$beta" --skip-elastic-gate --set mesh.size="$size" \
    -o "$work/out" > "$work/log.txt" 2>&1 ||
    { echo "size_study3: $mm mm failed:" >&2; cat "$work/log.txt" >&2; exit 1; }
  python3 - "$mm mm" "$work/time.txt" "$work/out/summary.json" "$load" >> "$records" <<'PY'
import json, sys
label, timing, summary, load = sys.argv[1:5]
wall, rss_kb = open(timing).read().split()[-2:]
s = json.load(open(summary))
print(json.dumps({"label": label, "wall_s": float(wall), "rss_bytes": int(rss_kb) * 1024,
                  "run_wall_s": s["wall_seconds"], "steps": s["steps"], "blocks": s["blocks"],
                  "bonds": s["bonds"], "peak_pa": s["peak_stress_pa"], "threads": s["threads"],
                  "load_average": float(load)}))
PY
  echo "size_study3: $mm mm done (load average $load at the start)"
done

python3 - "$records" "$out/size_study3_beta${beta}.json" "$beta" <<'PY'
import json, math, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
beta = sys.argv[3]
def slope(xs, ys):
    lx = [math.log(x) for x in xs]; ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)
blocks = [r["blocks"] for r in rows]
fits = {}
if len(rows) >= 2:
    fits = {"exponent_wall": slope(blocks, [r["wall_s"] for r in rows]),
            "exponent_run": slope(blocks, [r["run_wall_s"] for r in rows]),
            "exponent_steps": slope(blocks, [r["steps"] for r in rows])}
print(f"3D size study, beta = {beta} deg")
print(f"{'run':8s} {'blocks':>7s} {'bonds':>7s} {'steps':>7s} {'wall s':>8s} {'run s':>8s} {'rss MiB':>8s} "
      f"{'ns/bond-step':>12s} {'peak MPa':>9s} {'load':>5s}")
for r in rows:
    ns = 1e9 * r["run_wall_s"] / (r["steps"] * r["bonds"])
    print(f"{r['label']:8s} {r['blocks']:7d} {r['bonds']:7d} {r['steps']:7d} {r['wall_s']:8.2f} "
          f"{r['run_wall_s']:8.2f} {r['rss_bytes'] / 2**20:8.1f} {ns:12.1f} {r['peak_pa'] / 1e6:9.2f} "
          f"{r['load_average']:5.2f}")
if fits:
    print(f"fit over the meshes: wall ~ blocks^{fits['exponent_wall']:.2f}, run ~ blocks^{fits['exponent_run']:.2f}, "
          f"steps ~ blocks^{fits['exponent_steps']:.2f}")
json.dump({"beta_deg": float(beta), "runs": rows, **fits}, open(sys.argv[2], "w"), indent=1)
print(f"size_study3: wrote {sys.argv[2]}")
PY
