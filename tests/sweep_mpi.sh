#!/usr/bin/env bash
# An MPI sweep with 2 ranks gives the same summaries and table as a serial sweep.
# Usage: sweep_mpi.sh RBDEM STUDY
set -euo pipefail
rbdem=$1; study=$2
command -v mpirun > /dev/null || { echo "SKIP: mpirun not installed"; exit 77; }
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$rbdem" sweep "$study" --out "$work/serial" -q --skip-elastic-gate > /dev/null
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
mpirun -np 2 --oversubscribe "$rbdem" sweep "$study" --out "$work/mpi" -q --skip-elastic-gate > "$work/mpi.log" 2>&1 \
  || { cat "$work/mpi.log"; exit 1; }
grep -q "over 2 MPI ranks" "$work/mpi.log" || { echo "FAIL: the sweep did not run over 2 ranks"; cat "$work/mpi.log"; exit 1; }
cmp "$work/serial/table.csv" "$work/mpi/table.csv"
# Summaries equal apart from the wall time.
for f in $(cd "$work/serial" && find . -name summary.json | sort); do
  /usr/bin/python3 - "$work/serial/$f" "$work/mpi/$f" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
for d in (a, b): d.pop("wall_seconds", None); d.pop("threads", None)
sys.exit(0 if a == b else f"summaries differ: {sys.argv[1]}")
PY
done
echo "OK: MPI sweep equals the serial sweep"
