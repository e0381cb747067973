"""The book's Python walkthrough runs, and shows what it claims."""

import importlib.util

from conftest import REPOSITORY


def test_the_sampler_walkthrough_shows_sobol_ahead_of_independent(monkeypatch):
    path = REPOSITORY / "docs" / "src" / "python" / "sampler_study.py"
    spec = importlib.util.spec_from_file_location("sampler_study", path)
    walkthrough = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(walkthrough)
    # The walkthrough names its scene relative to the repository's root.
    monkeypatch.chdir(REPOSITORY)
    errors = walkthrough.study(spps=(4, 64), seeds=2, resolution=16, reference_spp=1024)
    independent, sobol = errors["independent"], errors["sobol"]
    assert independent[1] < independent[0] / 8  # about 1/16: relMSE ~ 1/spp
    assert sobol[1] < 0.8 * independent[1]
