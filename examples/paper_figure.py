#!/usr/bin/env python3
"""The seed paper's figure from Python: uniaxial strength against joint dip (beta = 0, 15, ..., 90 deg).

    PYTHONPATH=build/python /usr/bin/python3 examples/paper_figure.py --out strength_vs_dip.png
    PYTHONPATH=build/python /usr/bin/python3 examples/paper_figure.py --quick      # 4 mm mesh, seconds

Runs rbdem.ucs on the built-in paper scene (100 x 50 mm, joints every 10 mm, 1 mm mesh; about 15 s a dip) and
plots the peak stress and the modulus E50 against the dip (docs/python.md).
"""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import rbdem  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--out", default="strength_vs_dip.png", help="the PNG to write")
parser.add_argument("--quick", action="store_true", help="a coarse 4 mm mesh: a fast check, not the paper's numbers")
args = parser.parse_args()

overrides = {"mesh.size": 0.004} if args.quick else {}
dips = list(range(0, 91, 15))
peaks, moduli = [], []
for beta in dips:
    r = rbdem.ucs(beta=beta, overrides=overrides)
    peaks.append(r.summary["peak_stress_pa"] / 1e6)
    moduli.append(r.summary["youngs_modulus_pa"] / 1e9)
    print(f"beta {beta:2d} deg: peak {peaks[-1]:6.2f} MPa, E50 {moduli[-1]:5.1f} GPa, {r.summary['failure_mode']}")

fig, ax = plt.subplots(figsize=(5.5, 4), constrained_layout=True)
ax.plot(dips, peaks, "o-", label="peak stress")
ax.set_xlabel("joint dip beta (deg)")
ax.set_ylabel("uniaxial strength (MPa)")
ax.set_xticks(dips)
ax.set_ylim(bottom=0)
ax2 = ax.twinx()
ax2.plot(dips, moduli, "s--", color="tab:gray", label="E50")
ax2.set_ylabel("E50 (GPa)")
ax2.set_ylim(bottom=0)
ax.set_title("rbdem: strength against dip" + (" (quick, 4 mm mesh)" if args.quick else ""))
lines = ax.get_lines() + ax2.get_lines()
ax.legend(lines, [line.get_label() for line in lines], loc="lower left")
fig.savefig(args.out, dpi=150)
print(f"wrote {args.out}")
