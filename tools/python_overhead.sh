#!/usr/bin/env bash
# The cost of the Python layer (docs/python.md, "Cost of the Python layer"): `rbdem ucs --beta 90 -q --out X`
# against `rbdem.ucs(beta=90, out=X)` on the default scene, alternated, N times each (default 3), with the
# elastic gate's verdict cached beforehand (a warm-up run) so that both measure the test alone. Prints each run's
# process wall time and summary.json wall_seconds, the medians, and whether the summaries agree but for
# wall_seconds.
#   tools/python_overhead.sh [BUILD_DIR] [N]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}; n=${2:-3}
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
export RBDEM_CACHE_DIR=$work/cache PYTHONPATH=$build/python
"$build/bin/rbdem" ucs --beta 90 -q --out "$work/warm" > /dev/null
for i in $(seq 1 "$n"); do
  /usr/bin/time -f "cli $i %e" -a -o "$work/times" "$build/bin/rbdem" ucs --beta 90 -q --out "$work/cli$i" > /dev/null
  /usr/bin/time -f "python $i %e" -a -o "$work/times" /usr/bin/python3 -c \
    "import rbdem; rbdem.ucs(beta=90, out='$work/py$i')"
done
/usr/bin/python3 - "$work" "$n" <<'PY'
import json, statistics, sys
work, n = sys.argv[1], int(sys.argv[2])
proc = {"cli": [], "python": []}
for line in open(f"{work}/times"):
    who, _, seconds = line.split()
    proc[who].append(float(seconds))
summ = {w: [json.load(open(f"{work}/{'cli' if w == 'cli' else 'py'}{i}/summary.json")) for i in range(1, n + 1)]
        for w in proc}
for w in proc:
    walls = [s["wall_seconds"] for s in summ[w]]
    print(f"{w:6}: process {proc[w]} s (median {statistics.median(proc[w]):.2f}), wall_seconds "
          f"{[round(x, 2) for x in walls]} (median {statistics.median(walls):.2f})")
for key in ("process", "wall_seconds"):
    c = statistics.median(proc["cli"]) if key == "process" else statistics.median(s["wall_seconds"] for s in summ["cli"])
    p = statistics.median(proc["python"]) if key == "process" else statistics.median(s["wall_seconds"] for s in summ["python"])
    print(f"{key}: python / cli - 1 = {100 * (p / c - 1):+.2f} %")
strip = lambda s: {k: v for k, v in s.items() if k != "wall_seconds"}
same = all(strip(s) == strip(summ["cli"][0]) for w in summ for s in summ[w])
differ = sorted(k for k in summ["cli"][0] if summ["cli"][0][k] != summ["python"][0][k])
print(f"summaries identical but for wall_seconds: {same}; keys that differ: {differ}")
PY
