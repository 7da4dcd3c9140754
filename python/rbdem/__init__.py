"""rbdem from Python: rigid-block DEM tests of layered (transversely isotropic) rock.

    import rbdem
    r = rbdem.ucs(beta=60)                               # the paper specimen at a joint dip of 60 deg
    r.summary["peak_stress_pa"]                          # the summary.json of `rbdem ucs`, as a dict
    r.curve["strain"], r.curve["stress_pa"]              # the stress-strain curve, NumPy arrays
    rbdem.triaxial("my.toml", confining=10e6, overrides={"mesh.size": 0.002}, out="runs/t60")
    rbdem.brazilian({"joint_set": {"dip_deg": 30}})

The same library functions as the rbdem command run underneath (not the executable), with the same checks and
messages: bad input raises SceneError (a ValueError) naming the key and the fix; the elastic gate runs before a
failure run as on the command line (skip_elastic_gate=True skips it). docs/python.md is the reference.

Scenes: a TOML file (str or os.PathLike), a dict (nested {"rock": {"cohesion": 7e6}} and/or dotted
{"rock.cohesion": 7e6}) or None for the built-in paper scene. overrides= works as the command line's --set.
SI units throughout (m, Pa, s, J); angles in degrees.
"""
from __future__ import annotations

import json
import os
import tempfile
from dataclasses import dataclass, field
import numbers
import sys
from typing import TYPE_CHECKING, Any, Callable, Mapping, Optional, Union

from . import _rbdem

if TYPE_CHECKING:
    import numpy as np


def _numpy():
    """NumPy, imported where arrays are made, so that `import rbdem` works in a Python without it."""
    try:
        import numpy
    except ImportError as e:
        raise ImportError(f"rbdem's results are NumPy arrays, and {sys.executable} cannot import numpy ({e}): "
                          "apt-get install python3-numpy, or run Debian's /usr/bin/python3") from e
    return numpy

__all__ = [
    "ucs", "triaxial", "brazilian", "shear", "cyclic", "hold", "resolve_scene", "elastic_gate", "verify", "verify_cases", "sweep",
    "scene_keys", "version", "__version__", "Result", "Frame", "GateReport", "SceneError", "ElasticGateError",
    "RunFailed", "InstabilityError", "Simulation", "Protocol", "Platens", "Jacket", "Group",
]

#: Bad input: an unknown key, a value out of range or of the wrong type, a scene unfit for the test, an output
#: folder that cannot be written. A ValueError; the message names the key (or file) and the fix.
SceneError = _rbdem.SceneError

#: The elastic gate refused the scene (the command line's exit status 3). A RuntimeError whose message holds the
#: gate's table and what to do; skip_elastic_gate=True runs anyway.
ElasticGateError = _rbdem.ElasticGateFailed


#: Simulation.step() found a position or velocity no longer finite: the time step is too large for the scene.
InstabilityError = _rbdem.InstabilityError


class RunFailed(RuntimeError):
    """The watchdog stopped the run (non-finite state or energy from nowhere; the command line's exit status 1).

    `result` holds what was recorded up to the last sound state (summary["completed"] is False, the headline
    numbers are None); with out= those files were written as the command line writes them.
    """

    def __init__(self, message: str, result: "Result"):
        super().__init__(message)
        self.result = result


def version() -> str:
    """The version of the library, with the git commit it was built from ("0.2.0+abc1234")."""
    return _rbdem.version()


__version__ = version()

Scene = Union[None, str, "os.PathLike[str]", Mapping[str, Any]]
Progress = Callable[[int, float, float, float, int], Any]


def _text(origin: str, key: str, value: Any) -> str:
    """A scene value as the text the scene reader parses: floats in full precision (repr round-trips)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return repr(float(value))
    if isinstance(value, (str, os.PathLike)):
        return os.fspath(value)
    raise SceneError(f"{origin}: {key} = {value!r} has the wrong type ({type(value).__name__}): give a number, "
                     "a bool or a string (SI units)")


def _flatten(origin: str, mapping: Mapping[str, Any], prefix: str = "") -> list:
    """(origin, "section.key", text) for a nested and/or dotted dict, in its order."""
    if not isinstance(mapping, Mapping):
        raise SceneError(f"{origin}: expected a dict such as {{'rock.cohesion': 7e6}}, got {type(mapping).__name__}")
    keys = []
    for k, v in mapping.items():
        if not isinstance(k, str):
            raise SceneError(f"{origin}: key {k!r} is not a string: use 'section.key', e.g. 'rock.cohesion'")
        key = prefix + k
        if isinstance(v, Mapping):
            keys += _flatten(origin, v, key + ".")
        else:
            keys.append((origin, key, _text(origin, key, v)))
    return keys


def _scene_args(scene: Scene, overrides: Optional[Mapping[str, Any]]):
    """(file, scene keys, overrides) for the binding."""
    if scene is None:
        file, keys = "", []
    elif isinstance(scene, (str, os.PathLike)):
        file, keys = os.fspath(scene), []
        if not file:
            raise SceneError("scene: an empty file name; give a TOML scene file, a dict or None (the built-in scene)")
    elif isinstance(scene, Mapping):
        file, keys = "", _flatten("scene", scene)
    else:
        raise SceneError(f"scene: expected a TOML file name, a dict or None, got {type(scene).__name__}")
    return file, keys, _flatten("overrides", overrides or {})


def _beta(beta: Optional[float]) -> Optional[float]:
    if beta is None:
        return None
    if isinstance(beta, bool) or not isinstance(beta, numbers.Real):
        raise SceneError(f"beta={beta!r}: expected the joint dip in degrees (joint_set.dip_deg, 0..90)")
    return float(beta)


def resolve_scene(scene: Scene = None, *, beta: Optional[float] = None,
                  overrides: Optional[Mapping[str, Any]] = None, force: bool = False) -> str:
    """The resolved scene as TOML text (what scene.toml of a run holds), checked as a run would check it.

    Raises SceneError for a bad key or value.
    """
    file, keys, sets = _scene_args(scene, overrides)
    return _rbdem.resolve_scene(file, keys, _beta(beta), sets, force)


@dataclass
class Frame:
    """Block positions at one instant: every output.frame_strain_interval of axial strain, at the peak and at the end.

    x_m, y_m: block centroids [m]; theta_rad: block rotations [rad] (one entry per block, the order of
    Result.blocks); label: "", "elastic_start", "peak" or "final"; cracks: the number of cracks logged by then
    (Result.cracks rows [0, cracks)).
    """
    step: int
    time_s: float
    strain: float
    stress_pa: float
    label: str
    cracks: int
    x_m: np.ndarray
    y_m: np.ndarray
    theta_rad: np.ndarray


@dataclass
class Result:
    """One test's results (docs/python.md, "Result").

    summary   the summary.json dict, exactly as the command line writes it (docs/outputs.md)
    curve     dict of NumPy arrays, the curve.csv columns: step [-], time_s [s], strain [-], stress_top_pa and
              stress_bottom_pa [Pa], stress_pa [Pa, their mean], kinetic_j and strain_energy_j [J],
              broken_rock_tensile, broken_rock_shear, broken_joint_tensile, broken_joint_shear [count],
              lateral_strain, volumetric_strain [-]
    cracks    dict of NumPy arrays, the cracks.csv columns: time_s [s], strain [-], x_m, y_m [m], normal_x,
              normal_y [-], length_m [m], kind ("rock" | "joint"), mode ("tensile" | "shear"), bond [index],
              sigma_pa, tau_pa [Pa], orientation_deg [deg]
    blocks    dict of NumPy arrays of the blocks as meshed: x_m, y_m [m], area_m2 [m^2], mass_kg [kg], layer
    frames    list of Frame (block positions during the run)
    scene     the resolved scene as TOML text (scene.toml); scene_dict is the same as a dict
    out       the folder the files were written to, or None
    elastic_gate  the gate's verdict (status, from_cache, summary, note, key), or None when skipped
    """
    summary: dict
    curve: dict
    cracks: dict
    blocks: dict
    frames: list
    scene: str
    out: Optional[str] = None
    elastic_gate: Optional[dict] = None
    seconds: float = 0.0
    _raw: Any = field(default=None, repr=False)

    @property
    def scene_dict(self) -> dict:
        """The resolved scene as a nested dict (summary.json's "scene")."""
        return self.summary["scene"]

    @property
    def completed(self) -> bool:
        return bool(self.summary["completed"])

    @property
    def final_positions(self) -> np.ndarray:
        """(blocks, 3) array of the last frame: x [m], y [m], rotation [rad]."""
        f = self.frames[-1]
        return _numpy().column_stack([f.x_m, f.y_m, f.theta_rad])

    def __repr__(self) -> str:
        s = self.summary
        peak = s.get("peak_stress_pa")
        return (f"<rbdem.Result {s['test']} beta={s['beta_deg']:g} deg: peak "
                f"{'-' if peak is None else f'{peak / 1e6:.2f} MPa'}, {s['cracks']['total']} cracks, "
                f"{s['failure_mode']}, {s['blocks']} blocks>")


def _run(test: str, scene: Scene, beta, overrides, out, skip_elastic_gate: bool, force: bool,
         progress: Optional[Progress]) -> Result:
    if progress is not None and not callable(progress):
        raise TypeError(f"progress={progress!r} is not callable: give f(step, strain, stress, peak, cracks)")
    _numpy()  # before the run, so a Python without NumPy is told so rather than losing the run's result
    file, keys, sets = _scene_args(scene, overrides)
    folder = "" if out is None else os.fspath(out)
    if out is not None and not folder:
        raise SceneError("out: an empty folder name; give a folder, or out=None to write nothing")
    raw = _rbdem.run(test, file, keys, _beta(beta), sets, force, skip_elastic_gate, folder, progress)
    crack_cols = dict(raw["cracks"])
    crack_cols["kind"] = _numpy().asarray(crack_cols["kind"], dtype="<U5")
    crack_cols["mode"] = _numpy().asarray(crack_cols["mode"], dtype="<U7")
    result = Result(summary=json.loads(raw["summary_json"]), curve=dict(raw["curve"]), cracks=crack_cols,
                    blocks=dict(raw["blocks"]), frames=[Frame(**f) for f in raw["frames"]],
                    scene=raw["scene_toml"], out=folder or None, elastic_gate=raw["elastic_gate"],
                    seconds=raw["seconds"])
    if not result.completed:
        w = result.summary["watchdog"] or {}
        raise RunFailed(f"run failed: {w.get('message', 'the watchdog stopped it')}"
                        + (f" (results up to the last sound state in {folder})" if folder else ""), result)
    return result


def ucs(scene: Scene = None, *, beta: Optional[float] = None, overrides: Optional[Mapping[str, Any]] = None,
        out: Union[None, str, "os.PathLike[str]"] = None, skip_elastic_gate: bool = False, force: bool = False,
        progress: Optional[Progress] = None) -> Result:
    """One uniaxial compression test, as `rbdem ucs`.

    scene     TOML file, dict of keys, or None (the built-in paper scene, = scenes/paper.toml)
    beta      joint dip [deg] (joint_set.dip_deg; the command line's --beta)
    overrides {"section.key": value}, applied last (the command line's --set)
    out       folder for summary.json, curve.csv, cracks.csv, scene.toml, result.h5, result.xdmf; None: no files
    skip_elastic_gate  run even when the elastic gate fails (--skip-elastic-gate); the gate is cached per scene
    force     skip the likely-unit-mistake check (--force)
    progress  f(step, strain, stress_pa, peak_pa, cracks), called about every 1000 steps with the GIL held

    Raises SceneError (bad input), ElasticGateError, RunFailed, KeyboardInterrupt (Ctrl-C stops the run cleanly).
    """
    return _run("ucs", scene, beta, overrides, out, skip_elastic_gate, force, progress)


def triaxial(scene: Scene = None, *, beta: Optional[float] = None, confining: Optional[float] = None,
             overrides: Optional[Mapping[str, Any]] = None, out: Union[None, str, "os.PathLike[str]"] = None,
             skip_elastic_gate: bool = False, force: bool = False, progress: Optional[Progress] = None) -> Result:
    """One confined (triaxial) compression test, as `rbdem triaxial`.

    confining  sigma_3 [Pa] (loading.confining_pressure; the command line's --confining); None keeps the scene's.
    The other arguments as ucs().
    """
    sets = dict(overrides or {})
    if confining is not None:
        # First, as the command line puts --confining before the --set options.
        sets = {"loading.confining_pressure": confining, **sets}
    return _run("triaxial", scene, beta, sets, out, skip_elastic_gate, force, progress)


def brazilian(scene: Scene = None, *, beta: Optional[float] = None, overrides: Optional[Mapping[str, Any]] = None,
              out: Union[None, str, "os.PathLike[str]"] = None, skip_elastic_gate: bool = False, force: bool = False,
              progress: Optional[Progress] = None) -> Result:
    """One Brazilian test of a disc, as `rbdem brazilian` (specimen.shape = "disc" is set). Arguments as ucs()."""
    return _run("brazilian", scene, beta, overrides, out, skip_elastic_gate, force, progress)


def _with(sets: Optional[Mapping[str, Any]], **keys) -> dict:
    """The keyword shorthands first (as the command line puts its options before --set), then the overrides."""
    return {**{k: v for k, v in keys.items() if v is not None}, **dict(sets or {})}


def shear(scene: Scene = None, *, normal_stress: Optional[float] = None, normal_stiffness: Optional[float] = None,
          overrides: Optional[Mapping[str, Any]] = None, out: Union[None, str, "os.PathLike[str]"] = None,
          skip_elastic_gate: bool = False, force: bool = False, progress: Optional[Progress] = None) -> Result:
    """Direct shear of one joint, as `rbdem shear` (docs/model.md): the upper half pushed along the joint at
    loading.shear_velocity under a constant normal stress (CNL), or one that grows with the dilation (CNS).

    normal_stress     sigma_n [Pa] (loading.normal_stress; --normal-stress)
    normal_stiffness  k [Pa/m] of a CNS test (loading.normal_stiffness; --normal-stiffness); 0 = CNL
    The other arguments as ucs(). summary holds the peak and residual shear stress and the dilation.
    """
    sets = _with(overrides, **{"loading.normal_stress": normal_stress, "loading.normal_stiffness": normal_stiffness})
    return _run("shear", scene, None, sets, out, skip_elastic_gate, force, progress)


def cyclic(scene: Scene = None, *, beta: Optional[float] = None, confining: Optional[float] = None,
           overrides: Optional[Mapping[str, Any]] = None, out: Union[None, str, "os.PathLike[str]"] = None,
           skip_elastic_gate: bool = False, force: bool = False, progress: Optional[Progress] = None) -> Result:
    """Loading and unloading cycles, as `rbdem cyclic` (docs/model.md): uniaxial, or confined at `confining` [Pa];
    the per-cycle moduli, loop energies and cracks in summary["cycles"]. The other arguments as ucs()."""
    sets = _with(overrides, **{"loading.confining_pressure": confining})
    return _run("cyclic", scene, beta, sets, out, skip_elastic_gate, force, progress)


def hold(scene: Scene = None, *, beta: Optional[float] = None, hold_stress: Optional[float] = None,
         confining: Optional[float] = None, overrides: Optional[Mapping[str, Any]] = None,
         out: Union[None, str, "os.PathLike[str]"] = None, skip_elastic_gate: bool = False, force: bool = False,
         progress: Optional[Progress] = None) -> Result:
    """A hold at constant axial stress by the platen servo, as `rbdem hold`: hold_stress [Pa]
    (loading.hold_stress; --hold-stress), confining [Pa] as triaxial(). The other arguments as ucs()."""
    sets = _with(overrides, **{"loading.hold_stress": hold_stress, "loading.confining_pressure": confining})
    return _run("hold", scene, beta, sets, out, skip_elastic_gate, force, progress)


@dataclass
class GateReport:
    """The elastic gate over beta = 0, 15, ..., 90 deg (docs/elastic.md).

    passed; comparison (what decided: "fe_joints", "fe_joints_linear" or "amadei"); max_deviation (max |E_dem /
    E_ref - 1|, -) at worst_beta_deg; tolerance (elastic.tolerance); message, reason (why it failed); table (the
    printed table); json (the elastic.json dict).
    """
    passed: bool
    comparison: str
    max_deviation: float
    worst_beta_deg: float
    tolerance: float
    message: str
    reason: str
    table: str
    json: dict


def elastic_gate(scene: Scene = None, *, overrides: Optional[Mapping[str, Any]] = None,
                 out: Union[None, str, "os.PathLike[str]"] = None, fields: bool = False,
                 force: bool = False) -> GateReport:
    """The elastic gate, as `rbdem elastic`: measures it afresh (never from the cache) and stores the verdict in the
    gate's cache, so a later run of the scene need not repeat it. out: folder for elastic.json; fields: keep the
    block displacements per dip in the json. Returns a GateReport (a failed gate is a result here, not an error).
    """
    file, keys, sets = _scene_args(scene, overrides)
    raw = _rbdem.elastic_gate(file, keys, sets, force, "" if out is None else os.fspath(out), fields)
    raw = dict(raw)
    raw["json"] = json.loads(raw["json"])
    return GateReport(**raw)


def verify_cases() -> list:
    """The verification cases of this build as (name, quick) pairs; quick ones run in verify(quick=True)."""
    return [tuple(c) for c in _rbdem.verify_cases()]


def verify(quick: bool = True, only: Optional[str] = None,
           out: Union[None, str, "os.PathLike[str]"] = None) -> dict:
    """Every check of this build against theory, as `rbdem verify [--quick] [--only REGEX]`: returns the
    verify.json dict (cases[] with verdict, error, tolerance, seconds). out: folder for verify.json and verify.md
    (without the figures the command line adds); None: a temporary folder, removed afterwards.
    """
    if out is None:
        with tempfile.TemporaryDirectory(prefix="rbdem-verify-") as tmp:
            return json.loads(_rbdem.verify(quick, only or "", tmp))
    return json.loads(_rbdem.verify(quick, only or "", os.fspath(out)))


def sweep(study: Union[str, "os.PathLike[str]"], *, out: Union[str, "os.PathLike[str]"],
          overrides: Optional[Mapping[str, Any]] = None, workers: int = 0, skip_elastic_gate: bool = False,
          force: bool = False) -> list:
    """A parameter study, as `rbdem sweep STUDY --out OUT` in this process (no MPI): one folder per case,
    table.csv, groups.csv, timing.csv, report.md (envelope.csv for a confined study). A rerun skips complete cases.
    overrides change the study's base scene (--set); workers: cases at once (0 = all cores).
    Returns one dict per case: id, group, beta_deg, reused, summary (its summary.json).
    """
    sets = _flatten("overrides", overrides or {})
    cases = _rbdem.sweep(os.fspath(study), sets, os.fspath(out), workers, skip_elastic_gate, force)
    return [{"id": c["id"], "group": c["group"], "beta_deg": c["beta_deg"], "reused": c["reused"],
             "summary": json.loads(c["summary_json"])} for c in cases]


def scene_keys() -> list:
    """Every scene key as (key, unit, description), in file order (`rbdem --help-scene`)."""
    return [tuple(k) for k in _rbdem.scene_keys()]


# rbdem.Simulation and rbdem.Protocol (python/rbdem/simulation.py): last, since they use the helpers above.
from .simulation import Group, Jacket, Platens, Protocol, Simulation  # noqa: E402
