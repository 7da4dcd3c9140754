#!/usr/bin/env bash
# Whole-run benchmark: wall seconds of one UCS run on the default specimen at 1 and 2 threads (beta = 90, the
# slowest dip, and 60, the fastest) and of the default seven-dip curve (`rbdem`'s study, 2 workers), as medians of
# repeated runs. Takes about (3 x 30 + 3 x 20 + 3 x 60) s = 6 minutes with 3 repetitions on 2 cores.
#
#   benchmarks/whole_runs.sh [BUILD_DIR] [OUT_DIR]     # defaults: build, runs/benchmarks
#   REPETITIONS=5 benchmarks/whole_runs.sh
#
# Writes OUT_DIR/whole_runs.json: for each run its wall times, median, steps and peak. Run it on an idle machine.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
out=${2:-runs/benchmarks}
reps=${REPETITIONS:-3}
rbdem="$build/bin/rbdem"
[ -x "$rbdem" ] || { echo "whole_runs: $rbdem not built (scripts/setup.sh build)" >&2; exit 2; }
mkdir -p "$out"
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
records="$work/records.txt"
: > "$records"

time_run() {  # name, summary file pattern, command...
  local name=$1 pattern=$2; shift 2
  for r in $(seq 1 "$reps"); do
    rm -rf "$work/out"
    local t0 t1
    t0=$(date +%s.%N)
    "$@" > "$work/log.txt" 2>&1 || { echo "whole_runs: $name failed:" >&2; cat "$work/log.txt" >&2; exit 1; }
    t1=$(date +%s.%N)
    python3 - "$name" "$t0" "$t1" "$work/out" "$pattern" >> "$records" <<'PY'
import glob, json, os, sys
name, t0, t1, out, pattern = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4], sys.argv[5]
steps, peaks = 0, {}
for f in sorted(glob.glob(os.path.join(out, pattern))):
    s = json.load(open(f))
    steps += s["steps"]
    peaks[f"{s['beta_deg']:g}"] = s["peak_stress_pa"]
print(json.dumps({"name": name, "wall_s": t1 - t0, "steps": steps, "peaks_pa": peaks}))
PY
    echo "whole_runs: $name repetition $r: $(tail -1 "$records" | python3 -c 'import json,sys; print(round(json.load(sys.stdin)["wall_s"], 2))') s"
  done
}

for beta in 90 60; do
  for threads in 1 2; do
    time_run "ucs_beta${beta}_threads${threads}" "summary.json" \
      "$rbdem" ucs -q --beta "$beta" --set numerics.threads="$threads" -o "$work/out"
  done
done
# The default study, as `rbdem` runs it (2 workers, idle cores handed to the last runs), into a scratch folder.
printf '[study]\nname = "paper_dips"\nbase = ""\ndips = [0, 15, 30, 45, 60, 75, 90]\n' > "$work/paper_dips.toml"
time_run "seven_dip_curve" "beta=*/summary.json" "$rbdem" sweep "$work/paper_dips.toml" --out "$work/out" -q

python3 - "$records" "$out/whole_runs.json" <<'PY'
import json, statistics, sys
runs = {}
for line in open(sys.argv[1]):
    r = json.loads(line)
    e = runs.setdefault(r["name"], {"wall_s": [], "steps": r["steps"], "peaks_pa": r["peaks_pa"]})
    e["wall_s"].append(r["wall_s"])
for name, e in runs.items():
    e["median_wall_s"] = statistics.median(e["wall_s"])
    print(f"{name:28s} median {e['median_wall_s']:7.2f} s  of {len(e['wall_s'])}  steps {e['steps']}")
json.dump(runs, open(sys.argv[2], "w"), indent=1)
print(f"whole_runs: wrote {sys.argv[2]}")
PY
