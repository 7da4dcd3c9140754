#!/usr/bin/env python3
"""A confined compression test written in Python: servo-controlled side walls hold the lateral stress.

    PYTHONPATH=build/python /usr/bin/python3 examples/confined_servo.py --out confined.png        # 3 mm, ~30 s
    PYTHONPATH=build/python /usr/bin/python3 examples/confined_servo.py --sigma3 10e6 --beta 60 --mesh 0.001

Instead of the built-in test's jacket (a pressure on each outer face), each side of the specimen is held by a
column of rigid wall segments, PFC-style (and the platens start under a servo to sigma_3 too, an isotropic start): the blocks within one mesh size of the side, cut into segments
--segment tall. Each segment is a block group that moves as one body: across the side under a servo that drives
the force the specimen puts on it to sigma_3 times its height (x: "servo"), along the side freely with the
specimen (y: "free"), without turning (rotation: "fixed"). The servo's gain is set from the stiffness that ties the
segment to the specimen (Group.attachment_stiffness), 0.3 of the most one step can take, and its rate limit is
twenty times the platens' speed. Once the walls have brought the specimen to sigma_3 the top platen closes at
loading.platen_velocity, and the test ends when the axial stress has fallen to 85 % of its peak.

The script prints the lateral stress the walls held (from their reactions: the mean over the walls, and the
segment that strayed most, which a crack next to it loads or unloads for a moment) and the interior's Love-Weber
stress, and compares the peak with `rbdem triaxial` at the same sigma_3 (the jacket). Up to 90 % of the peak the
walls' mean lateral stress must stay within 1 % of sigma_3 on average and within 5 % at every sample (the bursts
of cracking before the peak move it for a few steps); otherwise the script exits 1.
"""
import argparse
import sys
import tomllib

import numpy as np

import rbdem

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--out", default="confined_servo.png", help="the figure (PNG)")
parser.add_argument("--beta", type=float, default=30.0, help="joint dip [deg]")
parser.add_argument("--sigma3", type=float, default=5e6, help="lateral stress the walls hold [Pa]")
parser.add_argument("--mesh", type=float, default=0.003, help="mesh size [m]")
parser.add_argument("--segment", type=float, default=0.005, help="height of one wall segment [m]")
args = parser.parse_args()

scene = {"mesh.size": args.mesh}


class ServoWalls(rbdem.Protocol):
    """Side walls of rigid segments under a lateral-stress servo; the top platen loads once sigma_3 is reached."""
    name = "confined_servo"
    every = 20
    max_steps = 400_000

    def prepare(self, sim):
        resolved = tomllib.loads(sim.scene)
        self.velocity = resolved["loading"]["platen_velocity"]
        self.platens = sim.add_platens(velocity=0.0)
        lo, hi = sim.specimen["lo"], sim.specimen["hi"]
        self.height, self.thickness = hi[1] - lo[1], sim.specimen["thickness"]
        # The isotropic start: the platens too are servoed to sigma_3 (docs/python.md's rule for the gain, with the
        # specimen's axial stiffness taken as E* A / H of the rock bonds).
        area = (hi[0] - lo[0]) * self.thickness
        stiffness = resolved["rock"]["effective_modulus"] * area / self.height
        gain = area / (10 * np.sqrt(stiffness * sim.blocks["mass"].sum()))
        self.platens.set_servo(args.sigma3, gain=gain, max_velocity=self.velocity)
        self.walls = []
        edges = np.arange(lo[1], hi[1] + 1e-12, args.segment)
        for side, x0, x1, push in (("left", lo[0] - 1, lo[0] + args.mesh, +1), ("right", hi[0] - args.mesh, hi[0] + 1, -1)):
            for k, (y0, y1) in enumerate(zip(edges[:-1], edges[1:])):
                load = push * args.sigma3 * (y1 - y0) * self.thickness          # N, on the whole segment
                g = sim.add_group(f"{side}_{k}", box=((x0, y0), (x1, y1)), modes=["servo", "free", "fixed"],
                                  value=[load, 0.0, 0.0], servo={"gain": 1e-20, "max_velocity": 20 * self.velocity})
                # the gain: 0.3 of the most one step can take against the bonds that tie it to the specimen
                g.set_servo(gain=0.3 / (g.attachment_stiffness()[0] * sim.dt), max_velocity=20 * self.velocity)
                self.walls.append((g, y1 - y0))
        self.loading = False
        self.trace = []                       # (axial strain, platen stress, lateral stress held, worst segment)

    def lateral(self):
        """The walls' mean lateral stress (compression positive) from their reactions, and the worst segment's."""
        per = np.array([abs(g.force[0]) / (h * self.thickness) for g, h in self.walls])
        return per.mean(), per[np.argmax(abs(per / args.sigma3 - 1))]

    def step(self, sim):
        mean, worst = self.lateral()
        if (not self.loading and abs(mean / args.sigma3 - 1) < 0.005 and sim.steps > 2000
                and abs(self.platens.stress / args.sigma3 - 1) < 0.005):
            self.platens.set_velocity(self.velocity)
            self.loading = True
        if self.loading:
            self.trace.append((self.platens.closure / self.height, self.platens.stress, mean, worst))

    def done(self, sim):
        if len(self.trace) < 50:
            return False
        stress = np.array([t[1] for t in self.trace])
        return stress[-1] < 0.85 * stress.max()

    def results(self, sim):
        # The servo's check: while the specimen deforms quasi-statically, up to 90 % of the peak (the failure
        # itself is dynamic, and a crack next to a segment unloads it for a moment).
        t = np.array(self.trace)
        before = t[: int(np.argmax(t[:, 1] >= 0.9 * t[:, 1].max())) + 1]
        return {"sigma3_pa": args.sigma3,
                "lateral_average_deviation": float(abs(before[:, 2].mean() / args.sigma3 - 1)),
                "lateral_mean_deviation": float(np.abs(before[:, 2] / args.sigma3 - 1).max()),
                "lateral_worst_deviation": float(np.abs(before[:, 3] / args.sigma3 - 1).max())}


walls = ServoWalls()
sim = rbdem.Simulation(beta=args.beta, overrides=scene)
r = sim.run(walls)
s = r.summary
own = {k: s[k] for k in ("lateral_average_deviation", "lateral_mean_deviation", "lateral_worst_deviation")}
print(f"{sim.specimen['blocks']} blocks, {len(walls.walls)} wall segments; peak sigma_1 = {s['peak_stress_pa'] / 1e6:.2f} MPa "
      f"at sigma_3 = {args.sigma3 / 1e6:g} MPa, {s['steps']} steps, {r.seconds:.1f} s")
print(f"lateral stress up to 90 % of the peak: on average within {100 * own['lateral_average_deviation']:.2f} % of "
      f"sigma_3, the walls' mean at every sample within {100 * own['lateral_mean_deviation']:.2f} %, every segment "
      f"within {100 * own['lateral_worst_deviation']:.2f} %")
h = sim.specimen["hi"][1]
w = sim.specimen["hi"][0]
inside = sim.stress(box=((0.2 * w, 0.2 * h), (0.8 * w, 0.8 * h)), boundaries=False)
print(f"interior Love-Weber stress at the end: sigma_xx = {-inside[0, 0] / 1e6:.2f} MPa, "
      f"sigma_yy = {-inside[1, 1] / 1e6:.2f} MPa (compression positive)")
jacket = rbdem.triaxial(beta=args.beta, confining=args.sigma3, overrides=scene, skip_elastic_gate=True)
print(f"rbdem triaxial (a jacket) at the same sigma_3: peak {jacket.summary['peak_stress_pa'] / 1e6:.2f} MPa; "
      f"servo walls / jacket = {s['peak_stress_pa'] / jacket.summary['peak_stress_pa']:.3f}")

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

t = np.array(walls.trace)
fig, ax = plt.subplots(figsize=(6, 4))
ax.plot(t[:, 0] * 1e3, t[:, 1] / 1e6, label="sigma_1 (platens), servo walls")
ax.plot(t[:, 0] * 1e3, t[:, 2] / 1e6, label="sigma_3 held by the walls (mean)")
ax.plot(t[:, 0] * 1e3, t[:, 3] / 1e6, lw=0.6, label="sigma_3, worst segment")
ax.plot(jacket.curve["strain"] * 1e3, jacket.curve["stress_pa"] / 1e6, "--", label="sigma_1, rbdem triaxial (jacket)")
ax.set_xlabel("axial strain (1e-3)")
ax.set_ylabel("stress (MPa)")
ax.set_title(f"confined test at sigma_3 = {args.sigma3 / 1e6:g} MPa, beta = {args.beta:g} deg")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(args.out, dpi=120)
print(f"wrote {args.out}")
if own["lateral_average_deviation"] > 0.01 or own["lateral_mean_deviation"] > 0.05:
    sys.exit("the walls did not hold sigma_3: on average within 1 % and at every sample within 5 % were required")
