"""Readers of an rbdem run folder (the --out folder of `rbdem ucs`, `triaxial` or `brazilian`) and of its tables.

    from rbdem import results
    s = results.read_summary("runs/b60")        # summary.json as a dict
    c = results.read_curve("runs/b60")          # curve.csv columns as NumPy arrays (docs/outputs.md)
    k = results.read_cracks("runs/b60")         # cracks.csv columns as NumPy arrays
    f = results.read_fragments("runs/b60")      # fragments.csv: the pieces at the end, largest first
    a = results.read_crack_rate("runs/b60")     # crack_rate.csv: cracks per unit strain, binned
    with results.RunFile("runs/b60") as r:      # result.h5: mesh, bonds, crack log, frames of block positions
        v = r.vertices(r.frame_index("peak"))

Pure Python (NumPy; h5py for result.h5), independent of the compiled module, so that the figure script
(python/rbdem_figures.py) reads runs with the same code in any Python that has NumPy. A folder that lacks a file
raises RunFolderError (a ValueError) naming the folder and the file.
"""
import csv
import json
import math
import os

import numpy as np


class RunFolderError(ValueError):
    """A run folder without the file asked for, or with an empty one."""


def read_csv_rows(path):
    """The rows of a CSV file with a header, as dicts of strings."""
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def to_float(text):
    """A CSV field as a float; NaN for an empty or non-numeric field."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def read_summary(run_dir):
    """summary.json of a run as a dict (from result.h5 when summary.json is absent)."""
    path = os.path.join(run_dir, "summary.json")
    if os.path.exists(path):
        with open(path) as f:
            return json.load(f)
    h5 = os.path.join(run_dir, "result.h5")
    if os.path.exists(h5):
        import h5py

        with h5py.File(h5, "r") as f:
            return json.loads(f["summary"].attrs["json"])
    raise RunFolderError(f"{run_dir}: no summary.json or result.h5 (is it the --out folder of `rbdem ucs`?)")


def read_curve(run_dir):
    """The stress-strain curve as a dict of NumPy arrays (curve.csv columns), from curve.csv or result.h5."""
    path = os.path.join(run_dir, "curve.csv")
    if os.path.exists(path):
        rows = read_csv_rows(path)
        if not rows:
            raise RunFolderError(f"{path}: empty curve")
        return {k: np.array([to_float(r[k]) for r in rows]) for k in rows[0]}
    h5 = os.path.join(run_dir, "result.h5")
    if os.path.exists(h5):
        import h5py

        with h5py.File(h5, "r") as f:
            return {k: np.asarray(v[()], dtype=float) for k, v in f["history"].items()}
    raise RunFolderError(f"{run_dir}: no curve.csv or result.h5")


def read_cracks(run_dir):
    """The crack log as a dict of NumPy arrays (cracks.csv columns; text columns such as kind and mode stay
    strings), empty arrays for a run without cracks."""
    rows, names = _csv_rows(run_dir, "cracks.csv", "")
    columns = {}
    for k in names:
        values = [r[k] for r in rows]
        numbers = [to_float(v) for v in values]
        text = any(v != "" and math.isnan(x) for v, x in zip(values, numbers))
        columns[k] = np.array(values) if text else np.array(numbers, dtype=float)
    return columns


def _csv_rows(run_dir, name, hint):
    """The rows (dicts of text) and the column names of a run's CSV file; RunFolderError naming it when absent."""
    path = os.path.join(run_dir, name)
    if not os.path.exists(path):
        raise RunFolderError(f"{run_dir}: no {name}{hint}")
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        rows = list(reader)
        return rows, reader.fieldnames or []


def _read_numeric_csv(run_dir, name):
    """A run's CSV file of numbers as a dict of float arrays (empty arrays for a file with a header only)."""
    rows, names = _csv_rows(run_dir, name, " (written by rbdem ucs, triaxial and brazilian)")
    return {k: np.array([to_float(r[k]) for r in rows], dtype=float) for k in names}


def read_fragments(run_dir):
    """fragments.csv: the fragments at the end of the run (blocks joined by intact bonds), largest first, as a
    dict of NumPy arrays (fragment, blocks, area_m2, area_fraction, x_m, y_m)."""
    return _read_numeric_csv(run_dir, "fragments.csv")


def read_crack_rate(run_dir):
    """crack_rate.csv: cracks per unit axial strain in strain bins, as a dict of NumPy arrays (strain_low,
    strain_high, cracks, crack_rate_per_strain)."""
    return _read_numeric_csv(run_dir, "crack_rate.csv")


class RunFile:
    """What a crack map needs from result.h5: mesh, bonds, crack log, frames (read lazily)."""

    def __init__(self, run_dir):
        import h5py

        path = os.path.join(run_dir, "result.h5")
        if not os.path.exists(path):
            raise RunFolderError(f"{run_dir}: no result.h5 (written by `rbdem ucs`)")
        self.run_dir = run_dir
        self.file = h5py.File(path, "r")
        f = self.file
        self.summary = json.loads(f["summary"].attrs["json"])
        self.triangles = f["mesh/triangles"][()]
        self.layer = f["mesh/layer"][()]
        self.nodes = f["mesh/nodes"][()]
        self.bond_i = f["bonds/i"][()]
        self.node_a = f["bonds/node_a"][()]
        self.node_b = f["bonds/node_b"][()]
        self.crack_bond = f["cracks/bond"][()]
        self.crack_kind = f["cracks/kind"][()]
        self.crack_mode = f["cracks/mode"][()]
        self.frames = []
        names = sorted(f["frames"].keys())
        for name in names:
            a = f["frames"][name].attrs
            label = a["label"]
            if isinstance(label, bytes):
                label = label.decode()
            self.frames.append(
                {
                    "name": name,
                    "label": str(label),
                    "step": int(a["step"]),
                    "strain": float(a["strain"]),
                    "stress": float(a["stress_pa"]),
                    "cracks": int(a["cracks"]),
                }
            )
        if not self.frames:
            raise RunFolderError(f"{path}: no frames")

    def frame_index(self, at):
        """Index of the frame labelled `at` ('peak' or 'final'); falls back to the highest stress or the last."""
        for k, fr in enumerate(self.frames):
            if fr["label"] == at:
                return k
        if at == "peak":
            return int(np.argmax([fr["stress"] for fr in self.frames]))
        return len(self.frames) - 1

    def vertices(self, k, magnify=1.0):
        """Block vertices (T, 3, 2) at frame k; displacements from the reference scaled by `magnify`."""
        v = self.file["frames"][self.frames[k]["name"]]["vertices"][()].astype(float)
        v = v.reshape(-1, 3, 3)[:, :, :2]
        if magnify != 1.0:
            ref = self.nodes[self.triangles]
            v = ref + magnify * (v - ref)
        return v

    def crack_segments(self, k, verts):
        """The broken bonds' edges up to frame k, end nodes moved with block i: (segments (C, 2, 2), kind, mode)."""
        n = self.frames[k]["cracks"]
        bonds = self.crack_bond[:n]
        i = self.bond_i[bonds]
        tri = self.triangles[i]  # (C, 3) node ids of block i; vertex v of block t is node triangles[t][v]
        ka = np.argmax(tri == self.node_a[bonds][:, None], axis=1)
        kb = np.argmax(tri == self.node_b[bonds][:, None], axis=1)
        seg = np.stack([verts[i, ka], verts[i, kb]], axis=1)
        return seg, self.crack_kind[:n], self.crack_mode[:n]

    def close(self):
        self.file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
