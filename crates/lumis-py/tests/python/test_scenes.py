"""Scenes from dicts, and errors that say where they are."""

import numpy as np
import pytest

import lumis

from conftest import SCENES

QUAD_LIT = {
    "seed": 2,
    "film": {"resolution": [16, 12]},
    "camera": {"type": "perspective", "origin": [0, 1, 3], "target": [0, 0, 0], "fov": 40.0},
    "sampler": {"type": "independent", "spp": 2},
    "integrator": {"type": "path", "max_depth": 3},
    "bsdf": [{"name": "white", "type": "diffuse", "reflectance": (0.7, 0.7, 0.7)}],
    "light": [{"type": "point", "position": [0.0, 2.0, 0.0], "intensity": np.array([5.0, 5.0, 5.0])}],
    "shape": [{"type": "quad", "bsdf": "white", "corner": [-2.0, 0.0, 2.0],
               "edge_u": [4.0, 0.0, 0.0], "edge_v": [0.0, 0.0, -4.0]}],
}

QUAD_LIT_TOML = """
seed = 2
[film]
resolution = [16, 12]
[camera]
type = "perspective"
origin = [0, 1, 3]
target = [0, 0, 0]
fov = 40.0
[sampler]
type = "independent"
spp = 2
[integrator]
type = "path"
max_depth = 3
[[bsdf]]
name = "white"
type = "diffuse"
reflectance = [0.7, 0.7, 0.7]
[[light]]
type = "point"
position = [0.0, 2.0, 0.0]
intensity = [5.0, 5.0, 5.0]
[[shape]]
type = "quad"
bsdf = "white"
corner = [-2.0, 0.0, 2.0]
edge_u = [4.0, 0.0, 0.0]
edge_v = [0.0, 0.0, -4.0]
"""


def test_a_dict_renders_as_its_toml(tmp_path):
    path = tmp_path / "quad.toml"
    path.write_text(QUAD_LIT_TOML)
    from_dict = lumis.load_dict(QUAD_LIT, name="quad").render(progress=False)
    from_file = lumis.load_file(path).render(progress=False)
    assert from_dict.image.shape == (12, 16, 3)
    assert from_dict.image.max() > 0
    assert np.array_equal(from_dict.image, from_file.image)
    assert from_dict.seed == 2


def test_a_dicts_error_names_the_value_by_its_subscripts():
    scene = {**QUAD_LIT, "bsdf": [{"name": "white", "type": "diffuse", "reflectance": "grey"}]}
    with pytest.raises(lumis.Error) as raised:
        lumis.load_dict(scene)
    error = raised.value
    assert error.location == 'scene["bsdf"][0]["reflectance"]'
    assert str(error).startswith('scene["bsdf"][0]["reflectance"]: ')
    assert "reflectance" in error.message and error.file is None and error.line is None


def test_a_value_python_cannot_give_is_an_error():
    with pytest.raises(lumis.Error, match=r'scene\["film"\]\["resolution"\]: a object cannot be'):
        lumis.load_dict({**QUAD_LIT, "film": {"resolution": object()}})
    with pytest.raises(lumis.Error, match="is not a string"):
        lumis.load_dict({**QUAD_LIT, "film": {1: 2}})


def test_a_files_error_names_its_file_and_line(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(QUAD_LIT_TOML.replace("max_depth = 3", "max_depth = \"deep\""))
    with pytest.raises(lumis.Error) as raised:
        lumis.load_file(path)
    error = raised.value
    assert error.file == str(path)
    assert error.line == QUAD_LIT_TOML.splitlines().index("max_depth = 3") + 1
    assert "max_depth" in str(error)


def test_an_overrides_error_is_the_command_lines():
    with pytest.raises(lumis.Error, match=r"--set integrator.max_depth=\"deep\""):
        lumis.load_file(SCENES / "cornell-box.toml", **{"integrator.max_depth": "deep"})
    with pytest.raises(lumis.Error, match="cannot read|No such file"):
        lumis.load_file(SCENES / "no-such-scene.toml")
