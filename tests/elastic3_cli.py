#!/usr/bin/env python3
"""`rbdem elastic` on a 3D scene (specimen.dimension = 3): the command runs, elastic.json holds the contract of
docs/elastic.md ("Three dimensions") and the exit status is the gate's verdict, which holds on the coarse mesh:
the DEM's static modulus is within elastic.tolerance of the FE twin with the DEM's constants at every dip.

    elastic3_cli.py --rbdem build/bin/rbdem --work build/tests/elastic3 [--set key=value ...]
"""
import argparse
import json
import math
import pathlib
import subprocess
import sys

CONSTANTS = ["E", "nu", "E_prime", "nu_prime", "G_prime"]
ANGLE_KEYS = ["beta_deg", "amadei_pa", "dem_static_pa", "fe_pa", "fe_goodman_pa", "amadei_goodman_pa",
              "amadei_goodman_jointed_mesh_pa", "fe_joints_pa", "dem_platen_pa", "fe_platen_pa", "poisson_strike",
              "poisson_dip", "blocks"]


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rbdem", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--set", action="append", default=[])
    a = ap.parse_args()
    out = pathlib.Path(a.work)
    cmd = [a.rbdem, "elastic", "-q", "--out", str(out), "--set", "specimen.dimension=3"]
    for s in a.set:
        cmd += ["--set", s]
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=240)
    print(run.stdout[-4000:], run.stderr[-2000:])
    if run.returncode not in (0, 3):
        fail(f"exit status {run.returncode}")
    j = json.loads((out / "elastic.json").read_text())
    if j.get("dimension") != 3:
        fail("dimension is not 3")
    for which in ("dem", "goodman", "goodman_jointed_mesh"):
        for k in CONSTANTS:
            v = j["constants"][which].get(k)
            if not isinstance(v, (int, float)) or not math.isfinite(v):
                fail(f"constants.{which}.{k} = {v}")
    betas = [row["beta_deg"] for row in j["angles"]]
    if betas != [0, 15, 30, 45, 60, 75, 90]:
        fail(f"angles at {betas}")
    for row in j["angles"]:
        for k in ANGLE_KEYS:
            if k not in row:
                fail(f"angles[beta = {row['beta_deg']}] lacks {k}")
    gate = j["gate"]
    tol = gate["tolerance"]
    worst = max(abs(row["dem_static_pa"] / row["fe_pa"] - 1.0) for row in j["angles"])
    if abs(worst - gate["max_deviation"]) > 1e-12:
        fail(f"gate.max_deviation {gate['max_deviation']} is not the angles' {worst}")
    if gate["passed"] != (worst <= tol) or run.returncode != (0 if gate["passed"] else 3):
        fail(f"verdict {gate['passed']} and exit {run.returncode} disagree with max deviation {worst}")
    if worst > tol:
        fail(f"dem_static is {100 * worst:.2f} % off fe, over elastic.tolerance {100 * tol:.2f} %")
    for k in ("total_seconds", "constants_seconds", "dem_seconds", "fe_seconds"):
        if not j["timing"].get(k, -1) >= 0:
            fail(f"timing.{k}")
    # rbdem mesh on the same scene: the tetrahedral mesh's statistics.
    mesh = subprocess.run([a.rbdem, "mesh", "-q", "--set", "specimen.dimension=3"] +
                          [x for s in a.set for x in ("--set", s)], capture_output=True, text=True, timeout=60)
    if mesh.returncode != 0 or "tetrahedra" not in mesh.stdout:
        fail(f"rbdem mesh on the 3D scene: status {mesh.returncode}: {mesh.stdout[-500:]} {mesh.stderr[-500:]}")
    print(f"ok: max |dem_static / fe - 1| = {100 * worst:.2f} % (tolerance {100 * tol:.2f} %), "
          f"{j['timing']['total_seconds']:.1f} s")


if __name__ == "__main__":
    main()
