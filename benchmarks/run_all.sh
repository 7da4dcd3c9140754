#!/usr/bin/env bash
# Runs every benchmark of a build and writes one machine-readable results file.
#
#   benchmarks/run_all.sh [BUILD_DIR] [OUT_DIR]        # defaults: build, runs/benchmarks
#   REPETITIONS=5 benchmarks/run_all.sh               # medians over 5 repetitions (default 3)
#   WITH_REFERENCE=1 benchmarks/run_all.sh            # also the ARKODE implicit/explicit study (about 75 s CPU)
#
# Writes OUT_DIR/<bench>.json (Google Benchmark JSON, with median aggregates), OUT_DIR/results.json (the medians of
# every benchmark and counter, with the machine's context) and prints the medians. Run it on an idle machine:
# timings on a loaded 2-core machine are noisy, so compare medians from one run, not across runs.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
out=${2:-runs/benchmarks}
reps=${REPETITIONS:-3}
mkdir -p "$out"
for b in bench_engine bench_bonds bench_contacts bench_mesh bench_fe; do
  exe="$build/benchmarks/$b"
  [ -x "$exe" ] || { echo "run_all: $exe not built, skipped"; continue; }
  echo "run_all: $b ($reps repetitions)"
  "$exe" --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true \
         --benchmark_out="$out/$b.json" --benchmark_out_format=json > "$out/$b.txt"
done
if [ "${WITH_REFERENCE:-0}" = 1 ] && [ -x "$build/benchmarks/bench_reference" ]; then
  echo "run_all: bench_reference"
  "$build/benchmarks/bench_reference" > "$out/bench_reference.txt"
fi
python3 - "$out" <<'PY'
import glob, json, os, sys
out = sys.argv[1]
merged = {"context": None, "benchmarks": {}}
for path in sorted(glob.glob(os.path.join(out, "bench_*.json"))):
    data = json.load(open(path))
    merged["context"] = merged["context"] or data.get("context")
    for b in data.get("benchmarks", []):
        if b.get("aggregate_name") != "median":
            continue
        name = b["run_name"]
        entry = {"real_time": b["real_time"], "cpu_time": b["cpu_time"], "time_unit": b["time_unit"]}
        for k, v in b.items():
            if k not in entry and isinstance(v, (int, float)) and k not in ("repetitions", "repetition_index",
                                                                              "threads", "iterations",
                                                                              "family_index",
                                                                              "per_family_instance_index"):
                entry[k] = v
        merged["benchmarks"][os.path.basename(path)[:-5] + "/" + name] = entry
json.dump(merged, open(os.path.join(out, "results.json"), "w"), indent=1)
for name, e in merged["benchmarks"].items():
    extra = ", ".join(f"{k} {v:.4g}" for k, v in e.items() if k not in ("real_time", "cpu_time", "time_unit"))
    print(f"{name:45s} {e['real_time']:10.3f} {e['time_unit']}  {extra}")
print(f"run_all: wrote {os.path.join(out, 'results.json')}")
PY
