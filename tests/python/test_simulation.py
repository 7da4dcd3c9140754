"""rbdem.Simulation and rbdem.Protocol (docs/python.md, "Scripting a simulation"): the model's state as arrays, its
boundaries from Python, explicit steps, snapshots, built-in tests equal to the command line's bit for bit, a test
written in Python through the same driver, checkpoint and resume.

CTest runs this within Python.Module (PYTHONPATH=build/python, RBDEM_EXE the rbdem binary of the same build).
"""
import json
import os
import subprocess

import numpy as np
import pytest

import rbdem

# 10 x 20 mm, joints every 6 mm, 2 mm mesh, one thread: about 130 blocks.
SMALL = {"specimen.width": 0.01, "specimen.height": 0.02, "joint_set.spacing": 0.006, "mesh.size": 0.002,
         "numerics.threads": 1}


def without_timing(summary):
    return {k: v for k, v in summary.items() if k != "wall_seconds"}


def test_state_tables_have_the_documented_shapes_and_are_copies():
    sim = rbdem.Simulation(beta=30, overrides=SMALL)
    n, nb = sim.specimen["blocks"], sim.specimen["bonds"]
    b, d, c = sim.blocks, sim.bonds, sim.contacts
    assert b["position"].shape == (n, 2) and b["rotation"].shape == (n,) and b["velocity"].shape == (n, 2)
    assert b["mass"].shape == (n,) and b["layer"].dtype.kind == "i"
    assert d["force"].shape == (nb, 2) and d["intact"].dtype == bool and d["intact"].all()
    assert set(d["kind"]) == {"rock", "joint"}
    assert c["i"].shape == c["j"].shape and c["force"].shape == (len(c["i"]), 2)
    np.testing.assert_array_equal(b["position"], b["reference_position"])  # at rest, as meshed
    b["position"][:] = 0.0  # a copy: the model does not move
    assert np.all(sim.blocks["position"] == sim.blocks["reference_position"])


def test_platens_step_and_read_forces_in_compression():
    sim = rbdem.Simulation(beta=90, overrides=SMALL)
    platens = sim.add_platens(velocity=0.2)
    sim.step(1500)
    assert sim.steps == 1500 and sim.time == pytest.approx(1500 * sim.dt)
    assert platens.closure == pytest.approx(0.2 * sim.time, rel=1e-9)
    assert platens.stress > 0
    bonds = sim.bonds
    vertical = np.abs(bonds["normal"][:, 1]) > 0.95
    assert np.mean(bonds["normal_force"][vertical]) < 0  # tension positive: the column is compressed
    e = sim.energies()
    assert e["work_j"] > 0 and e["strain_j"] > 0
    assert platens.readings()["top_force_n"] == pytest.approx(platens.top_force)


def test_groups_by_layer_box_and_index_and_a_fixed_group_holds():
    sim = rbdem.Simulation(beta=0, overrides=SMALL)
    names = sim.specimen["layer_names"]
    by_layer = sim.add_group("first", layer=names[0])
    assert set(sim.blocks["layer"][by_layer.blocks]) == {0}
    h = sim.specimen["hi"][1]
    top = sim.add_group("top", box=((-1, h - 0.002), (1, 1)), mode="velocity", value=[0.0, -0.05, 0.0])
    assert len(top.blocks) > 0
    sim.step(200)
    moved = sim.blocks["position"][top.blocks] - sim.blocks["reference_position"][top.blocks]
    np.testing.assert_allclose(moved[:, 1], -0.05 * sim.time, rtol=1e-9)
    held = sim.blocks["position"][by_layer.blocks] - sim.blocks["reference_position"][by_layer.blocks]
    assert np.all(held == 0.0)
    top.set_value([0.0, 0.0, 0.0])
    assert sim.controls[-1][2:] == ("top", "velocity", (0.0, 0.0, 0.0))
    with pytest.raises(rbdem.SceneError, match="layer 'nope'"):
        sim.add_group("bad", layer="nope")
    with pytest.raises(rbdem.SceneError, match="selects none"):
        sim.add_group("empty", box=((5, 5), (6, 6)))


def test_snapshot_restores_the_state_bit_for_bit():
    sim = rbdem.Simulation(beta=45, overrides=SMALL)
    sim.add_platens(velocity=0.2)
    sim.step(300)
    snap = sim.snapshot()
    sim.step(300)
    after = sim.blocks["position"]
    sim.restore(snap)
    assert sim.steps == 300
    sim.step(300)
    np.testing.assert_array_equal(sim.blocks["position"], after)


def test_builtin_test_equals_the_command_line_bit_for_bit(tmp_path):
    exe = os.environ.get("RBDEM_EXE")
    if not exe:
        pytest.skip("RBDEM_EXE (the rbdem binary) is not set; CTest sets it")
    r = rbdem.Simulation(beta=60, overrides=SMALL).run("ucs", out=tmp_path / "py")
    sets = sum((["--set", f"{k}={v}"] for k, v in SMALL.items()), [])
    subprocess.run([exe, "ucs", "--beta", "60", *sets, "--skip-elastic-gate", "-q", "--out", str(tmp_path / "cli")],
                   check=True, capture_output=True)
    cli = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert without_timing(r.summary) == without_timing(cli)
    assert (tmp_path / "py" / "curve.csv").read_bytes() == (tmp_path / "cli" / "curve.csv").read_bytes()
    assert (tmp_path / "py" / "cracks.csv").read_bytes() == (tmp_path / "cli" / "cracks.csv").read_bytes()


def test_interrupted_and_resumed_from_python_equals_the_uninterrupted_run(tmp_path):
    whole = rbdem.Simulation(beta=60, overrides=SMALL).run("ucs")
    half = whole.summary["steps"] // 2
    assert half > 10
    with pytest.raises(RuntimeError, match="interrupted at step"):
        rbdem.Simulation(beta=60, overrides=SMALL).run("ucs", out=tmp_path, _interrupt_at_step=half)
    assert (tmp_path / "checkpoint.h5").exists()
    resumed = rbdem.Simulation(beta=60, overrides=SMALL).run("ucs", out=tmp_path, resume=True)
    assert without_timing(resumed.summary) == without_timing(whole.summary)
    assert not (tmp_path / "checkpoint.h5").exists()


def test_a_checkpoint_written_from_python_is_resumed_by_the_command_line(tmp_path):
    """The checkpoint is the command line's: `rbdem ucs --resume` continues it to the uninterrupted run's result."""
    whole = rbdem.Simulation(beta=60, overrides=SMALL).run("ucs")
    with pytest.raises(RuntimeError, match="interrupted at step"):
        rbdem.Simulation(beta=60, overrides=SMALL).run("ucs", out=tmp_path, _interrupt_at_step=whole.summary["steps"] // 3)
    sets = [a for k, v in SMALL.items() for a in ("--set", f"{k}={v}")]
    subprocess.run([os.environ["RBDEM_EXE"], "ucs", "--beta", "60", *sets, "--out", str(tmp_path), "--resume", "-q"],
                   check=True, capture_output=True)
    cli = json.loads((tmp_path / "summary.json").read_text())
    assert without_timing(cli) == without_timing(whole.summary)


class Hold(rbdem.Protocol):
    """Loads to 2 MPa, then holds the platen stress there with the servo."""
    name = "hold_test"
    every = 5
    max_steps = 20000

    def prepare(self, sim):
        self.platens = sim.add_platens(velocity=0.2)

    def step(self, sim):
        if not self.platens.servo_active and self.platens.stress >= 2e6:
            self.platens.set_servo(2e6, gain=2e-8, max_velocity=0.2)

    def done(self, sim):
        return self.platens.servo_active and sim.steps >= 6000

    def results(self, sim):
        return {"held_stress_pa": self.platens.stress}


def test_a_protocol_written_in_python_runs_through_the_shared_driver(tmp_path):
    sim = rbdem.Simulation(beta=60, overrides=SMALL)
    r = sim.run(Hold(), out=tmp_path)
    s = r.summary
    assert s["test"] == "hold_test" and s["stop_reason"] == "protocol" and s["steps"] == 6000
    assert s["held_stress_pa"] == pytest.approx(2e6, rel=0.01)
    assert len(r.curve["stress_pa"]) > 10
    for name in ("summary.json", "curve.csv", "cracks.csv", "result.h5", "scene.toml"):
        assert (tmp_path / name).exists()
    assert [c[2:4] for c in sim.controls] == [("platens", "servo")]
    with pytest.raises(rbdem.SceneError, match="fresh Simulation"):
        sim.run("ucs")


def test_an_exception_in_a_hook_stops_the_run_and_is_raised():
    class Broken(Hold):
        def step(self, sim):
            if sim.steps > 50:
                raise ValueError("my protocol's own error")

    with pytest.raises(ValueError, match="my protocol's own error"):
        rbdem.Simulation(beta=60, overrides=SMALL).run(Broken())

    class Steps(Hold):
        def step(self, sim):
            sim.step(1)

    with pytest.raises(RuntimeError, match="inside a run"):
        rbdem.Simulation(beta=60, overrides=SMALL).run(Steps())


def test_bad_protocol_attributes_are_refused():
    class NoLimit(rbdem.Protocol):
        pass

    with pytest.raises(rbdem.SceneError, match="max_steps"):
        rbdem.Simulation(overrides=SMALL).run(NoLimit())
    with pytest.raises(rbdem.SceneError, match="give a test's name"):
        rbdem.Simulation(overrides=SMALL).run(42)
    with pytest.raises(rbdem.SceneError, match="unknown test"):
        rbdem.Simulation(overrides=SMALL).run("nope")


def test_love_weber_stress_of_the_whole_specimen_is_the_platen_stress():
    sim = rbdem.Simulation(beta=90, overrides=SMALL)
    platens = sim.add_platens(velocity=0.005)  # slow: the stress wave has crossed the specimen many times
    sim.step(6000)  # to about 10 MPa, elastic
    assert sim.cracks["bond"].size == 0
    s = sim.stress()
    assert s.shape == (2, 2) and s[0, 1] == s[1, 0]
    assert s[1, 1] == pytest.approx(-platens.stress, rel=0.02)  # tension positive
    h = sim.specimen["hi"][1]
    inner = sim.stress(box=((0.002, 0.25 * h), (0.008, 0.75 * h)), boundaries=False)
    assert inner[1, 1] < 0
    per_block = sim.block_stresses()
    assert per_block.shape == (sim.specimen["blocks"], 2, 2)
    area = sim.blocks["area"]
    np.testing.assert_allclose((per_block * area[:, None, None]).sum(axis=0) / area.sum(), s, rtol=1e-9, atol=1e-3)
    with pytest.raises(rbdem.SceneError):
        sim.stress(box=((0, 0), (1, 1)), layers=[0])


def test_force_network_has_every_intact_bond_then_every_contact():
    sim = rbdem.Simulation(beta=0, overrides=SMALL)
    sim.add_platens(velocity=0.2)
    sim.step(1000)
    n, bonds, contacts = sim.force_network(), sim.bonds, sim.contacts
    intact = int(bonds["intact"].sum())
    assert len(n["i"]) == intact + len(contacts["i"])
    assert not n["contact"][:intact].any() and n["contact"][intact:].all()
    np.testing.assert_allclose(n["normal_force"][:intact], bonds["normal_force"][bonds["intact"]], rtol=1e-6, atol=1e-3)


def test_a_servo_group_brings_its_reaction_to_the_load():
    sim = rbdem.Simulation(beta=0, overrides=SMALL)
    sim.add_group("base", box=((-1, -1), (1, 0.0015)))
    top = sim.add_group("top", box=((-1, 0.0185), (1, 1)), modes=["fixed", "servo", "fixed"],
                        value=[0.0, -2e4, 0.0], servo={"gain": 1e-12, "max_velocity": 1.0})
    top.set_servo(gain=0.2 / (top.attachment_stiffness()[1] * sim.dt), max_velocity=1.0)
    assert top.modes == ["fixed", "servo", "fixed"]
    sim.step(4000)
    assert top.force[1] == pytest.approx(2e4, rel=1e-3)  # the specimen pushes back with the load
    assert top.displacement[1] < 0
    assert sim.controls[-1][2:4] == ("top", "servo")


def test_shear_from_python_equals_the_command_line(tmp_path):
    sets = {"specimen.width": 0.02, "specimen.height": 0.02, "mesh.size": 0.002, "numerics.threads": 1}
    r = rbdem.shear(normal_stress=5e6, overrides=sets, skip_elastic_gate=True)
    args = [a for k, v in sets.items() for a in ("--set", f"{k}={v}")]
    subprocess.run([os.environ["RBDEM_EXE"], "shear", "--normal-stress", "5e6", *args, "--skip-elastic-gate", "-q",
                    "--out", str(tmp_path)], check=True, capture_output=True)
    cli = json.loads((tmp_path / "summary.json").read_text())
    assert without_timing(r.summary) == without_timing(cli)
    assert r.summary["test"] == "shear" and r.summary["residual_shear_stress_pa"] > 0


def test_a_3d_cylinder_has_the_same_tables_in_three_components():
    sim = rbdem.Simulation(beta=60, overrides={"specimen.dimension": 3, "mesh.size": 0.01, "numerics.threads": 1})
    assert sim.dimension == 3
    n, nb = sim.specimen["blocks"], sim.specimen["bonds"]
    b, d = sim.blocks, sim.bonds
    assert b["position"].shape == (n, 3) and b["rotation"].shape == (n, 3) and d["force"].shape == (nb, 3)
    platens = sim.add_platens(velocity=0.2)
    sim.step(300)
    assert platens.stress > 0 and platens.closure == pytest.approx(0.2 * sim.time, rel=1e-9)
    vertical = np.abs(sim.bonds["normal"][:, 2]) > 0.95
    assert np.mean(sim.bonds["normal_force"][vertical]) < 0  # the cylinder is compressed along z


def test_hilbert_block_order_holds_the_same_blocks_with_neighbours_next_to_each_other():
    """mesh.block_order = "hilbert" (docs/performance.md, "The order of the blocks"): the same blocks and bonds,
    numbered so that consecutive blocks lie side by side."""
    as_meshed = rbdem.Simulation(beta=30, overrides={**SMALL, "mesh.size": 0.001})
    curve = rbdem.Simulation(beta=30, overrides={**SMALL, "mesh.size": 0.001, "mesh.block_order": "hilbert"})
    a, c = as_meshed.blocks["position"], curve.blocks["position"]
    assert curve.specimen["blocks"] == as_meshed.specimen["blocks"]
    assert curve.specimen["bonds"] == as_meshed.specimen["bonds"]
    np.testing.assert_array_equal(a[np.lexsort(a.T)], c[np.lexsort(c.T)])
    step = lambda p: np.mean(np.linalg.norm(np.diff(p, axis=0), axis=1))  # noqa: E731
    assert step(c) < 0.5 * step(a), (step(c), step(a))
