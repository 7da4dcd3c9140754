#!/usr/bin/env bash
# Growth with size in 3D: the cost of one UCS run of the 3D cylinder (scenes/cylinder.toml) at several mesh sizes,
# with the exponents of power-law fits of the wall time, the CPU time and the step count against the number of
# blocks.
#
#   benchmarks/size_study3.sh [BUILD_DIR] [OUT_DIR] [BETA] [SIZES_MM...]
#       # defaults: build, runs/benchmarks, 60, 8 6 5 4
#
# Each run skips the elastic gate and uses the scene's default threads (2); the 3D mesh is made by gmsh in every run
# (the mesh cache is off; its time is in "wall" and "cpu", not in "run"). Writes OUT_DIR/size_study3_beta<BETA>.json
# and prints the table. The load average (/proc/loadavg) at the start of each run is recorded beside it: run it on
# an idle machine, or read the CPU time, which other processes' turns do not inflate as they do the wall time.
#
# Columns: wall = the whole command (meshing, static start, explicit run, output); run = summary.json's
# wall_seconds; cpu = the command's user + system CPU time over its threads (GNU time); rss = the peak resident
# memory; ns per bond-step = run / (steps x bonds) and cpu / (steps x bonds), serial parts included.
set -euo pipefail

measure() {  # rbdem, work folder, beta, size in mm: appends one JSON line to work/records.txt
  local rbdem=$1 work=$2 beta=$3 mm=$4 size load
  size=$(python3 -c "print($mm / 1000)")
  load=$(cut -d' ' -f1 /proc/loadavg)
  rm -rf "$work/out"
  /usr/bin/time -f "%e %M %U %S" -o "$work/time.txt" \
    "$rbdem" ucs scenes/cylinder.toml -q --beta "$beta" --skip-elastic-gate --set mesh.size="$size" \
    -o "$work/out" > "$work/log.txt" 2>&1 ||
    { echo "size_study3: $mm mm failed:" >&2; cat "$work/log.txt" >&2; return 1; }
  python3 - "$mm mm" "$work/time.txt" "$work/out/summary.json" "$load" >> "$work/records.txt" <<'PY'
import json, sys
label, timing, summary, load = sys.argv[1:5]
wall, rss_kb, user, system = open(timing).read().split()[-4:]
s = json.load(open(summary))
print(json.dumps({"label": label, "wall_s": float(wall), "cpu_s": float(user) + float(system),
                  "rss_bytes": int(rss_kb) * 1024, "run_wall_s": s["wall_seconds"], "steps": s["steps"],
                  "blocks": s["blocks"], "bonds": s["bonds"], "peak_pa": s["peak_stress_pa"],
                  "threads": s["threads"], "load_average": float(load)}))
PY
  echo "size_study3: beta $beta, $mm mm done (load average $load at the start)"
}

report() {  # records file, json out, beta
  python3 - "$@" <<'PY'
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
    fits = {f"exponent_{k}": slope(blocks, [r[c] for r in rows])
            for k, c in (("wall", "wall_s"), ("cpu", "cpu_s"), ("run", "run_wall_s"), ("steps", "steps"))}
print(f"3D size study, beta = {beta} deg")
print(f"{'run':6s} {'blocks':>7s} {'bonds':>7s} {'steps':>7s} {'wall s':>8s} {'run s':>8s} {'cpu s':>8s} "
      f"{'rss MiB':>8s} {'run ns/bs':>9s} {'cpu ns/bs':>9s} {'peak MPa':>9s} {'load':>5s}")
for r in rows:
    bs = r["steps"] * r["bonds"]
    print(f"{r['label']:6s} {r['blocks']:7d} {r['bonds']:7d} {r['steps']:7d} {r['wall_s']:8.1f} "
          f"{r['run_wall_s']:8.1f} {r['cpu_s']:8.1f} {r['rss_bytes'] / 2**20:8.1f} {1e9 * r['run_wall_s'] / bs:9.1f} "
          f"{1e9 * r['cpu_s'] / bs:9.1f} {r['peak_pa'] / 1e6:9.2f} {r['load_average']:5.2f}")
if fits:
    print("fit over the meshes: " + ", ".join(f"{k[9:]} ~ blocks^{v:.2f}" for k, v in fits.items()))
json.dump({"beta_deg": float(beta), "runs": rows, **fits}, open(sys.argv[2], "w"), indent=1)
print(f"size_study3: wrote {sys.argv[2]}")
PY
}

main() {
  cd "$(dirname "$0")/.."
  local build=${1:-build} out=${2:-runs/benchmarks} beta=${3:-60}
  shift $(($# < 3 ? $# : 3))
  local sizes=("$@")
  [ ${#sizes[@]} -gt 0 ] || sizes=(8 6 5 4)
  local rbdem="$build/bin/rbdem"
  [ -x "$rbdem" ] || { echo "size_study3: $rbdem not built (scripts/setup.sh build)" >&2; exit 2; }
  [ -x /usr/bin/time ] || { echo "size_study3: needs GNU time (/usr/bin/time; Debian package 'time')" >&2; exit 2; }
  mkdir -p "$out"
  export RBDEM_MESH_CACHE=off
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  : > "$work/records.txt"
  for mm in "${sizes[@]}"; do  # the records so far kept in OUT_DIR after each run
    measure "$rbdem" "$work" "$beta" "$mm"
    cp "$work/records.txt" "$out/size_study3_beta${beta}.records"
  done
  report "$work/records.txt" "$out/size_study3_beta${beta}.json" "$beta"
}

# The whole script is read before it runs (main is called on its last line), so editing it meanwhile is safe.
main "$@"
