"""rbdem.results reads a run folder into the arrays a run returns: the readers the figure script uses."""
import numpy as np
import pytest

import rbdem
from rbdem import results

SMALL = {"specimen.width": 0.01, "specimen.height": 0.02, "joint_set.spacing": 0.006, "mesh.size": 0.002,
         "numerics.threads": 1}


def test_the_files_of_a_run_read_back_as_its_result(tmp_path):
    r = rbdem.ucs(beta=60, overrides=SMALL, out=tmp_path, skip_elastic_gate=True)
    assert results.read_summary(tmp_path) == r.summary
    curve = results.read_curve(tmp_path)
    assert curve["strain"].shape == r.curve["strain"].shape
    assert np.allclose(curve["strain"], r.curve["strain"], rtol=1e-8, atol=0)  # curve.csv keeps 9 digits
    cracks = results.read_cracks(tmp_path)
    assert set(cracks) >= {"kind", "mode"}
    assert len(cracks["kind"]) == len(r.cracks["kind"]) > 0
    assert list(cracks["kind"]) == list(r.cracks["kind"])
    with results.RunFile(tmp_path) as f:
        assert f.summary == r.summary
        k = f.frame_index("final")
        assert f.vertices(k).shape == (len(f.triangles), 3, 2)


def test_a_folder_without_the_file_names_it(tmp_path):
    with pytest.raises(results.RunFolderError, match="no summary.json"):
        results.read_summary(tmp_path)
    with pytest.raises(ValueError, match="no cracks.csv"):
        results.read_cracks(tmp_path)
