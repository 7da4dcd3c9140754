"""The Python module against the rbdem command: same summary, same checks, arrays as documented (docs/python.md).

CTest runs this as Python.Module (python/CMakeLists.txt) with PYTHONPATH=build/python and RBDEM_EXE the rbdem
binary of the same build. A small scene keeps each run well under a second.
"""
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import rbdem

# The small scene of the tests: 10 x 20 mm, joints every 6 mm, 2 mm mesh, one thread, loaded from rest (no static
# elastic start) so that the run takes some thousand steps and the progress hook is called.
SMALL = {"specimen.width": 0.01, "specimen.height": 0.02, "joint_set.spacing": 0.006, "mesh.size": 0.002,
         "numerics.threads": 1, "numerics.elastic_start": False}
SMALL_TOML = """\
[specimen]
width = 0.01
height = 0.02
[joint_set]
spacing = 0.006
[mesh]
size = 0.002
[numerics]
threads = 1
elastic_start = false
"""
# Keys of summary.json that measure time, not the physics: the wall time of the run. Everything else must agree
# bit for bit between two runs of one scene.
TIMING_KEYS = {"wall_seconds"}


def without_timing(summary):
    return {k: v for k, v in summary.items() if k not in TIMING_KEYS}


def rbdem_exe():
    exe = os.environ.get("RBDEM_EXE")
    if not exe:
        pytest.skip("RBDEM_EXE (the rbdem binary) is not set; CTest sets it")
    return exe


@pytest.fixture(scope="module")
def small_toml(tmp_path_factory):
    path = tmp_path_factory.mktemp("scene") / "small.toml"
    path.write_text(SMALL_TOML)
    return path


@pytest.fixture(scope="module")
def small_run(tmp_path_factory, small_toml):
    out = tmp_path_factory.mktemp("py") / "run"
    calls = []
    r = rbdem.ucs(small_toml, beta=60, out=out, skip_elastic_gate=True, progress=lambda *a: calls.append(a))
    return r, out, calls


def test_version_is_the_commands(small_toml):
    p = subprocess.run([rbdem_exe(), "--version"], capture_output=True, text=True, check=True)
    assert rbdem.__version__ == rbdem.version()
    assert rbdem.__version__ in p.stdout


def test_same_summary_and_files_as_the_command_line(tmp_path, small_toml, small_run):
    r, out, _ = small_run
    cli_out = tmp_path / "cli"
    subprocess.run([rbdem_exe(), "ucs", str(small_toml), "--beta", "60", "-q", "--skip-elastic-gate", "--out",
                    str(cli_out)], check=True, capture_output=True)
    cli = json.loads((cli_out / "summary.json").read_text())
    py_file = json.loads((out / "summary.json").read_text())
    # The returned summary is the one written; both are the command line's except the timing.
    assert r.summary == py_file
    assert without_timing(r.summary) == without_timing(cli)
    assert set(r.summary) == set(cli)
    for name in ("curve.csv", "cracks.csv", "scene.toml"):
        assert (out / name).read_bytes() == (cli_out / name).read_bytes(), name
    assert r.scene == (cli_out / "scene.toml").read_text()


def test_dict_scene_gives_the_toml_scene(small_run):
    r, _, _ = small_run
    nested = {"specimen": {"width": 0.01, "height": 0.02}, "joint_set": {"spacing": 0.006},
              "mesh.size": 0.002, "numerics": {"threads": 1, "elastic_start": False}}
    d = rbdem.ucs(nested, beta=60, skip_elastic_gate=True)
    assert without_timing(d.summary) == without_timing(r.summary)
    assert d.scene == r.scene
    dotted = rbdem.resolve_scene(SMALL, beta=60)
    assert dotted == r.scene


def test_arrays_have_the_documented_shapes_and_units(small_run):
    r, out, _ = small_run
    s = r.summary
    rows = (out / "curve.csv").read_text().splitlines()
    header = rows[0].split(",")
    n = len(rows) - 1
    for col in header:
        assert r.curve[col].shape == (n,), col
    table = np.loadtxt(out / "curve.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(r.curve["strain"], table[:, header.index("strain")], rtol=1e-8)
    np.testing.assert_allclose(r.curve["stress_top_pa"], table[:, header.index("stress_top_pa")], rtol=1e-8)
    assert np.array_equal(r.curve["stress_pa"], 0.5 * (r.curve["stress_top_pa"] + r.curve["stress_bottom_pa"]))
    # Pa and strain, not MPa or percent: the peak is tens of MPa at strains of 1e-4.
    assert 1e6 < s["peak_stress_pa"] <= r.curve["stress_pa"].max() * (1 + 1e-12)
    assert 0 < r.curve["strain"].max() < s["scene"]["loading"]["max_strain"] + 1e-12
    assert r.curve["step"].dtype.kind == "i"
    crack_rows = (out / "cracks.csv").read_text().splitlines()
    assert len(crack_rows) - 1 == s["cracks"]["total"] > 0
    # The Python record is the crack table (dem/records.hpp) as cracks.csv writes it: the same fields, no other.
    assert set(r.cracks) == set(crack_rows[0].split(","))
    for col in crack_rows[0].split(","):
        assert len(r.cracks[col]) == s["cracks"]["total"], col
    assert set(np.unique(r.cracks["kind"])) <= {"rock", "joint"}
    assert set(np.unique(r.cracks["mode"])) <= {"tensile", "shear"}
    assert np.sum(r.cracks["kind"] == "joint") == s["cracks"]["joint_tensile"] + s["cracks"]["joint_shear"]
    nb = s["blocks"]
    assert r.blocks["x_m"].shape == (nb,) and r.blocks["mass_kg"].shape == (nb,)
    # Metres, in the specimen's frame (the blocks span the 10 x 20 mm specimen; cracks lie between blocks).
    x, y = r.blocks["x_m"], r.blocks["y_m"]
    assert 0.006 < x.max() - x.min() < 0.01 and 0.016 < y.max() - y.min() < 0.02
    assert (r.cracks["x_m"] >= x.min() - 0.002).all() and (r.cracks["x_m"] <= x.max() + 0.002).all()
    assert (r.cracks["y_m"] >= y.min() - 0.002).all() and (r.cracks["y_m"] <= y.max() + 0.002).all()
    np.testing.assert_allclose(r.blocks["area_m2"].sum(), 0.01 * 0.02, rtol=1e-9)
    assert r.frames[-1].label == "final" and any(f.label == "peak" for f in r.frames)
    assert r.final_positions.shape == (nb, 3)
    assert r.scene_dict["joint_set"]["dip_deg"] == 60


def test_progress_is_called_with_the_run_state(small_run):
    r, _, calls = small_run
    assert len(calls) >= 1
    steps = [c[0] for c in calls]
    assert steps == sorted(steps) and steps[-1] <= r.summary["steps"]
    step, strain, stress, peak, cracks = calls[-1]
    assert isinstance(cracks, int) and 0 < strain < 0.01 and 0 <= stress <= peak * (1 + 1e-12)


def test_an_exception_in_the_callback_stops_the_run():
    class Stop(Exception):
        pass

    def cb(*_):
        raise Stop()

    with pytest.raises(Stop):
        rbdem.ucs(SMALL, skip_elastic_gate=True, progress=cb)


@pytest.mark.parametrize("call, key", [
    (lambda: rbdem.ucs(overrides={"rock.cohesio": 7e6}), "rock.cohesio"),
    (lambda: rbdem.ucs({"rock": {"cohesio": 7e6}}), "rock.cohesio"),
    (lambda: rbdem.ucs(overrides={"rock.cohesion": -1.0}), "rock.cohesion"),
    (lambda: rbdem.ucs(overrides={"numerics.threads": 1.5}), "numerics.threads"),
    (lambda: rbdem.ucs(overrides={"rock.cohesion": [1, 2]}), "rock.cohesion"),
    (lambda: rbdem.ucs(beta=95), "joint_set.dip_deg"),
    (lambda: rbdem.ucs(overrides={"rock.tensile_strength": 200e9}), "rock.tensile_strength"),
    (lambda: rbdem.ucs(overrides={"loading.confining_pressure": 5e6}), "loading.confining_pressure"),
    (lambda: rbdem.triaxial(confining=-1.0), "loading.confining_pressure"),
    (lambda: rbdem.ucs("no/such/scene.toml"), "no/such/scene.toml"),
])
def test_bad_input_raises_a_value_error_naming_the_key(call, key):
    with pytest.raises(rbdem.SceneError) as e:
        call()
    assert isinstance(e.value, ValueError)
    assert key in str(e.value)


def test_the_message_is_the_command_lines(tmp_path):
    with pytest.raises(rbdem.SceneError) as e:
        rbdem.ucs(overrides={"rock.cohesio": 7e6})
    p = subprocess.run([rbdem_exe(), "ucs", "--set", "rock.cohesio=7e6", "--out", str(tmp_path)],
                       capture_output=True, text=True)
    assert p.returncode == 2
    # The command says "--set: unknown key ...", the module "overrides: unknown key ..."; the rest is the same.
    assert str(e.value).removeprefix("overrides: ") in p.stderr
    assert "did you mean 'rock.cohesion'" in str(e.value)


def test_out_none_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = rbdem.ucs(SMALL, skip_elastic_gate=True)
    assert r.out is None and list(tmp_path.iterdir()) == []


def test_triaxial_and_brazilian_set_their_keys():
    t = rbdem.triaxial(SMALL, beta=30, confining=2e6, skip_elastic_gate=True)
    assert t.summary["test"] == "triaxial" and t.summary["confining_pressure_pa"] == 2e6
    assert t.summary["deviator_at_peak_pa"] == pytest.approx(t.summary["peak_stress_pa"] - 2e6)
    b = rbdem.brazilian({**SMALL, "specimen.diameter": 0.02}, beta=30, skip_elastic_gate=True)
    assert b.summary["test"] == "brazilian" and b.summary["scene"]["specimen"]["shape"] == "disc"
    assert b.summary["tensile_strength_pa"] > 0


def test_the_elastic_gate_runs_first_and_reports(tmp_path):
    r = rbdem.ucs(SMALL, beta=60)
    assert r.elastic_gate is not None and r.elastic_gate["status"] in ("passed", "failed")
    g = rbdem.elastic_gate(SMALL, out=tmp_path)
    assert g.passed == (r.elastic_gate["status"] == "passed")
    assert json.loads((tmp_path / "elastic.json").read_text())["gate"]["passed"] == g.passed
    assert [a["beta_deg"] for a in g.json["angles"]] == [0, 15, 30, 45, 60, 75, 90]


def test_a_failed_gate_raises():
    # A tolerance no measurement meets: the gate fails whatever the DEM does.
    tight = {**SMALL, "elastic.tolerance": 1e-9}
    with pytest.raises(rbdem.ElasticGateError, match="skip_elastic_gate=True"):
        rbdem.ucs(tight)


def test_verify_runs_the_selected_cases(tmp_path):
    names = [n for n, quick in rbdem.verify_cases() if quick]
    assert names
    v = rbdem.verify(quick=True, only="^" + names[0].replace(".", r"\.") + "$", out=tmp_path)
    assert [c["name"] for c in v["cases"]] == [names[0]]
    assert (tmp_path / "verify.json").exists() and (tmp_path / "verify.md").exists()
    with pytest.raises(rbdem.SceneError, match="only="):
        rbdem.verify(only="no-such-case")


INTERRUPT_SCRIPT = """
import sys, time, rbdem
def progress(step, strain, stress, peak, cracks):
    if step >= 1000 and not hasattr(progress, 'told'):
        progress.told = True
        print('running', flush=True)
try:
    rbdem.ucs(beta=60, overrides={'numerics.threads': 1, 'numerics.elastic_start': False}, skip_elastic_gate=True,
              progress=progress)
except KeyboardInterrupt:
    print('KeyboardInterrupt', flush=True)
    sys.exit(130)
print('finished', flush=True)
"""


def test_ctrl_c_stops_a_run_with_keyboard_interrupt():
    # The default 1 mm specimen from rest: minutes of stepping, so only Ctrl-C ends it within the test.
    p = subprocess.Popen([sys.executable, "-c", INTERRUPT_SCRIPT], stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "running"
        t0 = time.monotonic()
        p.send_signal(signal.SIGINT)
        out, _ = p.communicate(timeout=30)
        assert "KeyboardInterrupt" in out and p.returncode == 130
        assert time.monotonic() - t0 < 10
    finally:
        if p.poll() is None:
            p.kill()


# tests/data/tiny_study.toml at two dips: 4 cases of a fraction of a second.
SMALL_STUDY = """\
[study]
name = "tiny"
base = ""
dips = [60, 90]
[study.set]
"mesh.size" = 0.005
[[axis]]
name = "joint_cohesion"
labels = ["low", "high"]
[axis.set]
"joint.cohesion" = { of = "rock.cohesion", factors = [0.5, 0.7] }
"""


def test_sweep_gives_the_command_lines_table(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text(SMALL_STUDY)
    subprocess.run([rbdem_exe(), "sweep", str(study), "--out", str(tmp_path / "cli"), "-q", "-j", "1",
                    "--skip-elastic-gate"], check=True, capture_output=True)
    cases = rbdem.sweep(study, out=tmp_path / "py", workers=1, skip_elastic_gate=True)
    assert len(cases) == 4 and not any(c["reused"] for c in cases)
    for name in ("table.csv", "groups.csv"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    assert (tmp_path / "py" / "report.md").exists()
    again = rbdem.sweep(study, out=tmp_path / "py", workers=1, skip_elastic_gate=True)
    assert all(c["reused"] for c in again)
    assert [c["summary"] for c in again] == [c["summary"] for c in cases]
    with pytest.raises(rbdem.SceneError, match="rock.cohesio"):
        rbdem.sweep(study, out=tmp_path / "bad", overrides={"rock.cohesio": 1e6})
