#!/usr/bin/python3
"""Figures of rbdem runs: stress-strain curves, strength versus dip, crack maps (the paper's Figure 9).

Run with Debian's /usr/bin/python3 (python3-matplotlib, python3-h5py, python3-numpy); headless (Agg).

    rbdem_figures.py stress-strain OUT.png RUN_DIR [RUN_DIR ...] [--labels L ...]
    rbdem_figures.py strength OUT.png TABLE.csv [--group COLUMN]
    rbdem_figures.py cracks OUT.png RUN_DIR [--at peak|final|both] [--magnify M]
    rbdem_figures.py crack-grid OUT.png RUN_DIR [RUN_DIR ...] [--labels L ...] [--magnify M]
    rbdem_figures.py elastic-fields OUT.png ELASTIC.json [--beta B]
    rbdem_figures.py stages OUT.png RUN_DIR [RUN_DIR ...] [--labels L ...]
    rbdem_figures.py rose OUT.png RUN_DIR [RUN_DIR ...] [--labels L ...] [--bin DEG]
    rbdem_figures.py crack-rate OUT.png RUN_DIR [RUN_DIR ...] [--labels L ...]
    rbdem_figures.py fragments OUT.png RUN_DIR [RUN_DIR ...] [--labels L ...]
    rbdem_figures.py batch LIST.jsonl [--jobs N]     (one figure's arguments per line, as a JSON list)

Examples:

    /usr/bin/python3 python/rbdem_figures.py stress-strain curves.png runs/b0 runs/b60 --labels '0 deg' '60 deg'
    /usr/bin/python3 python/rbdem_figures.py strength strength.png runs/study/table.csv --group group
    /usr/bin/python3 python/rbdem_figures.py cracks cracks.png runs/b60 --at both
    /usr/bin/python3 python/rbdem_figures.py crack-grid dips.png runs/study/b*
    /usr/bin/python3 python/rbdem_figures.py stages stages.png runs/b90

A RUN_DIR is the --out folder of `rbdem ucs` (summary.json, curve.csv, result.h5). What each figure shows and
how to read it: docs/outputs.md. The functions plot_* can be imported as well.
"""

import argparse
import json
import os
import sys
import time

INSTALL_HINT = "apt-get install python3-matplotlib python3-h5py python3-numpy"


def _missing_module(error):
    """One line instead of a traceback when run as a script without matplotlib, numpy or h5py: exit status 2."""
    name = getattr(error, "name", None) or str(error)
    print(f"rbdem_figures.py: {sys.executable} cannot import {name}: {INSTALL_HINT} "
          "(or run the script with a Python that has matplotlib, h5py and numpy: rbdem uses $RBDEM_PYTHON)",
          file=sys.stderr)
    sys.exit(2)


try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: E402
    import numpy as np  # noqa: E402
    from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402
    from matplotlib.lines import Line2D  # noqa: E402
except ImportError as e:
    if __name__ != "__main__":
        raise  # imported as a module: the importer sees the ImportError
    _missing_module(e)

# Crack classes: (kind, mode) -> (legend label, colour). kind 0 rock, 1 joint; mode 1 tensile, 2 shear.
CRACK_STYLES = {
    (0, 1): ("rock, tensile", "#d62728"),
    (0, 2): ("rock, shear", "#ff7f0e"),
    (1, 1): ("joint, tensile", "#1f77b4"),
    (1, 2): ("joint, shear", "#2ca02c"),
}
# Light fills, cycled by layer id, so the layering shows without hiding the cracks.
LAYER_FILLS = ["#ececec", "#dfe6ee", "#f1ebe0", "#e3ece2"]


# ------------------------------------------------------------------------------------------------ reading runs


def _load_results():
    """The run readers of the rbdem package (python/rbdem/results.py beside this script), loaded by path: the
    package's __init__ needs the compiled module, which a source tree does not have."""
    import importlib.util

    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "rbdem", "results.py")
    spec = importlib.util.spec_from_file_location("rbdem_results", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


results = _load_results()
_read_csv, _float = results.read_csv_rows, results.to_float
read_summary, read_curve, CrackMapData = results.read_summary, results.read_curve, results.RunFile


def _beta_label(summary):
    beta = summary.get("beta_deg")
    return f"β = {beta:g}°" if beta is not None else ""


def _mode_text(mode):
    return str(mode).replace("_", " ")


# ------------------------------------------------------------------------------------------------ figures


def _check_labels(labels, run_dirs):
    if labels and len(labels) != len(run_dirs):
        raise SystemExit(f"--labels: {len(labels)} labels for {len(run_dirs)} runs")


def _finish_runs_figure(fig, ax, out):
    """Grid, legend, save and close: the end of a one-axes figure with one curve per run."""
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.savefig(out, dpi=150)
    plt.close(fig)


def plot_stress_strain(out, run_dirs, labels=None):
    """Stress (MPa) against axial strain, top platen solid and bottom platen dashed, the peak marked."""
    _check_labels(labels, run_dirs)
    fig, ax = plt.subplots(figsize=(6.4, 4.6), constrained_layout=True)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for n, run in enumerate(run_dirs):
        c = read_curve(run)
        s = read_summary(run)
        color = colors[n % len(colors)]
        label = labels[n] if labels else (_beta_label(s) or os.path.basename(os.path.normpath(run)))
        order = np.argsort(c["strain"], kind="stable")
        e = c["strain"][order]
        peak, at = s.get("peak_stress_pa"), s.get("strain_at_peak")
        if peak is not None:
            label = f"{label}: peak {peak / 1e6:.1f} MPa"
        ax.plot(e, c["stress_top_pa"][order] / 1e6, color=color, lw=1.4, label=label)
        ax.plot(e, c["stress_bottom_pa"][order] / 1e6, color=color, lw=1.0, ls="--")
        if peak is not None and at is not None:
            ax.plot([at], [peak / 1e6], marker="o", ms=6, mfc="white", mec=color, mew=1.5, zorder=5)
            if len(run_dirs) <= 3:  # with more curves the values would overlap; the legend has them
                ax.annotate(f"{peak / 1e6:.1f} MPa", (at, peak / 1e6), textcoords="offset points", xytext=(4, 5),
                            fontsize=8, color=color)
    ax.set_xlabel("axial strain (-)")
    ax.set_ylabel("axial stress (MPa)")
    ax.set_title("Stress-strain (solid: top platen, dashed: bottom; o: peak)", fontsize=10)
    ax.ticklabel_format(axis="x", style="sci", scilimits=(-3, 3))
    ax.set_xlim(0, ax.get_xlim()[1] * 1.06)  # room for the peak labels
    ax.set_ylim(0, ax.get_ylim()[1] * 1.04)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2 if len(run_dirs) > 4 else 1)
    fig.savefig(out, dpi=150)
    plt.close(fig)


def plot_strength(out, table, group=None):
    """Peak strength against dip, one curve per group, Jaeger dashed when the table has it, minima marked."""
    rows = _read_csv(table)
    if not rows:
        raise SystemExit(f"{table}: no rows")
    for col in ("beta_deg", "peak_stress_pa"):
        if col not in rows[0]:
            raise SystemExit(f"{table}: no column {col} (columns: {', '.join(rows[0])})")
    if group and group not in rows[0]:
        raise SystemExit(f"{table}: no column {group} for --group (columns: {', '.join(rows[0])})")
    has_jaeger = "jaeger_pa" in rows[0]
    has_ci = "peak_stress_ci95_pa" in rows[0]
    groups = {}
    for r in rows:
        groups.setdefault(r[group] if group else "", []).append(r)
    fig, ax = plt.subplots(figsize=(6.4, 4.6), constrained_layout=True)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    jaeger_drawn = False
    for n, (name, rs) in enumerate(groups.items()):
        color = colors[n % len(colors)]
        beta = np.array([_float(r["beta_deg"]) for r in rs])
        peak = np.array([_float(r["peak_stress_pa"]) for r in rs]) / 1e6
        order = np.argsort(beta)
        beta, peak = beta[order], peak[order]
        if not group or name == "":
            label = "DEM"
        else:
            label = name if "=" in name else f"{group} = {name}"
        ok = np.isfinite(peak)
        if ok.any():
            k = int(np.nanargmin(peak))
            label += f" (min {peak[k]:.1f} MPa at {beta[k]:g}°)"
        if has_ci:  # a study with realizations: the mean with its 95 % interval
            ci = np.array([_float(r["peak_stress_ci95_pa"]) for r in rs])[order] / 1e6
            ax.errorbar(beta, peak, yerr=ci, marker="o", color=color, lw=1.5, capsize=3, label=label)
        else:
            ax.plot(beta, peak, marker="o", color=color, lw=1.5, label=label)
        if ok.any():
            ax.plot([beta[k]], [peak[k]], marker="v", ms=11, mfc="none", mec=color, mew=1.6, zorder=5)
        if has_jaeger:
            jae = np.array([_float(r["jaeger_pa"]) for r in rs])[order] / 1e6
            if np.isfinite(jae).any():
                ax.plot(beta, jae, ls="--", color=color, lw=1.0, alpha=0.8)
                jaeger_drawn = True
    handles, _ = ax.get_legend_handles_labels()
    if jaeger_drawn:
        handles.append(Line2D([0], [0], color="0.4", ls="--", lw=1.0, label="Jaeger, plane of weakness (dashed)"))
    ax.set_xlabel("joint dip β (deg)")
    ax.set_ylabel("peak strength (MPa)")
    ax.set_xticks(np.arange(0, 91, 15))
    ax.set_xlim(-3, 93)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    title = "Uniaxial strength versus joint dip (▽: minimum)"
    if has_ci:
        title += f"\nmean of {rows[0]['realizations']} meshes, bars: 95 % interval of the mean"
    ax.set_title(title, fontsize=10)
    ax.legend(handles=handles, fontsize=8, loc="lower left")
    fig.savefig(out, dpi=150)
    plt.close(fig)


def _require(rows, path, cols):
    if not rows:
        raise SystemExit(f"{path}: no rows")
    for col in cols:
        if col not in rows[0]:
            raise SystemExit(f"{path}: no column {col} (columns: {', '.join(rows[0])})")


def plot_tensile(out, table):
    """Brazilian tensile strength 2P/(pi D t) against the angle between the layers and the load, one marker per
    failure mode (rbdem sweep of a brazilian study)."""
    rows = _read_csv(table)
    _require(rows, table, ("layer_angle_deg", "tensile_strength_pa", "failure_mode"))
    angle = np.array([_float(r["layer_angle_deg"]) for r in rows])
    ts = np.array([_float(r["tensile_strength_pa"]) for r in rows]) / 1e6
    modes = [r["failure_mode"] for r in rows]
    order = np.argsort(angle)
    fig, ax = plt.subplots(figsize=(6.4, 4.4), constrained_layout=True)
    ax.plot(angle[order], ts[order], color="0.3", lw=1.2, zorder=1)
    if "tensile_strength_ci95_pa" in rows[0]:  # a study with realizations: the 95 % interval of each mean
        ci = np.array([_float(r["tensile_strength_ci95_pa"]) for r in rows]) / 1e6
        ax.errorbar(angle, ts, yerr=ci, ls="none", color="0.3", capsize=3, zorder=1)
    markers = {"central_fracture": "o", "non_central_fracture": "s", "layer_activation": "^", "mixed": "D"}
    for mode in dict.fromkeys(modes):
        k = [i for i, m in enumerate(modes) if m == mode]
        ax.plot(angle[k], ts[k], ls="none", marker=markers.get(mode, "x"), ms=8, label=_mode_text(mode), zorder=2)
    ax.set_xlabel("angle between the layers and the load (deg; 0 = load along the layers)")
    ax.set_ylabel("tensile strength 2P/(πDt) (MPa)")
    ax.set_xticks(np.arange(0, 91, 15))
    ax.set_xlim(-3, 93)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.set_title("Brazilian tensile strength versus layer angle", fontsize=10)
    ax.legend(fontsize=8, loc="lower right")
    fig.savefig(out, dpi=150)
    plt.close(fig)


def plot_envelope(out, table, envelope):
    """sigma_1 at peak against sigma_3, one colour per dip: the DEM's points (solid), its least-squares line
    (dotted) and Jaeger's (dashed; the sliding line where the dip is in the slip range, else the intact line fitted
    at 90 deg is not drawn: the table's jaeger_pa column is used as it is)."""
    rows = _read_csv(table)
    _require(rows, table, ("beta_deg", "confining_pressure_pa", "peak_stress_pa", "jaeger_pa"))
    env = {(_float(r["beta_deg"])): r for r in _read_csv(envelope)}
    by_beta = {}
    for r in rows:
        by_beta.setdefault(_float(r["beta_deg"]), []).append(r)
    fig, ax = plt.subplots(figsize=(6.8, 5.0), constrained_layout=True)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for n, beta in enumerate(sorted(by_beta)):
        rs = by_beta[beta]
        c = colors[n % len(colors)]
        s3 = np.array([_float(r["confining_pressure_pa"]) for r in rs]) / 1e6
        s1 = np.array([_float(r["peak_stress_pa"]) for r in rs]) / 1e6
        jae = np.array([_float(r["jaeger_pa"]) for r in rs]) / 1e6
        o = np.argsort(s3)
        s3, s1, jae = s3[o], s1[o], jae[o]
        label = f"β = {beta:g}°"
        e = env.get(beta)
        if e is not None and np.isfinite(_float(e.get("slope", "nan"))):
            label += f": k {_float(e['slope']):.2f}, φ {_float(e['friction_deg']):.1f}°, c {_float(e['cohesion_pa']) / 1e6:.1f} MPa"
        ax.plot(s3, s1, marker="o", color=c, lw=1.4, label=label)
        if e is not None and np.isfinite(_float(e.get("slope", "nan"))):
            xs = np.array([0.0, s3.max()])
            ax.plot(xs, _float(e["intercept_pa"]) / 1e6 + _float(e["slope"]) * xs, ls=":", color=c, lw=1.0)
        if np.isfinite(jae).any():
            ax.plot(s3, jae, ls="--", color=c, lw=1.0, alpha=0.8)
    handles, _ = ax.get_legend_handles_labels()
    handles.append(Line2D([0], [0], color="0.4", ls="--", lw=1.0, label="Jaeger (dashed)"))
    handles.append(Line2D([0], [0], color="0.4", ls=":", lw=1.0, label="DEM least-squares line (dotted)"))
    ax.set_xlabel("confining pressure σ3 (MPa)")
    ax.set_ylabel("σ1 at peak (MPa)")
    ax.set_xlim(left=-0.5)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.set_title("Confined strength per joint dip (k: slope dσ1/dσ3)", fontsize=10)
    ax.legend(handles=handles, fontsize=7, loc="upper left")
    fig.savefig(out, dpi=150)
    plt.close(fig)


def _draw_crack_map(ax, data, k, magnify=1.0, fill=True):
    """Deformed blocks (light fill by layer) and the cracks up to frame k on one axes; returns counts per class."""
    verts = data.vertices(k, magnify)
    if fill:
        fills = np.array([matplotlib.colors.to_rgba(c) for c in LAYER_FILLS])
        polys = PolyCollection(verts * 1e3, facecolors=fills[data.layer % len(fills)], edgecolors="none",
                               linewidths=0, antialiaseds=False)
        ax.add_collection(polys)
    seg, kind, mode = data.crack_segments(k, verts)
    counts = {}
    for key, (label, color) in CRACK_STYLES.items():
        sel = (kind == key[0]) & (mode == key[1])
        counts[key] = int(sel.sum())
        if counts[key]:
            ax.add_collection(LineCollection(seg[sel] * 1e3, colors=color, linewidths=1.3, capstyle="round",
                                             zorder=3))
    # The specimen, not the few blocks thrown off it (magnified, one can land far away): the limits hold 99.8 % of
    # the block centroids, and the blocks outside are clipped.
    centres = verts.mean(axis=1) * 1e3
    lo = np.percentile(centres, 0.1, axis=0) - 0.5 * np.ptp(verts[0], axis=0).max() * 1e3
    hi = np.percentile(centres, 99.9, axis=0) + 0.5 * np.ptp(verts[0], axis=0).max() * 1e3
    pad = 0.02 * (hi - lo).max()
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    return counts


_TET_EDGES = np.array([(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)])
_TRI_EDGES = np.array([(0, 1), (0, 2), (1, 2)])


def _cut(ref_y, y0, deformed, edges):
    """Where the plane y = y0 of the reference configuration cuts each cell's edges: per cell the (x, z) of the
    deformed points at the edges' reference crossing parameters, padded with the last valid point, and how many
    edges it cuts. A vertex exactly on the plane counts as above it."""
    d = np.where(ref_y == y0, 1e-300, ref_y - y0)
    da, db = d[:, edges[:, 0]], d[:, edges[:, 1]]
    crosses = da * db < 0
    t = np.where(crosses, da / np.where(crosses, da - db, 1.0), 0.0)
    pa, pb = deformed[:, edges[:, 0]][..., [0, 2]], deformed[:, edges[:, 1]][..., [0, 2]]
    pts = pa + t[..., None] * (pb - pa)
    order = np.argsort(~crosses, axis=1, kind="stable")  # the cut edges first
    pts = np.take_along_axis(pts, order[..., None], axis=1)
    count = crosses.sum(axis=1)
    last = np.take_along_axis(pts, np.maximum(count - 1, 0)[:, None, None], axis=1)
    pts = np.where((np.arange(pts.shape[1]) < count[:, None])[..., None], pts, last)
    return pts, count


class Section3:
    """A 3D run as a crack map: its x-z section through the specimen's centre (the plane y = y0 of the reference
    configuration, drawn where the blocks moved): each tetrahedron the plane cuts as its triangle or quadrilateral,
    each broken face it cuts as a segment. The same reading interface as the 2D RunFile."""

    def __init__(self, run_dir):
        import h5py

        self.file = h5py.File(os.path.join(run_dir, "result.h5"), "r")
        f = self.file
        self.summary = json.loads(f["summary"].attrs["json"])
        self.tets, self.nodes = f["mesh/tetrahedra"][()], f["mesh/nodes"][()]
        self.y0 = 0.5 * (self.nodes[:, 1].min() + self.nodes[:, 1].max())
        ref = self.nodes[self.tets]
        y = ref[..., 1]
        self.cells = np.flatnonzero((y.min(axis=1) < self.y0) & (y.max(axis=1) > self.y0))
        self.layer = f["mesh/layer"][()][self.cells]
        self.bond_i, self.bond_nodes = f["bonds/i"][()], f["bonds/nodes"][()]
        self.crack_bond, self.crack_kind, self.crack_mode = (f["cracks/bond"][()], f["cracks/kind"][()],
                                                              f["cracks/mode"][()])
        self.frames = []
        for name in sorted(f["frames"].keys()):
            a = f["frames"][name].attrs
            label = a["label"].decode() if isinstance(a["label"], bytes) else str(a["label"])
            self.frames.append({"name": name, "label": label, "step": int(a["step"]), "strain": float(a["strain"]),
                                "stress": float(a["stress_pa"]), "cracks": int(a["cracks"])})
        self._blocks = None

    def frame_index(self, at):
        return results.RunFile.frame_index(self, at)

    def _block_vertices(self, k, magnify):
        v = self.file["frames"][self.frames[k]["name"]]["vertices"][()].astype(float).reshape(-1, 4, 3)
        if magnify != 1.0:
            ref = self.nodes[self.tets]
            v = ref + magnify * (v - ref)
        return v

    def vertices(self, k, magnify=1.0):
        """The section's polygons (P, 4, 2) in (x, z) at frame k (a triangle repeats its last vertex)."""
        self._blocks = self._block_vertices(k, magnify)
        c = self.cells
        pts, _ = _cut(self.nodes[self.tets[c]][..., 1], self.y0, self._blocks[c], _TET_EDGES)
        pts = pts[:, :4]
        centre = pts.mean(axis=1, keepdims=True)
        angle = np.arctan2(pts[..., 1] - centre[..., 1], pts[..., 0] - centre[..., 0])
        return np.take_along_axis(pts, np.argsort(angle, axis=1)[..., None], axis=1)

    def crack_segments(self, k, verts):
        """The broken faces up to frame k that the plane cuts, moved with block i: (segments (C, 2, 2), kind,
        mode)."""
        n = self.frames[k]["cracks"]
        bonds = self.crack_bond[:n]
        i = self.bond_i[bonds]
        face = self.bond_nodes[bonds]  # (C, 3) mesh nodes; vertex v of block t is node tets[t][v]
        slot = np.argmax(self.tets[i][:, None, :] == face[:, :, None], axis=2)  # (C, 3)
        moved = np.take_along_axis(self._blocks[i], slot[..., None], axis=1)
        pts, count = _cut(self.nodes[face][..., 1], self.y0, moved, _TRI_EDGES)
        cut = count == 2
        return pts[cut, :2], self.crack_kind[:n][cut], self.crack_mode[:n][cut]

    def close(self):
        self.file.close()


def _crack_map_data(run_dir):
    """The crack map reader of a run: its triangles (2D) or the x-z section of its tetrahedra (3D)."""
    return Section3(run_dir) if read_summary(run_dir).get("dimension", 2) == 3 else CrackMapData(run_dir)


def _legend_handles(counts=None):
    handles = []
    for key, (label, color) in CRACK_STYLES.items():
        text = label if counts is None else f"{label} ({counts.get(key, 0)})"
        handles.append(Line2D([0], [0], color=color, lw=2, label=text))
    return handles


def plot_cracks(out, run_dir, at="final", magnify=1.0):
    """The paper's Figure 9: deformed specimen and cracks at the peak, the final state, or both side by side."""
    data = _crack_map_data(run_dir)
    try:
        which = ["peak", "final"] if at == "both" else [at]
        fig, axes = plt.subplots(1, len(which), figsize=(3.6 * len(which) + 1.6, 6.6), squeeze=False,
                                 constrained_layout=True)
        for ax, name in zip(axes[0], which):
            k = data.frame_index(name)
            fr = data.frames[k]
            counts = _draw_crack_map(ax, data, k, magnify)
            ax.set_title(f"{name}: strain {fr['strain']:.3g}, {fr['stress'] / 1e6:.1f} MPa\n"
                         f"{fr['cracks']} cracks", fontsize=9)
            ax.set_xlabel("x (mm)")
            section = isinstance(data, Section3)
            ax.set_ylabel(f"z (mm), the x-z section at y = {data.y0 * 1e3:.1f} mm" if section else "y (mm)")
            ax.legend(handles=_legend_handles(counts), loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2,
                      fontsize=7, frameon=False)
        s = data.summary
        mag = f", displacements x{magnify:g}" if magnify != 1.0 else ""
        fig.suptitle(f"{_beta_label(s)}: {_mode_text(s.get('failure_mode', '?'))}{mag}", fontsize=11)
        fig.savefig(out, dpi=150)
        plt.close(fig)
    finally:
        data.close()


def plot_crack_grid(out, run_dirs, labels=None, magnify=1.0):
    """Crack maps of several runs side by side at their final frame (e.g. the seven dips of a study)."""
    _check_labels(labels, run_dirs)
    n = len(run_dirs)
    fig, axes = plt.subplots(1, n, figsize=(2.3 * n + 0.6, 5.8), squeeze=False)
    fig.set_layout_engine("constrained", rect=(0, 0.05, 1, 0.95))  # room for the legend below
    sections = False
    for m, (ax, run) in enumerate(zip(axes[0], run_dirs)):
        data = _crack_map_data(run)
        sections = sections or isinstance(data, Section3)
        try:
            k = data.frame_index("final")
            _draw_crack_map(ax, data, k, magnify)
            s = data.summary
            title = labels[m] if labels else (_beta_label(s) or os.path.basename(os.path.normpath(run)))
            peak = s.get("peak_stress_pa")
            peak_text = f"{peak / 1e6:.1f} MPa, " if peak is not None else ""
            ax.set_title(f"{title}\n{peak_text}{data.frames[k]['cracks']} cracks\n"
                         f"{_mode_text(s.get('failure_mode', '?'))}", fontsize=8)
            ax.set_xticks([])
            ax.set_yticks([])
        finally:
            data.close()
    mag = f" (displacements x{magnify:g})" if magnify != 1.0 else ""
    where = " (3D runs: the x-z section through the centre)" if sections else ""
    fig.suptitle(f"Cracks at the end of each run{where}{mag}", fontsize=10)
    fig.legend(handles=_legend_handles(), loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.savefig(out, dpi=150)
    plt.close(fig)


def plot_elastic_fields(out, elastic_json, beta=None):
    """DEM and the FE model with the joints side by side: block-centroid |u| (um, rigid x translation removed) at one
    dip of `rbdem elastic --fields` (elastic.json), by default the dip where the two fields differ most."""
    with open(elastic_json) as f:
        angles = [a for a in json.load(f)["angles"] if "fields" in a and "fe_joints_ux" in a["fields"]]
    if not angles:
        raise SystemExit(f"{elastic_json}: no fields of the FE model with the joints; run rbdem elastic --fields")
    if beta is None:
        a = max(angles, key=lambda r: r.get("field_l2_joints") or 0.0)
    else:
        a = min(angles, key=lambda r: abs(r["beta_deg"] - beta))
    F = a["fields"]
    x, y = np.array(F["x"]) * 1e3, np.array(F["y"]) * 1e3
    du = [np.hypot(F["dem_ux"], F["dem_uy"]) * 1e6, np.hypot(F["fe_joints_ux"], F["fe_joints_uy"]) * 1e6]
    vmax = max(du[0].max(), du[1].max())
    fig, axes = plt.subplots(1, 2, figsize=(7.5, 5.6), constrained_layout=True)
    names = [f"DEM (static), E_gauge {a['dem_gauge_pa'] / 1e9:.3g} GPa",
             f"FE with the joints, E_gauge {a['fe_joints_pa'] / 1e9:.3g} GPa"]
    for ax, data, name in zip(axes, du, names):
        sc = ax.scatter(x, y, c=data, s=5, cmap="viridis", vmin=0, vmax=vmax, linewidths=0)
        ax.set_title(name, fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
    axes[0].set_ylabel("y (mm)")
    fig.colorbar(sc, ax=axes, shrink=0.8, label="|u| (um)")
    fig.suptitle(f"beta = {a['beta_deg']:g} deg: relative L2 difference {100 * (a.get('field_l2_joints') or 0):.2f} %, "
                 f"moduli {100 * a['dem_gauge_vs_fe_joints']:+.2f} %", fontsize=10)
    fig.savefig(out, dpi=120)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------ command line


def plot_fields(out, csv_path, title=None):
    """DEM and FE block-centroid displacements side by side (colour: |u| in um) and their difference."""
    rows = _read_csv(csv_path)
    x = np.array([_float(r["x_m"]) for r in rows]) * 1e3
    y = np.array([_float(r["y_m"]) for r in rows]) * 1e3
    du = [np.hypot([_float(r["dem_ux_m"]) for r in rows], [_float(r["dem_uy_m"]) for r in rows]) * 1e6,
          np.hypot([_float(r["fe_ux_m"]) for r in rows], [_float(r["fe_uy_m"]) for r in rows]) * 1e6]
    diff = np.hypot([_float(r["dem_ux_m"]) - _float(r["fe_ux_m"]) for r in rows],
                    [_float(r["dem_uy_m"]) - _float(r["fe_uy_m"]) for r in rows]) * 1e6
    fig, axes = plt.subplots(1, 3, figsize=(10, 5.2), constrained_layout=True)
    vmax = max(du[0].max(), du[1].max())
    for ax, data, name in zip(axes[:2], du, ["DEM (static)", "FE (deal.II)"]):
        sc = ax.scatter(x, y, c=data, s=4, cmap="viridis", vmin=0, vmax=vmax)
        ax.set_title(name)
    fig.colorbar(sc, ax=axes[:2], shrink=0.8, label="|u| (um)")
    sd = axes[2].scatter(x, y, c=diff, s=4, cmap="magma")
    axes[2].set_title("|u_DEM - u_FE|")
    fig.colorbar(sd, ax=axes[2], shrink=0.8, label="um")
    for ax in axes:
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
    axes[0].set_ylabel("y (mm)")
    if title:
        fig.suptitle(title)
    fig.savefig(out, dpi=110)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------ signals


def _run_label(run, summary, labels, m):
    return labels[m] if labels else (_beta_label(summary) or os.path.basename(os.path.normpath(run)))


def _grid(n, width=2.9, height=2.9, polar=False):
    cols = min(n, 4)
    rows = (n + cols - 1) // cols
    kw = {"subplot_kw": {"projection": "polar"}} if polar else {}
    # At least 7 in wide: the title and the legend below span the figure.
    fig, axes = plt.subplots(rows, cols, figsize=(max(width * cols + 0.4, 7.0), height * rows + 0.9), squeeze=False,
                             **kw)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, list(axes.flat[:n])


# The stages of a compression test on its curve: (summary key, label, colour).
STAGES = [
    ("crack_initiation_stress_pa", "crack initiation σ_ci", "#2ca02c"),
    ("crack_damage_stress_pa", "crack damage σ_cd", "#9467bd"),
    ("peak_stress_pa", "peak", "#d62728"),
    ("residual_stress_pa", "residual", "#7f7f7f"),
]


def plot_stages(out, run_dirs, labels=None):
    """Stress against axial, lateral and volumetric strain per run, the stages marked: crack initiation, crack
    damage (the reversal of the volumetric strain), peak and residual strength (summary.json)."""
    _check_labels(labels, run_dirs)
    fig, axes = _grid(len(run_dirs), 3.2, 2.9)
    below = 0.6 / fig.get_figheight()  # room for the legend below (rect: left, bottom, width, height)
    fig.set_layout_engine("constrained", rect=(0, below, 1, 0.96 - below))
    dims = set()
    for m, (ax, run) in enumerate(zip(axes, run_dirs)):
        c, s = read_curve(run), read_summary(run)
        dim = s.get("dimension", 2)
        dims.add(dim)
        order = np.argsort(c["strain"], kind="stable")
        stress = 0.5 * (c["stress_top_pa"] + c["stress_bottom_pa"])[order] / 1e6
        ea = c["strain"][order]
        el = c["lateral_strain"][order] if "lateral_strain" in c else np.zeros_like(ea)
        # 3D: the lateral strain is the radial one, the same in both horizontal directions.
        ev = c["volumetric_strain"][order] if "volumetric_strain" in c else ea + (dim - 1) * el
        ax.plot(ea, stress, color="k", lw=1.2)
        ax.plot(el, stress, color="#1f77b4", lw=1.0)
        ax.plot(ev, stress, color="#ff7f0e", lw=1.0)
        ax.axvline(0, color="0.6", lw=0.6)
        for key, _, color in STAGES:
            v = s.get(key)
            if v is None:
                continue
            ax.axhline(v / 1e6, color=color, lw=0.8, ls=":")
            if key == "crack_damage_stress_pa":  # on the volumetric curve, where it turns
                k = int(np.argmin(np.abs(stress - v / 1e6) + (ea > (s.get("strain_at_peak") or np.inf)) * 1e9))
                ax.plot([ev[k]], [stress[k]], marker="o", ms=5, mfc="white", mec=color, mew=1.4, zorder=5)
        title = _run_label(run, s, labels, m)
        ci, cd, peak = s.get("crack_initiation_stress_pa"), s.get("crack_damage_stress_pa"), s.get("peak_stress_pa")
        parts = []
        if peak:
            parts.append(f"peak {peak / 1e6:.1f} MPa")
            parts.append(f"ci {ci / peak:.2f}" if ci is not None else "ci -")
            parts.append(f"cd {cd / peak:.2f}" if cd is not None else "cd -")
        ax.set_title(f"{title}: " + ", ".join(parts), fontsize=8)
        ax.ticklabel_format(axis="x", style="sci", scilimits=(-3, 3))
        ax.tick_params(labelsize=7)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        ax.set_xlabel("strain (-), compression positive", fontsize=7)
        ax.set_ylabel("axial stress (MPa)", fontsize=7)
    handles = [Line2D([0], [0], color="k", lw=1.2, label="axial ε_a"),
               Line2D([0], [0], color="#1f77b4", lw=1.0, label="lateral ε_l"),
               Line2D([0], [0], color="#ff7f0e", lw=1.0,
                      label=" / ".join({2: "volumetric ε_v = ε_a + ε_l", 3: "volumetric ε_v = ε_a + 2 ε_l (3D)"}[d]
                                       for d in sorted(dims)))]
    handles += [Line2D([0], [0], color=col, lw=0.8, ls=":", label=lab) for _, lab, col in STAGES]
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=7, frameon=False)
    fig.suptitle("Stages of the compression test (dotted: stresses of summary.json; ci, cd: as fractions of "
                 "the peak)", fontsize=9)
    fig.savefig(out, dpi=150)
    plt.close(fig)


CLASS_STYLES = [("rock", "tensile", "rock, tensile", "#d62728"), ("rock", "shear", "rock, shear", "#ff7f0e"),
                ("joint", "tensile", "joint, tensile", "#1f77b4"), ("joint", "shear", "joint, shear", "#2ca02c")]


def plot_rose(out, run_dirs, labels=None, bin_deg=10.0):
    """Rose diagram of the crack orientations (the broken edges' angle from the horizontal, cracks.csv
    orientation_deg), stacked by kind and mode, one panel per run; symmetric (an edge at a and at a + 180 is the
    same line)."""
    _check_labels(labels, run_dirs)
    if not (0 < bin_deg <= 90 and abs(180 / bin_deg - round(180 / bin_deg)) < 1e-9):
        raise SystemExit(f"--bin {bin_deg}: give a divisor of 180 deg, e.g. 5, 10 or 15")
    nb = int(round(180 / bin_deg))
    solid = False
    fig, axes = _grid(len(run_dirs), 2.6, 2.8, polar=True)
    below = 0.6 / fig.get_figheight()  # room for the legend below (rect: left, bottom, width, height)
    fig.set_layout_engine("constrained", rect=(0, below, 1, 0.96 - below))
    for m, (ax, run) in enumerate(zip(axes, run_dirs)):
        s = read_summary(run)
        k = results.read_cracks(run)
        solid = solid or "dip_deg" in k
        if "dip_deg" in k:  # 3D: the dip, at 180 - dip for dip directions in [180, 360) (the x-z trace's angle)
            dip = np.asarray(k["dip_deg"], dtype=float)
            ang = np.where(np.asarray(k["dip_direction_deg"], dtype=float) >= 180.0, 180.0 - dip, dip)
        elif "orientation_deg" in k:
            ang = np.asarray(k["orientation_deg"], dtype=float)
        else:
            raise results.RunFolderError(f"{run}: cracks.csv has no orientation_deg column (rerun with this rbdem)")
        kind, mode = np.asarray(k.get("kind", [])), np.asarray(k.get("mode", []))
        # Bins centred on 0, bin, 2 bin, ...: horizontal (0) and vertical (90) edges fall in the middle of a bin.
        edges = np.linspace(0, 180, nb + 1)
        width = np.radians(bin_deg)
        bottom = np.zeros(2 * nb)
        for kd, md, _, color in CLASS_STYLES:
            sel = ang[(kind == kd) & (mode == md)] if ang.size else ang
            h, _ = np.histogram(np.mod(sel + 0.5 * bin_deg, 180.0), bins=edges)
            h2 = np.concatenate([h, h])  # the same line at a + 180
            theta = np.radians(np.concatenate([edges[:-1], edges[:-1] + 180.0]))
            ax.bar(theta, h2, width=width, bottom=bottom, color=color, edgecolor="white", lw=0.3)
            bottom += h2
        ax.set_title(f"{_run_label(run, s, labels, m)}: {ang.size} cracks", fontsize=8)
        ax.set_xticks(np.radians(np.arange(0, 360, 45)))
        ax.tick_params(labelsize=6)
    handles = [Line2D([0], [0], color=col, lw=6, label=lab) for _, _, lab, col in CLASS_STYLES]
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=7, frameon=False)
    what = "the broken edges' angle" if not solid else "the broken faces' dip (3D; 180 - dip for dip directions 180-360)"
    fig.suptitle(f"Crack orientations: {what} from the horizontal ({bin_deg:g}° bins)", fontsize=9)
    fig.savefig(out, dpi=150)
    plt.close(fig)


def plot_crack_rate(out, run_dirs, labels=None):
    """Cracks per unit axial strain (crack_rate.csv) against the axial strain over the strain at the peak, one
    line per run: the acoustic-emission-like record of the test."""
    _check_labels(labels, run_dirs)
    fig, ax = plt.subplots(figsize=(6.4, 4.6), constrained_layout=True)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for m, run in enumerate(run_dirs):
        s = read_summary(run)
        r = results.read_crack_rate(run)
        at = s.get("strain_at_peak") or 0.0
        if not at or r["cracks"].size == 0:
            continue
        mid = 0.5 * (r["strain_low"] + r["strain_high"]) / at
        rate = np.where(r["crack_rate_per_strain"] > 0, r["crack_rate_per_strain"], np.nan)
        ax.step(mid, rate, where="mid", color=colors[m % len(colors)], lw=1.2,
                label=f"{_run_label(run, s, labels, m)}: {int(r['cracks'].sum())} cracks")
    ax.axvline(1.0, color="0.4", lw=0.8, ls="--")
    ax.set_yscale("log")
    ax.set_xlabel("axial strain / strain at the peak (-)")
    ax.set_ylabel("cracks per unit axial strain")
    ax.set_title("Crack rate (50 strain bins per run; dashed: the peak)", fontsize=10)
    _finish_runs_figure(fig, ax, out)


def plot_fragments(out, run_dirs, labels=None):
    """Fragment size distribution at the end of each run (fragments.csv): the number of fragments with an area
    of at least A against A over the specimen's area, log-log."""
    _check_labels(labels, run_dirs)
    fig, ax = plt.subplots(figsize=(6.4, 4.6), constrained_layout=True)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for m, run in enumerate(run_dirs):
        s = read_summary(run)
        f = results.read_fragments(run)
        fraction = f["volume_fraction"] if "volume_fraction" in f else f["area_fraction"]  # 3D: volumes
        if fraction.size == 0:
            continue
        a = np.sort(fraction)[::-1]
        n = np.arange(1, a.size + 1)
        ax.step(a, n, where="post", color=colors[m % len(colors)], lw=1.2,
                label=f"{_run_label(run, s, labels, m)}: {a.size} fragments, largest {a[0]:.2f}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("fragment area (3D: volume) / specimen area (volume) (-)")
    ax.set_ylabel("fragments at least this large")
    ax.set_title("Fragments at the end of the run (blocks joined by intact bonds)", fontsize=10)
    _finish_runs_figure(fig, ax, out)


def main(argv=None):
    p = argparse.ArgumentParser(prog="rbdem_figures.py", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog="How to read each figure: docs/outputs.md")
    sub = p.add_subparsers(dest="figure", required=True)

    s = sub.add_parser("stress-strain", help="stress-strain curves of runs (both platens, MPa), peak marked")
    s.add_argument("out")
    s.add_argument("runs", nargs="+", metavar="RUN_DIR")
    s.add_argument("--labels", nargs="+", help="one legend label per run (default: beta from summary.json)")

    s = sub.add_parser("strength", help="peak strength versus dip from a sweep table, Jaeger dashed")
    s.add_argument("out")
    s.add_argument("table", metavar="TABLE.csv")
    s.add_argument("--group", help="column whose values split the rows into curves")

    s = sub.add_parser("cracks", help="deformed blocks and cracks of one run (the paper's Figure 9)")
    s.add_argument("out")
    s.add_argument("run", metavar="RUN_DIR")
    s.add_argument("--at", choices=["peak", "final", "both"], default="final")
    s.add_argument("--magnify", type=float, default=1.0, help="scale block displacements by this (default 1)")

    s = sub.add_parser("crack-grid", help="crack maps of several runs side by side, at the final frame")
    s.add_argument("out")
    s.add_argument("runs", nargs="+", metavar="RUN_DIR")
    s.add_argument("--labels", nargs="+", help="one title per run (default: beta from summary.json)")
    s.add_argument("--magnify", type=float, default=1.0, help="scale block displacements by this (default 1)")

    for name, text in (("stages", "stress against axial, lateral and volumetric strain, the stages marked"),
                       ("rose", "rose diagrams of the crack orientations by kind and mode"),
                       ("crack-rate", "cracks per unit strain against strain (acoustic-emission-like)"),
                       ("fragments", "fragment size distribution at the end of each run")):
        s = sub.add_parser(name, help=text)
        s.add_argument("out")
        s.add_argument("runs", nargs="+", metavar="RUN_DIR")
        s.add_argument("--labels", nargs="+", help="one label per run (default: beta from summary.json)")
        if name == "rose":
            s.add_argument("--bin", type=float, default=10.0, help="bin width in deg, a divisor of 180 (default 10)")

    s = sub.add_parser("fields", help="DEM and FE block displacements side by side (rbdem verify)")
    s.add_argument("out")
    s.add_argument("csv", metavar="FIELDS.csv")
    s.add_argument("--title")

    s = sub.add_parser("tensile", help="Brazilian tensile strength versus layer angle from a sweep table")
    s.add_argument("out")
    s.add_argument("table", metavar="TABLE.csv")
    s = sub.add_parser("envelope", help="sigma_1 against sigma_3 per dip from a confined sweep, Jaeger dashed")
    s.add_argument("out")
    s.add_argument("table", metavar="TABLE.csv")
    s.add_argument("envelope", metavar="ENVELOPE.csv")
    s = sub.add_parser("elastic-fields", help="DEM and the FE model with the joints side by side (rbdem elastic --fields)")
    s.add_argument("out")
    s.add_argument("elastic_json", metavar="ELASTIC.json")
    s.add_argument("--beta", type=float, help="dip to show (default: where the two fields differ most)")

    s = sub.add_parser("batch", help="several figures in one process, N at a time (rbdem's study reports)")
    s.add_argument("list", metavar="LIST.jsonl", help="one figure per line: its arguments as a JSON list of strings")
    s.add_argument("--jobs", type=int, default=1, help="figures drawn at once, one process each (default 1)")

    a = p.parse_args(argv)
    if a.figure == "batch":
        return run_batch(a.list, a.jobs)
    t0 = time.perf_counter()
    out_dir = os.path.dirname(os.path.abspath(a.out))
    os.makedirs(out_dir, exist_ok=True)
    if a.figure == "stress-strain":
        plot_stress_strain(a.out, a.runs, a.labels)
    elif a.figure == "strength":
        plot_strength(a.out, a.table, a.group)
    elif a.figure == "cracks":
        plot_cracks(a.out, a.run, a.at, a.magnify)
    elif a.figure == "fields":
        plot_fields(a.out, a.csv, a.title)
    elif a.figure == "tensile":
        plot_tensile(a.out, a.table)
    elif a.figure == "envelope":
        plot_envelope(a.out, a.table, a.envelope)
    elif a.figure == "stages":
        plot_stages(a.out, a.runs, a.labels)
    elif a.figure == "rose":
        plot_rose(a.out, a.runs, a.labels, a.bin)
    elif a.figure == "crack-rate":
        plot_crack_rate(a.out, a.runs, a.labels)
    elif a.figure == "fragments":
        plot_fragments(a.out, a.runs, a.labels)
    elif a.figure == "elastic-fields":
        plot_elastic_fields(a.out, a.elastic_json, a.beta)
    else:
        plot_crack_grid(a.out, a.runs, a.labels, a.magnify)
    print(f"wrote {a.out} ({time.perf_counter() - t0:.2f} s)")
    return 0


def _draw_one(argv):
    """One figure of a batch: (its output file, None when drawn or the reason it was not)."""
    out = argv[1] if len(argv) > 1 else "?"
    try:
        main(argv)
        return out, None
    except SystemExit as e:  # argparse's errors and the figures' own refusals
        return out, str(e.code) if e.code not in (None, 0) else None
    except Exception as e:  # noqa: BLE001 - a batch reports each figure's failure and goes on
        return out, f"{type(e).__name__}: {e}"


def run_batch(list_path, jobs=1):
    """Draws the figures of LIST (one JSON list of arguments per line), `jobs` at a time in forked workers, which
    share this process's imports (matplotlib takes about 0.3 s to import). Prints `drawn OUT` or `failed OUT:
    reason` per figure in list order; exit status 1 if any failed."""
    with open(list_path, encoding="utf-8") as f:
        figures = [json.loads(line) for line in f if line.strip()]
    if not all(isinstance(a, list) and all(isinstance(x, str) for x in a) for a in figures):
        raise SystemExit(f"{list_path}: each line must be a JSON list of strings (a figure's arguments)")
    jobs = max(1, min(jobs, len(figures)))
    done = None  # stays None where the figures are drawn one at a time
    if jobs > 1:
        import multiprocessing

        # The slowest kinds first (polar bars and crack maps take 1-2 s), so that none is left to draw alone at the end.
        slow = {"rose": 0, "crack-grid": 1, "cracks": 1}
        start = sorted(range(len(figures)), key=lambda k: slow.get(figures[k][0] if figures[k] else "", 2))
        try:
            with multiprocessing.get_context("fork").Pool(jobs) as pool:
                drawn = pool.map(_draw_one, [figures[k] for k in start], chunksize=1)
            done = [result for _, result in sorted(zip(start, drawn))]
        except OSError:  # no worker processes here (no /dev/shm for their semaphores, say): one at a time
            pass
    if done is None:
        done = [_draw_one(a) for a in figures]
    for out, why in done:
        print(f"drawn {out}" if why is None else f"failed {out}: {why}")
    return 1 if any(why is not None for _, why in done) else 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except ImportError as e:  # h5py is imported where a figure needs result.h5
        _missing_module(e)
    except results.RunFolderError as e:  # a run folder without the file a figure needs: one line, exit status 1
        sys.exit(str(e))
