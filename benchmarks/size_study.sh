#!/usr/bin/env bash
# Growth with size: the cost and memory of one UCS run at mesh sizes 2, 1, 0.7 and 0.5 mm on the default specimen
# (50 x 100 mm) and at 1 mm on a specimen twice as large (100 x 200 mm), with the exponent of a power-law fit of
# the cost against the number of blocks, and the bytes per block and per bond.
#
#   benchmarks/size_study.sh [BUILD_DIR] [OUT_DIR] [BETA]   # defaults: build, runs/benchmarks, 60
#
# BETA = 60 (joint slip, about 1 400 steps at 1 mm) takes about a minute in all; BETA = 90 (splitting, about
# 28 000 steps at 1 mm and 73 000 at 0.5 mm) about 20 minutes. Each run skips the elastic gate (its cost is the
# gate's, cached after the first run of a scene: docs/elastic.md) and uses the scene's default threads. Writes
# OUT_DIR/size_study_beta<BETA>.json and prints the table. Run it on an idle machine.
#
# Columns: wall = the whole command (meshing, static start, explicit run, output); run = summary.json's
# wall_seconds; rss = the peak resident memory (GNU time); ns per bond-step = run wall / (steps x bonds), which
# includes the serial parts, so it falls towards the engine's kernel cost as the run grows.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
out=${2:-runs/benchmarks}
beta=${3:-60}
rbdem="$build/bin/rbdem"
[ -x "$rbdem" ] || { echo "size_study: $rbdem not built (scripts/setup.sh build)" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "size_study: needs GNU time (/usr/bin/time; Debian package 'time')" >&2; exit 2; }
mkdir -p "$out"
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
records="$work/records.txt"
: > "$records"

run() {  # label, extra rbdem options...
  local label=$1; shift
  rm -rf "$work/out"
  /usr/bin/time -f "%e %M" -o "$work/time.txt" \
    "$rbdem" ucs -q --beta "$beta" --skip-elastic-gate "$@" -o "$work/out" > "$work/log.txt" 2>&1 ||
    { echo "size_study: $label failed:" >&2; cat "$work/log.txt" >&2; exit 1; }
  python3 - "$label" "$work/time.txt" "$work/out/summary.json" >> "$records" <<'PY'
import json, sys
label, timing, summary = sys.argv[1:4]
wall, rss_kb = open(timing).read().split()[-2:]
s = json.load(open(summary))
print(json.dumps({"label": label, "wall_s": float(wall), "rss_bytes": int(rss_kb) * 1024,
                  "run_wall_s": s["wall_seconds"], "steps": s["steps"], "blocks": s["blocks"],
                  "bonds": s["bonds"], "peak_pa": s["peak_stress_pa"], "threads": s["threads"]}))
PY
  echo "size_study: $label done"
}

run "2 mm" --set mesh.size=0.002
run "1 mm" --set mesh.size=0.001
run "0.7 mm" --set mesh.size=0.0007
run "0.5 mm" --set mesh.size=0.0005
run "1 mm, 100 x 200 mm" --set mesh.size=0.001 --set specimen.width=0.1 --set specimen.height=0.2

python3 - "$records" "$out/size_study_beta${beta}.json" "$beta" <<'PY'
import json, math, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
beta = sys.argv[3]
# Power laws over the four mesh sizes of the default specimen: cost ~ blocks^p, steps ~ blocks^q.
fit = [r for r in rows if "100 x 200" not in r["label"]]
def slope(xs, ys):
    lx = [math.log(x) for x in xs]; ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)
blocks = [r["blocks"] for r in fit]
p_wall = slope(blocks, [r["wall_s"] for r in fit])
p_steps = slope(blocks, [r["steps"] for r in fit])
p_rss = slope(blocks, [r["rss_bytes"] for r in fit])
# Memory per block and per bond: the growth of the peak RSS between the smallest and the largest mesh, per block
# (bonds are about 1.5 per block, so the two are one number expressed twice).
lo, hi = min(fit, key=lambda r: r["blocks"]), max(fit, key=lambda r: r["blocks"])
per_block = (hi["rss_bytes"] - lo["rss_bytes"]) / (hi["blocks"] - lo["blocks"])
per_bond = (hi["rss_bytes"] - lo["rss_bytes"]) / (hi["bonds"] - lo["bonds"])
print(f"size study, beta = {beta} deg")
print(f"{'run':22s} {'blocks':>7s} {'bonds':>7s} {'steps':>7s} {'wall s':>8s} {'run s':>7s} {'rss MiB':>8s} "
      f"{'ns/bond-step':>12s} {'peak MPa':>9s}")
for r in rows:
    ns = 1e9 * r["run_wall_s"] / (r["steps"] * r["bonds"])
    print(f"{r['label']:22s} {r['blocks']:7d} {r['bonds']:7d} {r['steps']:7d} {r['wall_s']:8.2f} {r['run_wall_s']:7.2f} "
          f"{r['rss_bytes'] / 2**20:8.1f} {ns:12.1f} {r['peak_pa'] / 1e6:9.2f}")
print(f"fit over the default specimen's four meshes: wall ~ blocks^{p_wall:.2f}, steps ~ blocks^{p_steps:.2f}, "
      f"peak memory ~ blocks^{p_rss:.2f}; {per_block:.0f} bytes per block ({per_bond:.0f} per bond) of peak memory "
      f"growth")
json.dump({"beta_deg": float(beta), "runs": rows, "exponent_wall": p_wall, "exponent_steps": p_steps,
           "exponent_memory": p_rss, "bytes_per_block": per_block, "bytes_per_bond": per_bond},
          open(sys.argv[2], "w"), indent=1)
print(f"size_study: wrote {sys.argv[2]}")
PY
