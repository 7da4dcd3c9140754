#!/usr/bin/env bash
# A sweep with realizations = 3 runs three meshes per dip (different peaks, mesh.seed 0, 1, 2), writes their
# rows to realizations.csv and one row per dip to table.csv whose mean, sd and 95 % interval are recomputed here
# from realizations.csv (Student t_{0.975, 2} = 4.302652730); a rerun reuses every realization. IDS lists the
# study's cases (default: the 2D tiny study's two dips).
# Usage: sweep_realizations.sh RBDEM STUDY [IDS]
set -euo pipefail
rbdem=$1; study=$2; ids=${3:-beta=60,beta=90}
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$rbdem" sweep "$study" --out "$work/s" -q -j 2 --skip-elastic-gate > /dev/null
python3 - "$work/s" "$ids" <<'PY'
import csv, math, sys
out = sys.argv[1]
real = list(csv.DictReader(open(f"{out}/realizations.csv")))
table = {r["id"]: r for r in csv.DictReader(open(f"{out}/table.csv"))}
assert sorted(table) == sorted(sys.argv[2].split(",")), sorted(table)
for point, row in table.items():
    rs = [r for r in real if r["point"] == point]
    assert [r["mesh_seed"] for r in rs] == ["0", "1", "2"], [r["mesh_seed"] for r in rs]
    peaks = [float(r["peak_stress_pa"]) for r in rs]
    assert len(set(peaks)) == 3, f"{point}: realizations gave equal peaks {peaks}: the meshes do not differ"
    mean = sum(peaks) / 3
    sd = math.sqrt(sum((p - mean) ** 2 for p in peaks) / 2)
    half = 4.302652730 * sd / math.sqrt(3)
    for col, want in (("peak_stress_pa", mean), ("peak_stress_sd_pa", sd), ("peak_stress_ci95_pa", half),
                      ("peak_stress_ci95_low_pa", mean - half), ("peak_stress_ci95_high_pa", mean + half)):
        got = float(row[col])
        # The CSVs hold 9 significant digits: the peaks read here and the table's values are rounded by up to
        # 5e-9 of the mean, and the interval's 4.3 / sqrt(3) amplifies the peaks' share (up to about 2e-8).
        assert abs(got - want) <= 4e-8 * abs(mean), f"{point} {col}: table {got}, by hand {want}"
    assert row["realizations"] == "3", row["realizations"]
    print(f"{point}: peaks {', '.join(f'{p / 1e6:.3f}' for p in peaks)} MPa, mean {mean / 1e6:.3f} "
          f"+- {half / 1e6:.3f} MPa (sd {sd / 1e6:.3f}): as in table.csv")
PY
cp "$work/s/table.csv" "$work/table_first.csv"
"$rbdem" sweep "$study" --out "$work/s" -q -j 2 --skip-elastic-gate > /dev/null
runs=$(( 3 * $(tr ',' '\n' <<< "$ids" | wc -l) ))
reused=$(awk -F, 'NR > 1 && $2 == 1' "$work/s/timing.csv" | wc -l)
[ "$reused" -eq "$runs" ] || { echo "FAIL: $reused of $runs realizations reused on rerun"; cat "$work/s/timing.csv"; exit 1; }
cmp "$work/table_first.csv" "$work/s/table.csv" || { echo "FAIL: the rerun changed table.csv"; exit 1; }
echo "OK: a rerun reuses every realization and gives the same table.csv"
