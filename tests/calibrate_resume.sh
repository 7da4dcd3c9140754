#!/usr/bin/env bash
# A calibration interrupted with SIGINT and continued with --resume ends with the same calibration.csv and
# calibrated.toml as an uninterrupted one; without --resume the folder of an earlier calibration is refused.
# Usage: calibrate_resume.sh RBDEM TARGETS
set -euo pipefail
rbdem=$1; targets=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
set +e; "$rbdem" calibrate "$targets" --out "$work/full" -j 1 > "$work/full.log" 2>&1; set -e
grep -q "^calibrate: .*converged after" "$work/full.log" || { echo "FAIL: the calibration did not finish"; cat "$work/full.log"; exit 1; }
evals=$(grep -c "^ *[0-9]* \(start\|jacobian\|step\|rejected\)" "$work/full.log" || true)
"$rbdem" calibrate "$targets" --out "$work/cut" -j 1 > "$work/cut.log" 2>&1 &
pid=$!
# Interrupt once the second evaluation has a complete run (the first is done, later ones are still to run).
for _ in $(seq 1 1200); do
  n=$( (find "$work/cut/eval_01" -name summary.json 2>/dev/null || true) | wc -l)
  [ "$n" -ge 1 ] && break
  sleep 0.05
done
kill -INT "$pid"
set +e; wait "$pid"; rc=$?; set -e
echo "interrupted calibration: exit $rc; the uninterrupted one made $evals evaluations"
[ "$rc" -eq 130 ] || { echo "FAIL: expected exit 130 after SIGINT"; cat "$work/cut.log"; exit 1; }
grep -q -- "--resume" "$work/cut.log" || { echo "FAIL: the interrupted calibration does not say how to continue"; cat "$work/cut.log"; exit 1; }
[ ! -f "$work/cut/calibration.csv" ] || { echo "FAIL: an interrupted calibration must not write calibration.csv"; exit 1; }
set +e; "$rbdem" calibrate "$targets" --out "$work/cut" -j 1 > "$work/again.log" 2>&1; rc=$?; set -e
[ "$rc" -eq 2 ] && grep -q -- "add --resume" "$work/again.log" || { echo "FAIL: the earlier calibration's folder was not refused without --resume (exit $rc)"; cat "$work/again.log"; exit 1; }
set +e; "$rbdem" calibrate "$targets" --out "$work/cut" -j 1 --resume > "$work/resume.log" 2>&1; set -e
grep -q "(runs reused)" "$work/resume.log" || { echo "FAIL: the resumed calibration reused no evaluation"; cat "$work/resume.log"; exit 1; }
cmp "$work/full/calibration.csv" "$work/cut/calibration.csv" || { echo "FAIL: calibration.csv differs"; diff "$work/full/calibration.csv" "$work/cut/calibration.csv"; exit 1; }
cmp <(tail -n +2 "$work/full/calibrated.toml") <(tail -n +2 "$work/cut/calibrated.toml") || { echo "FAIL: calibrated.toml differs"; exit 1; }
echo "OK: the resumed calibration reproduces calibration.csv and calibrated.toml"
