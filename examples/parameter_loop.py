#!/usr/bin/env python3
"""A loop of your own: the uniaxial strength at beta = 60 deg as the joints' cohesion varies.

    PYTHONPATH=build/python /usr/bin/python3 examples/parameter_loop.py            # 2 mm mesh, about a minute
    PYTHONPATH=build/python /usr/bin/python3 examples/parameter_loop.py --out runs/loop   # keep each run's files

Each run is one rbdem.ucs call with overrides (the command line's --set); the results stay in Python as dicts and
NumPy arrays. For studies with resumable folders and Jaeger's tables, rbdem.sweep runs a study file instead.
"""
import argparse
import os

import rbdem

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--out", help="write each run's files into OUT/cohesion=...")
parser.add_argument("--beta", type=float, default=60.0, help="joint dip [deg]")
args = parser.parse_args()

base = {"mesh.size": 0.002}
print(f"{'joint.cohesion MPa':>18} {'peak MPa':>9} {'E50 GPa':>8} {'cracks':>7}  failure mode")
for cohesion in (2e6, 4e6, 6e6, 8e6):
    out = os.path.join(args.out, f"cohesion={cohesion:g}") if args.out else None
    r = rbdem.ucs(beta=args.beta, overrides={**base, "joint.cohesion": cohesion}, out=out)
    s = r.summary
    joint_cracks = int((r.cracks["kind"] == "joint").sum())
    print(f"{cohesion / 1e6:18.1f} {s['peak_stress_pa'] / 1e6:9.2f} {s['youngs_modulus_pa'] / 1e9:8.1f} "
          f"{s['cracks']['total']:7d}  {s['failure_mode']} ({joint_cracks} along the joints)")
