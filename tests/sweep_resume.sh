#!/usr/bin/env bash
# A sweep interrupted with SIGINT and rerun finishes with the same table.csv as an uninterrupted one; results of
# another scene are never reused.
# Usage: sweep_resume.sh RBDEM STUDY
set -euo pipefail
rbdem=$1; study=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$rbdem" sweep "$study" --out "$work/full" -q -j 1 --skip-elastic-gate > /dev/null
"$rbdem" sweep "$study" --out "$work/cut" -q -j 1 --skip-elastic-gate > "$work/cut.log" 2>&1 &
pid=$!
# Interrupt as soon as the first case is complete (the others are still to run).
for _ in $(seq 1 600); do
  n=$( (find "$work/cut" -name summary.json 2>/dev/null || true) | wc -l)
  [ "$n" -ge 1 ] && break
  sleep 0.05
done
kill -INT "$pid"
set +e; wait "$pid"; rc=$?; set -e
done_cases=$(find "$work/cut" -name summary.json | wc -l)
total=$(find "$work/full" -name summary.json | wc -l)
echo "interrupted run: exit $rc with $done_cases of $total cases complete"
[ "$rc" -eq 130 ] || { echo "FAIL: expected exit 130 after SIGINT"; cat "$work/cut.log"; exit 1; }
[ "$done_cases" -lt "$total" ] || { echo "FAIL: the sweep finished before the interrupt; nothing was tested"; exit 1; }
[ ! -f "$work/cut/table.csv" ] || { echo "FAIL: an interrupted sweep must not write table.csv"; exit 1; }
"$rbdem" sweep "$study" --out "$work/cut" -q -j 1 --skip-elastic-gate > /dev/null
cmp "$work/full/table.csv" "$work/cut/table.csv" || { echo "FAIL: tables differ"; diff "$work/full/table.csv" "$work/cut/table.csv"; exit 1; }
cmp "$work/full/groups.csv" "$work/cut/groups.csv"
echo "OK: resumed sweep reproduces table.csv"
# Results of another scene are not reused: after an edit every case runs again.
"$rbdem" sweep "$study" --out "$work/cut" -q -j 1 --skip-elastic-gate --set loading.stop_fraction=0.69 > /dev/null
reused=$(awk -F, 'NR > 1 && $2 != 0' "$work/cut/timing.csv" | wc -l)
[ "$reused" -eq 0 ] || { echo "FAIL: $reused cases of another scene were reused"; cat "$work/cut/timing.csv"; exit 1; }
echo "OK: an edited scene reruns every case"
