"""Fixtures of the Python module's tests: the repository's scenes, the
`lumis` command line to compare with, and a small Cornell box."""

import os
import pathlib
import subprocess

import pytest

REPOSITORY = pathlib.Path(__file__).resolve().parents[4]
SCENES = REPOSITORY / "scenes"
# Small enough to render in a fraction of a second in a debug build.
RESOLUTION = [32, 32]


@pytest.fixture
def cornell_box():
    return SCENES / "cornell-box.toml"


@pytest.fixture
def cli(tmp_path):
    """Runs the `lumis` binary `LUMIS_BIN` names (the test harness builds
    it) in `tmp_path`, failing the test with its stderr."""
    binary = os.environ.get("LUMIS_BIN")
    if not binary:
        pytest.skip("LUMIS_BIN is not set: cargo test -p lumis-py sets it")

    def run(*args):
        done = subprocess.run(
            [binary, *map(str, args)], cwd=tmp_path, capture_output=True, text=True
        )
        assert done.returncode == 0, done.stderr
        return done.stdout

    return run
