"""Studies from Python: `lumis converge`'s records, and the bias/variance
split of arrays of renders."""

import numpy as np
import pytest

import lumis

from conftest import RESOLUTION

VARIANTS = [
    {"name": "independent", "set": {"sampler.type": "independent"}},
    {"name": "sobol", "set": {"sampler.type": "sobol"}},
]


def small(path, **overrides):
    return lumis.load_file(path, **{"film.resolution": RESOLUTION}, **overrides)


@pytest.fixture
def reference(cornell_box, tmp_path):
    small(cornell_box).render(spp=256, seed=100, progress=False).write(tmp_path / "reference")
    return tmp_path / "reference.exr"


def test_converge_returns_the_studys_records(cornell_box, reference, tmp_path):
    study = lumis.converge(cornell_box, reference, VARIANTS, spp=[1, 4], seeds=2,
                           overrides={"film.resolution": RESOLUTION}, out=tmp_path / "study")
    assert not study.interrupted
    assert len(study.runs) == 2 * 2 * 2 and len(study.points) == 2 * 2
    assert set(study.slopes) == {"independent", "sobol"}
    assert (tmp_path / "study" / "converge.csv").is_file()
    assert "efficiency" in study.table
    # A run is the render Python makes of the same variant, spp and seed.
    run = next(r for r in study.runs if (r["variant"], r["spp"], r["seed"]) == ("sobol", 4, 1))
    render = small(cornell_box, **{"sampler.type": "sobol"}).render(spp=4, seed=1, progress=False)
    assert lumis.diff(render, reference)["rel_mse"] == pytest.approx(run["rel_mse"], rel=1e-12)
    point = next(p for p in study.points if (p["variant"], p["spp"]) == ("sobol", 4))
    assert point["rel_bias2"] + point["rel_variance"] == pytest.approx(point["rel_mse"], rel=1e-9)


def test_a_variants_error_names_the_variant(cornell_box, reference, tmp_path):
    with pytest.raises(lumis.Error, match=r'variants\[0\]\["image"\]'):
        lumis.converge(cornell_box, reference, [{"name": "a", "image": "blurred"}],
                       spp=[1], seeds=1, out=tmp_path / "study")


def test_the_bias_variance_split_adds_up_to_the_mean_error(cornell_box, reference):
    scene = small(cornell_box)
    renders = [scene.render(spp=2, seed=s, progress=False) for s in range(4)]
    split = lumis.bias_variance(renders, reference)
    assert split["renders"] == 4
    mean_mse = np.mean([lumis.diff(r, reference)["mse"] for r in renders])
    assert split["mse"]["total"] == pytest.approx(mean_mse, rel=1e-6)
    assert split["mse"]["bias2"] + split["mse"]["variance"] == pytest.approx(mean_mse, rel=1e-6)
    # An unbiased estimator's squared bias is within noise of zero.
    assert abs(split["mse"]["bias2"]) < 3 * split["mse"]["bias2_se"] + 1e-12
    # Arrays work as well as renders.
    assert lumis.bias_variance([r.image for r in renders], reference) == split
    with pytest.raises(lumis.Error, match="at least 2 renders"):
        lumis.bias_variance(renders[:1], reference)


def test_a_study_becomes_a_dataframe(cornell_box, reference, tmp_path):
    pandas = pytest.importorskip("pandas")
    study = lumis.converge(cornell_box, reference, VARIANTS[:1], spp=[1, 2], seeds=2,
                           overrides={"film.resolution": RESOLUTION}, out=tmp_path / "study")
    frame = study.to_pandas()
    assert isinstance(frame, pandas.DataFrame) and len(frame) == 2
    assert list(study.to_pandas("runs")["seed"]) == [0, 1, 0, 1]
