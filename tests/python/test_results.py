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


def test_curve_csv_and_result_h5_carry_the_same_columns_and_the_signal_files_add_up(tmp_path):
    r = rbdem.ucs(beta=60, overrides=SMALL, out=tmp_path, skip_elastic_gate=True)
    csv_curve = results.read_curve(tmp_path)
    (tmp_path / "curve.csv").rename(tmp_path / "curve.csv.away")
    h5_curve = results.read_curve(tmp_path)  # from result.h5's /history
    assert set(csv_curve) == set(h5_curve) == set(r.curve) - {"stress_pa"}
    for k in csv_curve:
        assert np.allclose(csv_curve[k], h5_curve[k], rtol=1e-5, atol=1e-30), k  # energies keep 6 digits
    assert np.allclose(csv_curve["volumetric_strain"], csv_curve["strain"] + csv_curve["lateral_strain"],
                       rtol=1e-7, atol=1e-15)
    cracks = results.read_cracks(tmp_path)
    assert np.all((cracks["orientation_deg"] >= 0) & (cracks["orientation_deg"] < 180))
    assert np.allclose(cracks["orientation_deg"], r.cracks["orientation_deg"], rtol=1e-5, atol=1e-4)
    f = results.read_fragments(tmp_path)
    assert len(f["area_m2"]) == r.summary["fragments"]["count"] >= 1
    assert np.isclose(f["area_fraction"].sum(), 1.0, rtol=1e-9)
    assert np.isclose(f["area_m2"].sum(), 0.01 * 0.02, rtol=1e-6)  # the blocks tile the specimen
    assert np.all(np.diff(f["area_m2"]) <= 0)
    rate = results.read_crack_rate(tmp_path)
    assert rate["cracks"].sum() == r.summary["cracks"]["total"]
    assert np.allclose(rate["crack_rate_per_strain"] * (rate["strain_high"] - rate["strain_low"]), rate["cracks"])


def test_a_folder_without_the_file_names_it(tmp_path):
    with pytest.raises(results.RunFolderError, match="no summary.json"):
        results.read_summary(tmp_path)
    with pytest.raises(ValueError, match="no cracks.csv"):
        results.read_cracks(tmp_path)
    with pytest.raises(ValueError, match="no fragments.csv"):
        results.read_fragments(tmp_path)
