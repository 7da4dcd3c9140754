"""rbdem.Simulation: a model built from a scene without running it, its state, its boundaries, and runs of a built-in
or Python protocol through the same driver as the command line (docs/python.md, "Scripting a simulation").

    sim = rbdem.Simulation(beta=60, overrides={"mesh.size": 0.003})
    platens = sim.add_platens(velocity=0.01)        # the top platen closes at 1 cm/s
    sim.step(1000)
    sim.blocks["position"], sim.bonds["normal_force"], sim.contacts["force"]
    r = rbdem.Simulation(beta=60).run("ucs")         # the same result as `rbdem ucs --beta 60`

The state tables are copies (NumPy arrays made on each access): reading them never disturbs a run, and writing
into them changes nothing in the model.
"""
from __future__ import annotations

import json
import numbers
import os
from typing import TYPE_CHECKING, Any, Callable, Iterable, Mapping, Optional, Sequence, Union

from . import _rbdem

if TYPE_CHECKING:
    import numpy as np

PathLike = Union[str, "os.PathLike[str]"]


class Protocol:
    """A test written in Python, run by `Simulation.run(protocol)` through the shared driver: the same curve, peak,
    cracks, frames, watchdog, checkpoints, summary and run folder as a built-in test.

    Subclass it and override what the test needs; every hook receives the Simulation:
      prepare(sim)   install the boundaries (sim.add_platens, add_jacket, add_group); called on a fresh run and
                     on a resumed one alike
      start(sim)     once before the first explicit step of a fresh run (not on resume)
      step(sim)      every `every` steps, after the step and its records: change the boundaries
      done(sim)      every `every` steps: True ends the test
      read(sim)      optional, after each step: (strain, stress_pa) for the curve and the peak; by default the
                     platens' closure over the height and their mean stress (zeros without platens)
      results(sim)   after the run: {"name": number} for summary.json's own values
    Attributes: name (summary.json's "test"), every (steps between step() and done(); 1 by default), max_steps (the
    most explicit steps; required).

    What the protocol keeps between steps should live in the simulation's boundaries (a platen's servo, a group's
    velocity), so that a run resumed from its checkpoint goes on the same.
    """

    name: str = ""
    every: int = 1
    max_steps: int = 0

    def prepare(self, sim: "Simulation") -> None:
        pass

    def start(self, sim: "Simulation") -> None:
        pass

    def step(self, sim: "Simulation") -> None:
        pass

    def done(self, sim: "Simulation") -> bool:
        return False

    def results(self, sim: "Simulation") -> Optional[Mapping[str, float]]:
        return None


class _Hooks:
    """What the compiled driver calls: the protocol's hooks with the Simulation as their argument."""

    def __init__(self, protocol: Protocol, sim: "Simulation"):
        self._p, self._sim = protocol, sim
        self.name = protocol.name or type(protocol).__name__.lower()
        every = getattr(protocol, "every", 1)
        if isinstance(every, bool) or not isinstance(every, numbers.Integral) or every < 1:
            raise _rbdem.SceneError(f"Protocol.every = {every!r}: give the steps between step() calls, an integer >= 1")
        max_steps = getattr(protocol, "max_steps", 0)
        if isinstance(max_steps, bool) or not isinstance(max_steps, numbers.Integral) or max_steps < 1:
            raise _rbdem.SceneError(f"Protocol.max_steps = {max_steps!r}: give the most explicit steps the test may "
                                    "take, an integer >= 1")
        self.every, self.max_steps = int(every), int(max_steps)
        self.reads = callable(getattr(protocol, "read", None))

    def install(self):
        self._p.prepare(self._sim)

    def start(self):
        self._p.start(self._sim)

    def control(self):
        self._p.step(self._sim)

    def done(self):
        return bool(self._p.done(self._sim))

    def read(self):
        v = self._p.read(self._sim)
        return None if v is None else (float(v[0]), float(v[1]))

    def results(self):
        v = self._p.results(self._sim)
        return None if v is None else [(str(k), float(x)) for k, x in dict(v).items()]


def _layer_ids(sim: "Simulation", layer) -> list:
    """Layer ids from a name or id, or several."""
    names = sim.specimen["layer_names"]
    wanted = [layer] if isinstance(layer, (str, numbers.Integral)) else list(layer)
    ids = []
    for w in wanted:
        if isinstance(w, str):
            if w not in names:
                raise _rbdem.SceneError(f"layer '{w}': the specimen's layers are {', '.join(names)}")
            ids.append(names.index(w))
        else:
            ids.append(int(w))
    return ids


def _block_list(sim: "Simulation", blocks=None, *, layer=None, box=None) -> list:
    """The blocks chosen by index, by layer (a name or id, or several) or by box ((xmin, ymin), (xmax, ymax)) of
    the reference centroids; several criteria intersect."""
    np_ = __import__("numpy")
    b = sim.blocks
    keep = np_.ones(len(b["layer"]), dtype=bool)
    chosen = blocks is not None or layer is not None or box is not None
    if not chosen:
        raise _rbdem.SceneError("a group needs its blocks: give blocks=[indices], layer='layer_1' (or several) "
                                "or box=((xmin, ymin), (xmax, ymax))")
    if blocks is not None:
        idx = np_.asarray(blocks, dtype=np_.int64).ravel()
        if idx.size and (idx.min() < 0 or idx.max() >= keep.size):
            raise _rbdem.SceneError(f"blocks: indices must be in 0..{keep.size - 1}")
        mask = np_.zeros_like(keep)
        mask[idx] = True
        keep &= mask
    if layer is not None:
        keep &= np_.isin(b["layer"], _layer_ids(sim, layer))
    if box is not None:
        lo, hi = np_.asarray(box[0], dtype=float), np_.asarray(box[1], dtype=float)
        x = b["reference_position"]
        keep &= np_.all((x >= lo) & (x <= hi), axis=1)
    out = np_.flatnonzero(keep).tolist()
    if not out:
        raise _rbdem.SceneError("the group's choice of blocks selects none: check blocks=, layer= and box=")
    return out


class Simulation:
    """A model of one scene, built without running it (docs/python.md, "Scripting a simulation").

    Simulation(scene=None, *, beta=None, overrides=None, mesh=None, force=False): the scene as for rbdem.ucs() (a
    TOML file, a dict or None for the built-in paper scene); mesh: a gmsh .msh file instead of meshing (mesh.file).

    State (copies, NumPy arrays; positions and vectors are (n, dim) arrays, rotations (n,) in 2D):
      blocks    position, rotation, velocity, angular_velocity, force, moment (of the last step), reference_position,
                area (2D) or volume, mass, layer
      bonds     i, j, kind ("rock"/"joint"), material, size, intact, point, normal (from i to j), force and moment
                (on block j), normal_force (tension positive), shear_force, failure_index (1 at the strength), damage
      contacts  i, j, point, normal, force (on block j), normal_force (compression positive), shear_force
    time, steps, dt (set it to fix the time step; otherwise numerics.dt or dt_safety times the stability limit of
    the model and its boundaries), energies(), cracks (the crack log as arrays).

    Boundaries: add_platens(), add_jacket(), add_group(); each one's readings(); every change made through them
    between steps is recorded in `controls`.
    """

    def __init__(self, scene=None, *, beta: Optional[float] = None, overrides: Optional[Mapping[str, Any]] = None,
                 mesh: Optional[PathLike] = None, force: bool = False):
        from . import _scene_args, _beta
        sets = dict(overrides or {})
        if mesh is not None:
            sets = {"mesh.file": os.fspath(mesh), **sets}
        file, keys, flat = _scene_args(scene, sets)
        self._core = _rbdem.Simulation(file, keys, _beta(beta), flat, force)
        #: Every change to a boundary made through this object: (step, time_s, boundary, setting, value).
        self.controls: list = []

    # --- the model ---
    @property
    def scene(self) -> str:
        """The resolved scene as TOML text."""
        return self._core.scene_toml

    @property
    def dimension(self) -> int:
        return self._core.dimension

    @property
    def specimen(self) -> dict:
        """dimension, lo and hi (the bounding box, m), thickness (m), layer_names, blocks, bonds."""
        return self._core.specimen

    # --- stepping ---
    def step(self, n: int = 1) -> None:
        """n explicit steps (Ctrl-C stops between chunks of 1000). Raises InstabilityError when the state blows up."""
        if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 0:
            raise _rbdem.SceneError(f"step(n={n!r}): give the number of steps, an integer >= 0")
        self._core.step(int(n))

    @property
    def time(self) -> float:
        return self._core.time

    @property
    def steps(self) -> int:
        return self._core.steps

    @property
    def dt(self) -> float:
        return self._core.dt

    @dt.setter
    def dt(self, value: float) -> None:
        self._core.dt = float(value)

    def stability_limit(self) -> float:
        """2 / sqrt(lambda_max) of the intact model with its boundaries: the largest stable time step (s)."""
        return self._core.stability_limit()

    def energies(self) -> dict:
        """kinetic_j, strain_j, damping_j, friction_j, work_j (J, the last three cumulative)."""
        return self._core.energies()

    # --- state ---
    @property
    def blocks(self) -> dict:
        return self._core.blocks()

    @property
    def bonds(self) -> dict:
        return self._core.bonds()

    @property
    def contacts(self) -> dict:
        return self._core.contacts()

    @property
    def cracks(self) -> dict:
        """The crack log so far, as the cracks.csv columns (docs/outputs.md)."""
        return dict(self._core.cracks())

    def lateral_strain(self) -> float:
        """-(width change) / width from the side blocks that still hold a bond (compression positive)."""
        return self._core.lateral_strain()

    # --- boundaries ---
    def add_platens(self, velocity: float = 0.0, friction: float = 0.0) -> "Platens":
        """Two rigid platens on the top and bottom faces; the top one closes at `velocity` (m/s) or under a servo
        (Platens.set_servo); the bottom one is fixed. friction: Coulomb coefficient with the blocks."""
        return Platens(self, self._core.add_platens(float(velocity), float(friction)))

    def add_jacket(self, pressure: float) -> "Jacket":
        """A confining pressure (Pa) on the outer faces that are not on a platen, as a membrane applies it."""
        return Jacket(self, self._core.add_jacket(float(pressure)))

    def add_group(self, name: str = "group", blocks: Optional[Iterable[int]] = None, *, layer=None, box=None,
                  mode: str = "fixed", value: Optional[Sequence[float]] = None, modes: Optional[Sequence[str]] = None,
                  servo: Optional[Mapping[str, float]] = None) -> "Group":
        """Blocks chosen by index, layer or box (reference centroids), held `fixed`, moved at a `velocity` (value:
        vx, vy [m/s], omega [rad/s]) or loaded by a constant `force` on each block (fx, fy [N], moment [N m]).

        modes: one mode per degree of freedom (x, y, rotation) instead of `mode`, among "fixed", "velocity",
        "servo" and "free" (the blocks then move together as one body): a velocity dof moves at its value, a servo
        dof at clamp(gain (value - stiffness (u - origin) + F), -max_velocity, max_velocity) with F the model's force
        on the group and value the load on the whole group (N), a free dof as one body under F plus its value.
        servo: {"gain": m/s per N, "max_velocity": m/s, "stiffness": N/m (0: a constant load), "origin": m}."""
        chosen = _block_list(self, blocks, layer=layer, box=box)
        dof = 3 if self.dimension == 2 else 6
        vals = [0.0] * dof if value is None else [float(v) for v in value]
        per_dof = [str(m) for m in (modes or [])]
        if (mode != "fixed" or per_dof) and len(vals) != dof:
            raise _rbdem.SceneError(f"value: a {mode} group takes {dof} numbers (x, y and the rotation)")
        sv = dict(servo or {})
        unknown = set(sv) - {"gain", "max_velocity", "stiffness", "origin"}
        if unknown:
            raise _rbdem.SceneError(f"servo: unknown {sorted(unknown)}; give gain, max_velocity, stiffness, origin")
        sv_list = [float(sv.get(k, 0.0)) for k in ("gain", "max_velocity", "stiffness", "origin")] if sv else []
        keep = vals if (mode != "fixed" or per_dof) else []
        try:
            core = self._core.add_group(name, chosen, mode, keep, per_dof, sv_list)
        except ValueError as e:
            raise _rbdem.SceneError(str(e)) from None
        return Group(self, core)

    # --- measurement ---
    def stress(self, *, box=None, circle=None, layers=None, blocks=None, bonds: bool = True, contacts: bool = True,
               boundaries: bool = True) -> "np.ndarray":
        """The Love-Weber average stress (Pa, tension positive, a dim x dim array) of the whole specimen, or of the
        blocks whose centroids lie in box=((xmin, ymin), (xmax, ymax)) or circle=((x, y), radius), or of layers=
        (names or ids) or blocks= (indices). bonds, contacts, boundaries: which forces enter (the whole specimen
        needs the boundaries' loads; an interior region has none). docs/theory.md, "The stress inside the
        specimen"."""
        given = [k for k, v in (("box", box), ("circle", circle), ("layers", layers), ("blocks", blocks))
                 if v is not None]
        if len(given) > 1:
            raise _rbdem.SceneError(f"stress(): give one region, not {' and '.join(given)}")
        kind, lo, hi, radius, ids = "whole", [], [], 0.0, []
        if box is not None:
            kind, lo, hi = "box", [float(v) for v in box[0]], [float(v) for v in box[1]]
        elif circle is not None:
            kind, lo, radius = "circle", [float(v) for v in circle[0]], float(circle[1])
        elif layers is not None:
            kind, ids = "layers", _layer_ids(self, layers)
        elif blocks is not None:
            kind, ids = "blocks", [int(b) for b in blocks]
        try:
            tensor, _, _ = self._core.stress(kind, lo, hi, radius, ids, bonds, contacts, boundaries)
        except ValueError as e:
            raise _rbdem.SceneError(str(e)) from None
        return tensor

    def block_stresses(self, *, bonds: bool = True, contacts: bool = True, boundaries: bool = True) -> "np.ndarray":
        """The Love-Weber stress of every block, an (n, dim, dim) array (Pa, tension positive)."""
        return self._core.block_stresses(bonds, contacts, boundaries)

    def force_network(self) -> dict:
        """The forces between blocks now: one row per intact bond, then one per contact. i, j (blocks), contact
        (False for a bond), force (on block j, (n, dim), N), normal_force (along the normal from i to j, tension
        positive, N). The same network each result.h5 frame stores."""
        return self._core.force_network()

    @property
    def boundaries(self) -> list:
        """The boundaries in the order installed (the order their forces are summed)."""
        wrap = {_rbdem.Platens: Platens, _rbdem.Jacket: Jacket, _rbdem.BlockGroup: Group}
        return [wrap.get(type(b), _Boundary)(self, b) for b in self._core.boundaries()]

    def _record(self, boundary: str, setting: str, value: Any) -> None:
        self.controls.append((self.steps, self.time, boundary, setting, value))

    # --- snapshots ---
    def snapshot(self):
        """The state, boundaries included, to restore() later on this simulation."""
        return self._core.snapshot()

    def restore(self, snapshot) -> None:
        self._core.restore(snapshot)

    # --- runs ---
    def run(self, protocol: Union[str, Protocol], *, out: Optional[PathLike] = None,
            progress: Optional[Callable] = None, resume: bool = False, _interrupt_at_step: int = -1):
        """Runs a test on this (fresh) simulation: a built-in one by name ("ucs", "triaxial", ...) or a Protocol.
        The protocol installs its boundaries. out: the run folder, written as the command line writes it (with
        checkpoint.h5 when interrupted; resume=True continues it on a fresh Simulation of the same scene).
        progress: f(step, strain, stress_pa, peak_pa, cracks) about every 1000 steps. Returns an rbdem.Result;
        raises RunFailed when the watchdog stopped the run, RunInterrupted after Ctrl-C (the checkpoint written
        with out=)."""
        from . import Result, Frame, RunFailed, _numpy
        folder = "" if out is None else os.fspath(out)
        if isinstance(protocol, str):
            raw = self._core.run_builtin(protocol, folder, progress, resume, int(_interrupt_at_step))
        elif isinstance(protocol, Protocol):
            raw = self._core.run_python(_Hooks(protocol, self), folder, progress, resume, int(_interrupt_at_step))
        else:
            raise _rbdem.SceneError(f"run({protocol!r}): give a test's name (e.g. 'ucs') or an rbdem.Protocol")
        crack_cols = dict(raw["cracks"])
        crack_cols["kind"] = _numpy().asarray(crack_cols["kind"], dtype="<U5")
        crack_cols["mode"] = _numpy().asarray(crack_cols["mode"], dtype="<U7")
        result = Result(summary=json.loads(raw["summary_json"]), curve=dict(raw["curve"]), cracks=crack_cols,
                        blocks=dict(raw["blocks"]), frames=[Frame(**f) for f in raw["frames"]],
                        scene=raw["scene_toml"], out=folder or None, elastic_gate=None, seconds=raw["seconds"])
        if not result.completed:
            w = result.summary["watchdog"] or {}
            raise RunFailed(f"run failed: {w.get('message', 'the watchdog stopped it')}", result)
        return result

    def __repr__(self) -> str:
        s = self.specimen
        return (f"<rbdem.Simulation {s['dimension']}D: {s['blocks']} blocks, {s['bonds']} bonds, step {self.steps}, "
                f"t = {self.time:.4g} s, {len(self._core.boundaries())} boundaries>")


class _Boundary:
    """A boundary of a Simulation: its name, work (J, cumulative), energy (J, stored) and readings()."""

    def __init__(self, sim: Simulation, core):
        self._sim, self._core = sim, core

    @property
    def name(self) -> str:
        return self._core.name

    @property
    def work(self) -> float:
        return self._core.work

    @property
    def energy(self) -> float:
        return self._core.energy

    def readings(self) -> dict:
        """Its readings after the last step, with the unit in each name."""
        return self._core.readings()

    def __repr__(self) -> str:
        return f"<rbdem.{type(self).__name__} {self.name}: {self.readings()}>"


class Platens(_Boundary):
    """Top and bottom platens: forces (N, compression positive), closure (m), stress (Pa, their mean)."""

    top_force = property(lambda self: self._core.top_force)
    bottom_force = property(lambda self: self._core.bottom_force)
    closure = property(lambda self: self._core.closure)
    area = property(lambda self: self._core.area)
    velocity = property(lambda self: self._core.velocity)
    stress = property(lambda self: self._core.stress)
    servo_active = property(lambda self: self._core.servo_active)

    def set_velocity(self, velocity: float) -> None:
        """The top platen's closing speed (m/s) from the next step on; ends a servo."""
        self._core.set_velocity(float(velocity))
        self._sim._record(self.name, "velocity", float(velocity))

    def set_servo(self, target_stress: float, gain: float, max_velocity: float) -> None:
        """A servo from the next step on: v = clamp(gain (target - stress), -max_velocity, max_velocity), with the
        mean platen stress of the last step (Pa, compression positive), gain in m/s per Pa."""
        self._core.set_servo(float(target_stress), float(gain), float(max_velocity))
        self._sim._record(self.name, "servo", (float(target_stress), float(gain), float(max_velocity)))


class Jacket(_Boundary):
    """A confining pressure on the free outer faces."""

    pressure = property(lambda self: self._core.pressure)
    faces_lost = property(lambda self: self._core.faces_lost)

    def set_pressure(self, pressure: float) -> None:
        self._core.set_pressure(float(pressure))
        self._sim._record(self.name, "pressure", float(pressure))


class Group(_Boundary):
    """Blocks held fixed, moved at a velocity, loaded by a force, or moved as one body by a servo or freely, each
    dof its own way: blocks, mode, modes, value, force (the reaction or load summed over the group, N and N m),
    displacement (mean, m), velocity (of the last step)."""

    blocks = property(lambda self: self._core.blocks)
    mode = property(lambda self: self._core.mode)
    value = property(lambda self: list(self._core.value))
    force = property(lambda self: list(self._core.force))
    displacement = property(lambda self: list(self._core.displacement))

    modes = property(lambda self: list(self._core.modes))
    velocity = property(lambda self: list(self._core.velocity))

    def set_value(self, value: Sequence[float]) -> None:
        """A new velocity, force or servo load (the mode's numbers, one per dof) from the next step on."""
        v = [float(x) for x in value]
        self._core.set_value(v)
        modes = set(self.modes)
        self._sim._record(self.name, modes.pop() if len(modes) == 1 else "value", tuple(v))

    def set_modes(self, modes: Sequence[str]) -> None:
        """The mode of each dof from the next step on (fixed, velocity, servo, free)."""
        m = [str(x) for x in modes]
        try:
            self._core.set_modes(m)
        except ValueError as e:
            raise _rbdem.SceneError(str(e)) from None
        self._sim._record(self.name, "modes", tuple(m))

    def set_servo(self, gain: float, max_velocity: float, stiffness: float = 0.0, origin: float = 0.0) -> None:
        """The servo of the servo dofs from the next step on (m/s per N, m/s, N/m, m)."""
        args = (float(gain), float(max_velocity), float(stiffness), float(origin))
        try:
            self._core.set_servo(*args)
        except ValueError as e:
            raise _rbdem.SceneError(str(e)) from None
        self._sim._record(self.name, "servo", args)

    def attachment_stiffness(self) -> list:
        """The stiffness of the intact bonds tying the group to the rest of the model, per dof (N/m, N m/rad): what
        a servo on the group pushes against within one step, from which its gain is chosen."""
        return list(self._core.attachment_stiffness())
