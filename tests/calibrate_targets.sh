#!/usr/bin/env bash
# The envelope targets of a calibration read the confined runs: each evaluation runs the dip at every confining
# pressure, fits the envelope (envelope.csv) and takes its cohesion and friction angle as the measured values.
# Usage: calibrate_targets.sh RBDEM TARGETS
set -euo pipefail
rbdem=$1; targets=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
set +e; "$rbdem" calibrate "$targets" --out "$work/c" -j 1 > "$work/log" 2>&1; rc=$?; set -e
[ "$rc" -eq 0 ] || [ "$rc" -eq 3 ] || { echo "FAIL: exit $rc"; cat "$work/log"; exit 1; }
runs=$(find "$work/c/eval_00/triaxial" -name summary.json | wc -l)
[ "$runs" -eq 3 ] || { echo "FAIL: evaluation 0 ran $runs confined runs, not one per pressure (3)"; exit 1; }
python3 - "$work/c" <<'PY'
import csv, sys
out = sys.argv[1]
env = list(csv.DictReader(open(f"{out}/eval_00/triaxial/envelope.csv")))[0]
row = list(csv.DictReader(open(f"{out}/calibration.csv")))[0]
for target, column in (("cohesion@60", "cohesion_pa"), ("friction_angle@60", "friction_deg")):
    measured, fitted = float(row[target]), float(env[column])
    if abs(measured - fitted) > 1e-3 * abs(fitted):
        sys.exit(f"FAIL: {target} = {measured} but the envelope fit gives {fitted}")
print(f"OK: cohesion {float(row['cohesion@60']) / 1e6:.3f} MPa and friction angle {float(row['friction_angle@60']):.2f} deg "
      "from the confined envelope")
PY
