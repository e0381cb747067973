"""Plugins written in Python: checked by `lumis check-plugin`'s suite,
rendered like built-ins, and an exception in one is an exception at the
render."""

import numpy as np
import pytest

import lumis

from plugins_in_python import Independent, Lambert, PointLight
from test_scenes import QUAD_LIT

lumis.register_bsdf("py-lambert", Lambert, params={"reflectance": {"type": "rgb", "default": [0.5, 0.5, 0.5]}})
lumis.register_light("py-point", PointLight,
                     params={"position": {"type": "vec3"}, "intensity": {"type": "rgb"}})
lumis.register_sampler("py-independent", Independent, params={"spp": 16})

# Few samples and one reflectance: each call into Python takes the GIL.
QUICK = {"samples": 10_000, "bins": 10, "reflectance": [0.5, 0.5, 0.5]}


def with_(scene, **tables):
    return {**scene, **tables}


def test_a_python_bsdf_renders_as_the_builtin(tmp_path):
    direct = {"type": "path", "max_depth": 2}
    builtin = lumis.load_dict(with_(QUAD_LIT, integrator=direct)).render(progress=False)
    python = lumis.load_dict(with_(
        QUAD_LIT, integrator=direct,
        bsdf=[{"name": "white", "type": "py-lambert", "reflectance": [0.7, 0.7, 0.7]}],
        light=[{"type": "py-point", "position": [0.0, 2.0, 0.0], "intensity": [5.0, 5.0, 5.0]}],
    )).render(progress=False)
    # Direct light from a point: the same numbers up to the last bits of
    # Python's double-precision arithmetic.
    assert builtin.image.max() > 0
    assert np.allclose(python.image, builtin.image, rtol=1e-5, atol=1e-7)


def test_a_python_sampler_renders(tmp_path):
    render = lumis.load_dict(with_(QUAD_LIT, sampler={"type": "py-independent", "spp": 4})).render(progress=False)
    assert render.spp == 4 and render.image.max() > 0


def test_a_python_bsdf_passes_the_check_and_a_defective_one_fails(capsys):
    assert lumis.check_plugin("py-lambert", **QUICK)
    assert "py-lambert" in capsys.readouterr().out

    class Defective(Lambert):
        """Samples the cosine, but claims a uniform density."""

        def pdf(self, wo, wi):
            return 1 / (2 * np.pi) if wo[2] > 0 and wi[2] > 0 else 0.0

    lumis.register_bsdf("py-defective", Defective, params={"reflectance": [0.5, 0.5, 0.5]})
    assert not lumis.check_plugin("py-defective", **QUICK)


def test_python_lights_and_samplers_pass_their_checks():
    assert lumis.check_plugin("py-point", position=[0.0, 1.0, 0.0], intensity=[1.0, 1.0, 1.0])
    assert lumis.check_plugin("py-independent")


def test_an_exception_in_a_plugin_is_raised_by_the_render():
    class Failing(Lambert):
        def f(self, wo, wi):
            return 1 / 0

    lumis.register_bsdf("py-failing", Failing, params={"reflectance": [0.5, 0.5, 0.5]})
    scene = lumis.load_dict(with_(QUAD_LIT, bsdf=[{"name": "white", "type": "py-failing"}]))
    with pytest.raises(ZeroDivisionError) as raised:
        scene.render(progress=False)
    notes = getattr(raised.value, "__notes__", [])
    assert any("py-failing" in note and "panicked in Bsdf::" in note for note in notes), notes


def test_a_plugins_parameters_are_checked_as_a_builtins():
    with pytest.raises(lumis.Error, match="reflectance"):
        lumis.load_dict(with_(QUAD_LIT, bsdf=[{"name": "white", "type": "py-lambert", "reflectance": "red"}]))
    with pytest.raises(lumis.Error, match="has no method sample_f"):
        lumis.register_bsdf("py-incomplete", type("Incomplete", (), {"f": None, "pdf": None}))
    with pytest.raises(lumis.Error, match="outside the range"):
        lumis.register_bsdf("py-ranged", Lambert, params={"r": {"type": "float", "default": 2.0, "range": [0, 1]}})
