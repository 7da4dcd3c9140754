"""Speed against error: peak-stress error against cost (bond-steps) for the mesh-size, platen-speed and time-step
studies (docs/performance.md). Reads docs/data/speed_error.csv, writes docs/speed_error.png.

    /usr/bin/python3 python/speed_error.py docs/data/speed_error.csv docs/speed_error.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(src, dst):
    rows = list(csv.DictReader(open(src)))
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
    labels = {"mesh_size": "mesh size (mm)", "loading_rate": "platen speed (m/s)", "time_step": "dt_safety"}
    for ax, beta in zip(axes, ("60", "90")):
        for knob, marker in (("mesh_size", "o"), ("loading_rate", "s"), ("time_step", "^")):
            sel = [r for r in rows if r["knob"] == knob and r["beta_deg"] == beta]
            ref = [float(r["peak_stress_pa"]) for r in sel if r["value"] == r["reference_value"]][0]
            pts = sorted((float(r["bond_steps"]), abs(float(r["peak_stress_pa"]) / ref - 1) * 100, r["value"])
                         for r in sel if r["value"] != r["reference_value"])
            ax.plot([p[0] for p in pts], [max(p[1], 0.01) for p in pts], marker=marker, label=labels[knob])
            for c, e, v in pts:
                ax.annotate(v, (c, max(e, 0.01)), textcoords="offset points", xytext=(3, 3), fontsize=7)
        ax.axhline(5, color="grey", lw=0.8, ls="--")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("cost of one run (bond-steps)")
        ax.set_ylabel("|peak / finest - 1| (%)")
        ax.set_title(f"beta = {beta} deg")
    axes[0].legend(fontsize=8)
    fig.savefig(dst, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
