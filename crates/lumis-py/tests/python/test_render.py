"""Scenes rendered from Python are the command line's renders."""

import numpy as np
import pytest

import lumis

from conftest import RESOLUTION


def small(path, **overrides):
    return lumis.load_file(path, **{"film.resolution": RESOLUTION}, **overrides)


def test_render_is_the_command_lines_image_bit_for_bit(cornell_box, cli, tmp_path):
    render = small(cornell_box).render(spp=4, seed=3, progress=False)
    cli("render", cornell_box, "--spp", 4, "--seed", 3, "--set",
        f"film.resolution={RESOLUTION}", "-o", tmp_path / "cli", "--no-checkpoint", "-q")
    image = lumis.read_image(tmp_path / "cli.exr")
    assert render.image.dtype == np.float32
    assert render.image.shape == (32, 32, 3)
    assert np.array_equal(render.image, image)
    assert render.spp == 4 and render.seed == 3 and not render.interrupted


def test_overrides_are_the_command_lines_set(cornell_box, cli, tmp_path):
    scene = small(cornell_box, **{"integrator.max_depth": 2, "sampler.type": "independent"})
    render = scene.render(spp=2, progress=False)
    cli("render", cornell_box, "--spp", 2, "--set", f"film.resolution={RESOLUTION}",
        "--set", "integrator.max_depth=2", "--set", "sampler.type=independent",
        "-o", tmp_path / "cli", "--no-checkpoint", "-q")
    assert np.array_equal(render.image, lumis.read_image(tmp_path / "cli.exr"))


def test_the_seed_and_spp_change_the_image_and_come_back(cornell_box):
    scene = small(cornell_box)
    first = scene.render(spp=2, seed=1, progress=False).image
    assert not np.array_equal(first, scene.render(spp=2, seed=2, progress=False).image)
    assert scene.render(spp=4, seed=1, progress=False).spp == 4
    assert np.array_equal(first, scene.render(spp=2, seed=1, progress=False).image)


def test_threads_do_not_change_the_image(cornell_box):
    scene = small(cornell_box)
    one = scene.render(spp=2, threads=1, progress=False).image
    two = scene.render(spp=2, threads=2, progress=False).image
    assert np.array_equal(one, two)


def test_parts_written_from_python_merge_as_the_command_lines(cornell_box, cli, tmp_path):
    scene = small(cornell_box)
    for k, samples in enumerate([range(0, 2), range(2, 4)]):
        part = scene.render(spp=4, seed=5, samples=samples, progress=False)
        assert part.spp == 2
        exr, png = part.write(tmp_path / f"part{k}")
        assert exr == tmp_path / f"part{k}.exr" and png is None
    cli("merge", tmp_path / "part0.exr", tmp_path / "part1.exr", "-o", tmp_path / "merged")
    # `--parts 2` sums the same two slices apart, then adds them: what
    # `lumis merge` makes of the parts, bit for bit.
    cli("render", cornell_box, "--spp", 4, "--seed", 5, "--set", f"film.resolution={RESOLUTION}",
        "--parts", 2, "-o", tmp_path / "whole", "--no-checkpoint", "-q")
    merged = lumis.read_image(tmp_path / "merged.exr")
    assert np.array_equal(merged, lumis.read_image(tmp_path / "whole.exr"))
    with pytest.raises(lumis.Error, match="expected A..B"):
        scene.render(spp=4, samples=range(2, 9), progress=False)


def test_write_makes_the_command_lines_files(cornell_box, tmp_path):
    render = small(cornell_box).render(spp=2, progress=False)
    exr, png = render.write(tmp_path / "box")
    assert exr == tmp_path / "box.exr" and png == tmp_path / "box.png"
    assert np.array_equal(lumis.read_image(exr), render.image)
    assert png.read_bytes() == render._repr_png_()
    # A finished image with more samples is kept unless forced.
    fewer = small(cornell_box).render(spp=1, progress=False)
    with pytest.raises(lumis.Error, match="refusing to replace it"):
        fewer.write(tmp_path / "box")
    fewer.write(tmp_path / "box", force=True)


def test_a_scenes_denoiser_runs_as_the_command_lines(cornell_box, cli, tmp_path):
    denoiser = {"denoiser.type": "oidn", "denoiser.quality": "fast"}
    render = small(cornell_box, **denoiser).render(spp=2, seed=4, progress=False)
    assert render.denoised.dtype == np.float32
    assert render.denoised.shape == (32, 32, 3)
    assert not np.array_equal(render.denoised, render.image)
    cli("render", cornell_box, "--spp", 2, "--seed", 4, "--set", f"film.resolution={RESOLUTION}",
        "--set", 'denoiser.type="oidn"', "--set", 'denoiser.quality="fast"',
        "-o", tmp_path / "cli", "--no-checkpoint", "-q")
    assert np.array_equal(render.image, lumis.read_image(tmp_path / "cli.exr"))
    assert np.array_equal(render.denoised, lumis.read_image(tmp_path / "cli.denoised.exr"))
    render.write(tmp_path / "py")
    assert np.array_equal(lumis.read_image(tmp_path / "py.denoised.exr"), render.denoised)
    assert (tmp_path / "py.denoised.png").is_file()
    # A part of the samples is not denoised, nor a scene without a denoiser.
    part = small(cornell_box, **denoiser).render(spp=2, samples=range(0, 1), progress=False)
    assert part.denoised is None
    part.write(tmp_path / "part")
    assert not (tmp_path / "part.denoised.exr").exists()
    assert small(cornell_box).render(spp=1, progress=False).denoised is None


def test_outputs_statistics_and_notebook_display(cornell_box):
    scene = small(cornell_box, **{"film.aovs": ["albedo", "depth", "variance"]})
    render = scene.render(spp=2, progress=False)
    assert set(render.aovs) == {"albedo", "depth", "variance"}
    assert render.aovs["albedo"].shape == (32, 32, 3)
    assert render.aovs["depth"].shape == (32, 32)
    assert render.aovs["depth"].max() > 0
    stats = render.stats
    assert stats["samples"] == 32 * 32 * 2 and stats["spp"] == 2 and stats["rays"] > 0
    assert render._repr_png_().startswith(b"\x89PNG\r\n\x1a\n")
    assert np.array_equal(np.asarray(render), render.image)


def test_progress_reaches_the_total(cornell_box):
    seen = []
    small(cornell_box).render(spp=4, pass_spp=1, progress=lambda done, total: seen.append((done, total)))
    assert seen and seen[-1][0] <= seen[-1][1]
    assert all(a[0] <= b[0] for a, b in zip(seen, seen[1:]))


def test_a_tqdm_bar_shows_progress_by_default(cornell_box, capsys):
    pytest.importorskip("tqdm")
    small(cornell_box).render(spp=2, pass_spp=1)
    assert "tile" in capsys.readouterr().err


def test_a_progress_callback_that_raises_stops_the_render(cornell_box):
    def fail(done, total):
        raise RuntimeError("from the callback")

    with pytest.raises(RuntimeError, match="from the callback"):
        small(cornell_box).render(spp=64, pass_spp=1, progress=fail)


def test_diff_gives_lumis_diffs_metrics(cornell_box, cli, tmp_path):
    scene = small(cornell_box)
    noisy = scene.render(spp=1, seed=1, progress=False)
    reference = scene.render(spp=16, seed=2, progress=False)
    noisy.write(tmp_path / "noisy")
    reference.write(tmp_path / "reference")
    metrics = lumis.diff(noisy, reference)
    assert lumis.diff(noisy.image, tmp_path / "reference.exr") == metrics
    assert lumis.diff(reference, reference)["mse"] == 0.0
    printed = cli("diff", tmp_path / "noisy.exr", tmp_path / "reference.exr")
    row = next(line.split() for line in printed.splitlines() if line.startswith("image"))
    assert float(row[1]) == pytest.approx(metrics["mse"], rel=1e-3)
    assert float(row[3]) == pytest.approx(metrics["rel_mse"], rel=1e-3)
    with pytest.raises(lumis.Error, match="expected \\(height, width, 3\\)"):
        lumis.diff(np.zeros((4, 4, 2)), np.zeros((4, 4, 2)))


def test_the_renders_warnings_are_python_warnings(cornell_box):
    with pytest.warns(UserWarning, match="--threads 100000 capped"):
        small(cornell_box).render(spp=1, threads=100000, progress=False)
