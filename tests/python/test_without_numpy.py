"""`import rbdem` works in a Python without NumPy (another python3 first on PATH, a bare virtual environment); a
run there says in one line what is missing instead of failing inside the extension module."""
import os
import subprocess
import sys


def test_import_without_numpy_and_a_run_names_what_is_missing(tmp_path):
    fake = tmp_path / "numpy"
    fake.mkdir()
    (fake / "__init__.py").write_text('raise ModuleNotFoundError("No module named numpy", name="numpy")\n')
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(tmp_path), env.get("PYTHONPATH", "")])
    code = (
        "import rbdem\n"
        "print('version', rbdem.__version__)\n"
        "try:\n"
        "    rbdem.ucs(overrides={'mesh.size': 0.005}, skip_elastic_gate=True)\n"
        "except ImportError as e:\n"
        "    print('refused:', e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert "version " in out.stdout
    assert "refused:" in out.stdout and "python3-numpy" in out.stdout, out.stdout
