"""Ctrl-C stops a render cleanly and keeps the passes it finished."""

import os
import signal

import pytest

import lumis

from conftest import RESOLUTION


def test_ctrl_c_raises_interrupted_with_the_passes_done(cornell_box):
    scene = lumis.load_file(cornell_box, **{"film.resolution": RESOLUTION})
    spp = 256

    def interrupt_after_two_passes(done, total):
        # Called on the rendering thread's caller, the main thread, where
        # Python runs its signal handlers: SIGINT is Ctrl-C.
        if done >= 2 * total // spp:
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(lumis.Interrupted) as raised:
        scene.render(spp=spp, pass_spp=1, progress=interrupt_after_two_passes)
    assert isinstance(raised.value, KeyboardInterrupt)
    render = raised.value.render
    assert render is not None and render.interrupted
    assert 1 <= render.spp < spp
    assert render.image.shape == (32, 32, 3)
    # The scene renders again after an interrupt.
    assert scene.render(spp=1, progress=False).spp == 1
