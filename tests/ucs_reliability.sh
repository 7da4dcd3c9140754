#!/usr/bin/env bash
# rbdem ucs end to end (docs/reliability.md): an interrupted run resumed with --resume ends with the same
# summary.json (wall time excluded), curve.csv and cracks.csv as an uninterrupted one, also after a real SIGTERM;
# an unstable step makes the watchdog stop the run with exit 1 and "completed": false; an output folder that cannot
# be written is refused with exit 2 before the run; a full disk (a tiny tmpfs, where mounting is allowed) is
# reported and leaves no summary.json.
# Also: --version and the version recorded in summary.json.
# Usage: ucs_reliability.sh RBDEM
set -euo pipefail
rbdem=$1
work=$(mktemp -d); trap 'umount "$work/tiny" 2>/dev/null || true; rm -rf "$work"' EXIT
args=(ucs -q --skip-elastic-gate --set specimen.width=0.01 --set specimen.height=0.02 --set joint_set.spacing=0.006
      --set mesh.size=0.002 --set numerics.threads=1 --set numerics.checkpoint_every_steps=500)
same() {  # summary.json equal without wall_seconds
  python3 - "$1" "$2" <<'PY'
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
for j in (a, b): j.pop("wall_seconds", None); j.pop("threads", None)
sys.exit(0 if a == b else 1)
PY
}

"$rbdem" "${args[@]}" --out "$work/full" > /dev/null
[ ! -e "$work/full/checkpoint.h5" ] || { echo "FAIL: a complete run leaves its checkpoint behind"; exit 1; }
steps=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['steps'])" "$work/full/summary.json")
echo "uninterrupted: $steps steps"

# 0. The version: printed by --version and recorded in the summary.
version=$("$rbdem" --version)
[[ "$version" =~ ^rbdem\ [0-9]+\.[0-9]+\.[0-9]+ ]] || { echo "FAIL: --version printed '$version'"; exit 1; }
python3 -c "import json,sys; v=json.load(open(sys.argv[1]))['version']; assert sys.argv[2] == 'rbdem ' + v, v" \
  "$work/full/summary.json" "$version" || { echo "FAIL: summary.json's version is not --version's"; exit 1; }
echo "OK: $version, recorded in summary.json"

# 1. Interrupted (as by SIGINT) half-way, then resumed.
set +e; "$rbdem" "${args[@]}" --out "$work/cut" --interrupt-at-step $((steps / 2)) > "$work/cut.log" 2>&1; rc=$?; set -e
[ "$rc" -eq 130 ] || { echo "FAIL: expected exit 130 when interrupted, got $rc"; cat "$work/cut.log"; exit 1; }
grep -q -- "--resume" "$work/cut.log" || { echo "FAIL: the message does not say how to resume"; cat "$work/cut.log"; exit 1; }
[ -f "$work/cut/checkpoint.h5" ] || { echo "FAIL: no checkpoint.h5"; exit 1; }
[ ! -f "$work/cut/summary.json" ] || { echo "FAIL: an interrupted run wrote summary.json"; exit 1; }
"$rbdem" "${args[@]}" --out "$work/cut" --resume > /dev/null
same "$work/full/summary.json" "$work/cut/summary.json" || { echo "FAIL: resumed summary.json differs"; exit 1; }
cmp "$work/full/curve.csv" "$work/cut/curve.csv"
cmp "$work/full/cracks.csv" "$work/cut/cracks.csv"
echo "OK: resumed at step $((steps / 2)) of $steps reproduces summary.json, curve.csv, cracks.csv"

# 2. A real SIGTERM while running (slower platen so the run lasts a few seconds), then resumed.
slow=(--set loading.platen_velocity=0.002)
"$rbdem" "${args[@]}" "${slow[@]}" --out "$work/slow_full" > /dev/null
"$rbdem" "${args[@]}" "${slow[@]}" --out "$work/term" > "$work/term.log" 2>&1 &
pid=$!
for _ in $(seq 1 200); do [ -f "$work/term/checkpoint.h5" ] && break; sleep 0.02; done
kill -TERM "$pid" 2>/dev/null || true
set +e; wait "$pid"; rc=$?; set -e
if [ "$rc" -eq 0 ]; then
  echo "note: the run finished before SIGTERM arrived; the signal path was not exercised"
else
  [ "$rc" -eq 143 ] || { echo "FAIL: expected exit 143 after SIGTERM, got $rc"; cat "$work/term.log"; exit 1; }
  grep -q -- "--resume" "$work/term.log" || { echo "FAIL: no resume hint"; cat "$work/term.log"; exit 1; }
  "$rbdem" "${args[@]}" "${slow[@]}" --out "$work/term" --resume > /dev/null
  same "$work/slow_full/summary.json" "$work/term/summary.json" || { echo "FAIL: summary after SIGTERM + resume differs"; exit 1; }
  echo "OK: SIGTERM -> exit 143 with a checkpoint; --resume reproduces summary.json"
fi

# 3. The watchdog: three times the exact stability limit (numerics.dt_safety stops at 0.7: a hidden test flag lets
#    numerics.dt through).
dt3=$(python3 -c "import json,sys; print(3 * json.load(open(sys.argv[1]))['dt_critical_s'])" "$work/full/summary.json")
set +e; "$rbdem" "${args[@]}" --set numerics.dt=$dt3 --allow-supercritical-dt --out "$work/wd" > "$work/wd.log" 2>&1; rc=$?; set -e
[ "$rc" -eq 1 ] || { echo "FAIL: expected exit 1 from the watchdog, got $rc"; cat "$work/wd.log"; exit 1; }
grep -q "numerics.dt_safety" "$work/wd.log" || { echo "FAIL: the message does not name the fix"; cat "$work/wd.log"; exit 1; }
python3 - "$work/wd/summary.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
assert j["completed"] is False and j["peak_stress_pa"] is None and j["watchdog"]["cause"], j
PY
echo "OK: watchdog exit 1, summary says completed = false"

# 4. An output folder that cannot be written: exit 2 naming it, before the run.
touch "$work/plainfile"
set +e; "$rbdem" "${args[@]}" --out "$work/plainfile/out" > "$work/bad.log" 2>&1; rc=$?; set -e
[ "$rc" -eq 2 ] || { echo "FAIL: expected exit 2 for an unwritable folder, got $rc"; cat "$work/bad.log"; exit 1; }
grep -q "$work/plainfile/out" "$work/bad.log" || { echo "FAIL: the error does not name the folder"; cat "$work/bad.log"; exit 1; }
! grep -q "^ucs:" "$work/bad.log" || { echo "FAIL: the run started"; exit 1; }
echo "OK: unwritable --out refused with exit 2"

# 5. A disk that fills up: a 64 KiB tmpfs holds the probe but not result.h5.
mkdir -p "$work/tiny"
if mount -t tmpfs -o size=64k tmpfs "$work/tiny" 2>/dev/null; then
  set +e; "$rbdem" "${args[@]}" --out "$work/tiny/run" > "$work/full.log" 2>&1; rc=$?; set -e
  [ "$rc" -eq 1 ] || { echo "FAIL: expected exit 1 on a full disk, got $rc"; cat "$work/full.log"; exit 1; }
  grep -qi "disk full\|No space" "$work/full.log" || { echo "FAIL: no disk-full message"; cat "$work/full.log"; exit 1; }
  [ ! -f "$work/tiny/run/summary.json" ] || { echo "FAIL: summary.json written despite failed writes"; exit 1; }
  umount "$work/tiny"
  echo "OK: full disk reported, no summary.json"
else
  echo "note: cannot mount a tmpfs here; the full-disk case is covered by Files.FullDiskIsReportedNotTruncated"
fi

# 6. A user mesh's joints set the dip: horizontal layers in a scene that says 30 deg report the measured 0 deg.
"$rbdem" mesh -q --set joint_set.dip_deg=0 --set specimen.width=0.01 --set specimen.height=0.02 \
  --set joint_set.spacing=0.006 --set mesh.size=0.002 --out "$work/flat.msh" > /dev/null
printf '[joint_set]\ndip_deg = 30\n[mesh]\nfile = "%s"\n[numerics]\nthreads = 1\n' "$work/flat.msh" > "$work/flat.toml"
"$rbdem" ucs "$work/flat.toml" -q --skip-elastic-gate --out "$work/flat" > "$work/flat.log"
grep -q "beta = 0 deg (measured from the mesh's joint edges)" "$work/flat.log" \
  || { echo "FAIL: the header does not give the measured dip"; cat "$work/flat.log"; exit 1; }
python3 - "$work/flat/summary.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
assert abs(j["beta_deg"]) < 1e-6 and j["beta_source"] == "mesh", (j["beta_deg"], j["beta_source"])
PY
echo "OK: a user mesh with horizontal layers reports beta_deg 0 (beta_source mesh), not the scene's 30"
