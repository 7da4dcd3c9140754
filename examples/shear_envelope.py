#!/usr/bin/env python3
"""Direct shear of a joint at three normal stresses, and the Mohr-Coulomb envelope fitted to the peaks.

    PYTHONPATH=build/python /usr/bin/python3 examples/shear_envelope.py --out shear.png          # 2 mm mesh, ~5 s
    PYTHONPATH=build/python /usr/bin/python3 examples/shear_envelope.py --mesh 0.001 --stresses 2e6 5e6 10e6

Each run is rbdem.shear (the command `rbdem shear`, docs/model.md): the paper scene's specimen split by one
horizontal joint, the lower half held, the upper half pushed along the joint under a constant normal stress. The
script fits tau = c + sigma_n tan(phi) to the peaks and tau = mu sigma_n to the residual stresses, and draws both
with the shear curves.

What to expect (docs/theory.md, "Direct shear of a joint"): the residual slope is the joint's contact friction
(joint.contact_friction), and the peaks lie on the bonded interface's envelope, tau = 2 c + sigma_n tan(phi_b) with c
and phi_b the joint's cohesion and friction angle: rbdem shear meshes the specimen as a structured grid
(mesh.structured), every joint bond has the same stiffness and all reach their strength together. The script checks
the fitted friction angle against joint.friction_deg (within 1 deg), the fitted intercept against 2 c (within 5 %)
and the residual slope against joint.contact_friction (within 2 %), and exits 1 otherwise.
"""
import argparse
import math
import sys
import tomllib

import numpy as np

import rbdem

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--out", default="shear_envelope.png", help="the figure (PNG)")
parser.add_argument("--mesh", type=float, default=0.002, help="mesh size [m]")
parser.add_argument("--stresses", type=float, nargs="+", default=[2e6, 5e6, 10e6], help="normal stresses [Pa]")
args = parser.parse_args()

runs = []
for sigma_n in args.stresses:
    r = rbdem.shear(normal_stress=sigma_n, overrides={"mesh.size": args.mesh}, skip_elastic_gate=True)
    runs.append(r)
    s = r.summary
    print(f"sigma_n {sigma_n / 1e6:5.1f} MPa: peak {s['peak_shear_stress_pa'] / 1e6:6.2f} MPa (interface envelope "
          f"{s['joint_envelope_peak_pa'] / 1e6:.2f}, first break {s['first_break_peak_pa'] / 1e6:.2f}), residual "
          f"{s['residual_shear_stress_pa'] / 1e6:.3f} MPa, dilation {s['dilation_m'] * 1e9:+.1f} nm, "
          f"{s['steps']} steps, {r.seconds:.1f} s")

joint = tomllib.loads(runs[0].scene)["joint"]
sn = np.array(args.stresses)
peak = np.array([r.summary["peak_shear_stress_pa"] for r in runs])
residual = np.array([r.summary["residual_shear_stress_pa"] for r in runs])
slope, intercept = np.polyfit(sn, peak, 1)
phi = math.degrees(math.atan(slope))
mu = float(residual @ sn / (sn @ sn))
uniformity = runs[0].summary["joint_stiffness_uniformity"]
c_int = 2 * joint["cohesion"]
print(f"peak envelope: c = {intercept / 1e6:.2f} MPa, phi = {phi:.2f} deg (joint.friction_deg = {joint['friction_deg']:g}; "
      f"the bonded interface's cohesion 2 c = {c_int / 1e6:.2f} MPa; the joint's stiffness uniformity {uniformity:.2f})")
print(f"residual: mu = {mu:.4f} (joint.contact_friction = {joint['contact_friction']:g})")

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
for sigma_n, r in zip(args.stresses, runs):
    ax1.plot(r.curve["shear_displacement_m"] * 1e6, r.curve["stress_pa"] / 1e6, label=f"sigma_n = {sigma_n / 1e6:g} MPa")
ax1.set_xlabel("shear displacement (um)")
ax1.set_ylabel("shear stress (MPa)")
ax1.legend(fontsize=8)
x = np.linspace(0, sn.max() * 1.1, 50)
ax2.plot(sn / 1e6, peak / 1e6, "o", label="peaks")
ax2.plot(x / 1e6, (intercept + slope * x) / 1e6, "-", label=f"fit: c = {intercept / 1e6:.2f} MPa, phi = {phi:.1f} deg")
ax2.plot(x / 1e6, (2 * joint["cohesion"] + x * math.tan(math.radians(joint["friction_deg"]))) / 1e6, ":",
         label="bonded interface envelope")
ax2.plot(sn / 1e6, residual / 1e6, "s", label="residual")
ax2.plot(x / 1e6, mu * x / 1e6, "--", label=f"residual fit: mu = {mu:.3f}")
ax2.set_xlabel("normal stress (MPa)")
ax2.set_ylabel("shear stress (MPa)")
ax2.set_xlim(0, None)
ax2.set_ylim(0, None)
ax2.legend(fontsize=8)
fig.tight_layout()
fig.savefig(args.out, dpi=120)
print(f"wrote {args.out}")

if (abs(phi - joint["friction_deg"]) > 1.0 or abs(intercept / c_int - 1) > 0.05
        or abs(mu / joint["contact_friction"] - 1) > 0.02):
    sys.exit("the fitted friction angle, cohesion or residual friction is off the joint's (see the docstring)")
