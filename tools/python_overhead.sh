#!/usr/bin/env bash
# The cost of the Python layer (docs/python.md, "Cost of the Python layer"): `rbdem ucs --beta 90 -q --out X`
# against `rbdem.ucs(beta=90, out=X)` on the default scene, alternated, N times each (default 3), after a warm-up
# run that caches the elastic gate's verdict, so that both measure the test alone. THREADS=n sets
# numerics.threads in both (default: the scene's, all cores). Prints each run's process wall and CPU time and its
# summary.json wall_seconds, the medians, and which summary keys differ between the two.
#   tools/python_overhead.sh [BUILD_DIR] [N]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}; n=${2:-3}; threads=${THREADS:-}
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
export RBDEM_CACHE_DIR=$work/cache PYTHONPATH=$build/python
cli=("$build/bin/rbdem" ucs --beta 90 -q); py="overrides={}"
if [ -n "$threads" ]; then cli+=(--set "numerics.threads=$threads"); py="overrides={'numerics.threads': $threads}"; fi
"${cli[@]}" --out "$work/warm" > /dev/null
for i in $(seq 1 "$n"); do
  /usr/bin/time -f "cli $i %e %U %S" -a -o "$work/times" "${cli[@]}" --out "$work/cli$i" > /dev/null
  /usr/bin/time -f "python $i %e %U %S" -a -o "$work/times" /usr/bin/python3 -c \
    "import rbdem; rbdem.ucs(beta=90, $py, out='$work/py$i')"
done
/usr/bin/python3 - "$work" "$n" <<'PY'
import json, statistics, sys
work, n = sys.argv[1], int(sys.argv[2])
wall, cpu = {"cli": [], "python": []}, {"cli": [], "python": []}
for line in open(f"{work}/times"):
    who, _, e, u, s = line.split()
    wall[who].append(float(e))
    cpu[who].append(float(u) + float(s))
summ = {w: [json.load(open(f"{work}/{w[:3] if w == 'cli' else 'py'}{i}/summary.json")) for i in range(1, n + 1)]
        for w in wall}
engine = {w: [s["wall_seconds"] for s in summ[w]] for w in wall}
for name, m in (("process wall", wall), ("process cpu (user+sys)", cpu), ("summary wall_seconds", engine)):
    c, p = statistics.median(m["cli"]), statistics.median(m["python"])
    print(f"{name:24}: cli {[round(x, 2) for x in m['cli']]} median {c:.2f} s; python "
          f"{[round(x, 2) for x in m['python']]} median {p:.2f} s; python / cli - 1 = {100 * (p / c - 1):+.2f} %")
strip = lambda s: {k: v for k, v in s.items() if k != "wall_seconds"}
same = all(strip(s) == strip(summ["cli"][0]) for w in summ for s in summ[w])
differ = sorted(k for k in summ["cli"][0] if summ["cli"][0][k] != summ["python"][0][k])
print(f"summaries identical but for wall_seconds: {same}; keys that differ (cli 1 vs python 1): {differ}")
PY
