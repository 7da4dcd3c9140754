#!/usr/bin/env python3
"""The force network of a loaded specimen and a rose of its bond force directions.

    PYTHONPATH=build/python /usr/bin/python3 examples/force_rose.py --out rose.png       # 2 mm mesh, seconds
    PYTHONPATH=build/python /usr/bin/python3 examples/force_rose.py --mesh 0.001 --beta 60 --stress 30e6

A Simulation of the scene is loaded by its platens (closing at loading.platen_velocity) until their mean stress
reaches --stress; then the bonds and contacts are read as arrays (sim.bonds, sim.contacts). Each bond carries a
normal force along the line between its blocks (tension positive); the rose sums the compressive ones by the
direction of that line, folded into 0-180 deg (a bond at 90 deg is vertical). The force-weighted fabric tensor
F = sum |f_n| n (x) n / sum |f_n| gives the mean direction of the compressive chains and how strongly they align:
under vertical platens its major direction is within a few degrees of vertical, which the script checks (exit 1
otherwise). The figure shows the rose beside the compressive bond network drawn between block centroids, the
line width growing with the force.
"""
import argparse
import sys
import tomllib

import numpy as np

import rbdem

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--out", default="force_rose.png", help="the figure (PNG)")
parser.add_argument("--beta", type=float, default=30.0, help="joint dip [deg]")
parser.add_argument("--mesh", type=float, default=0.002, help="mesh size [m]")
parser.add_argument("--stress", type=float, default=15e6, help="platen stress at which to read the network [Pa]")
args = parser.parse_args()

sim = rbdem.Simulation(beta=args.beta, overrides={"mesh.size": args.mesh})
velocity = tomllib.loads(sim.scene)["loading"]["platen_velocity"]
platens = sim.add_platens(velocity=velocity)
while platens.stress < args.stress:
    sim.step(200)
    if sim.steps > 200_000:
        sys.exit(f"the platens did not reach {args.stress / 1e6:g} MPa in {sim.steps} steps")
print(f"{sim.specimen['blocks']} blocks; platen stress {platens.stress / 1e6:.2f} MPa after {sim.steps} steps "
      f"({sim.time * 1e3:.3f} ms), closure {platens.closure * 1e6:.1f} um")

bonds, contacts, blocks = sim.bonds, sim.contacts, sim.blocks
compressed = bonds["intact"] & (bonds["normal_force"] < 0)
n = bonds["normal"][compressed]
f = -bonds["normal_force"][compressed]
angle = np.degrees(np.arctan2(n[:, 1], n[:, 0])) % 180.0
fabric = (f[:, None, None] * n[:, :, None] * n[:, None, :]).sum(axis=0) / f.sum()
values, vectors = np.linalg.eigh(fabric)
major = np.degrees(np.arctan2(vectors[1, 1], vectors[0, 1])) % 180.0
print(f"compressive bonds: {compressed.sum()} of {len(compressed)}; "
      f"contacts: {len(contacts['i'])}")
print(f"force-weighted fabric: major direction {major:.1f} deg, eigenvalues {values[1]:.3f} and {values[0]:.3f}")

bins = np.linspace(0.0, 180.0, 19)
weight, _ = np.histogram(angle, bins=bins, weights=f)
print("direction [deg]  share of the compressive bond force")
for lo, w in zip(bins[:-1], weight / weight.sum()):
    print(f"  {lo:5.0f}-{lo + 10:3.0f}      {w:6.3f}  {'#' * int(round(200 * w))}")

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.collections import LineCollection

fig = plt.figure(figsize=(10, 5))
ax = fig.add_subplot(1, 2, 1, projection="polar")
centres = np.radians(0.5 * (bins[:-1] + bins[1:]))
width = np.radians(bins[1] - bins[0])
share = weight / weight.sum()
ax.bar(np.concatenate([centres, centres + np.pi]), np.concatenate([share, share]), width=width,
       edgecolor="k", linewidth=0.4)
ax.set_title(f"compressive bond force by direction\nmajor fabric direction {major:.1f} deg")
ax2 = fig.add_subplot(1, 2, 2)
pos = blocks["position"]
i, j = bonds["i"][compressed], bonds["j"][compressed]
segments = np.stack([pos[i], pos[j]], axis=1) * 1e3
lines = LineCollection(segments, linewidths=0.8 * f / f.max(), colors="k")
ax2.add_collection(lines)
ax2.set_xlim(segments[..., 0].min(), segments[..., 0].max())
ax2.set_ylim(segments[..., 1].min(), segments[..., 1].max())
ax2.set_aspect("equal")
ax2.set_xlabel("x [mm]")
ax2.set_ylabel("y [mm]")
ax2.set_title(f"bond force network at {platens.stress / 1e6:.1f} MPa (beta = {args.beta:g} deg)")
fig.tight_layout()
fig.savefig(args.out, dpi=120)
print(f"wrote {args.out}")

if abs(major - 90.0) > 10.0:
    sys.exit(f"the compressive chains should be near vertical under vertical platens; major direction {major:.1f} deg")
