"""How much slower a BSDF written in Python renders than the same BSDF in
Rust: the Cornell box with every wall `diffuse`, then `py-lambert` (the
tests' Lambertian in Python), best of three renders each, on one thread
and on two.

Run from the repository's root with the module installed:
`python3 docs/src/python/plugin_speed.py`.
"""

import sys

import lumis

sys.path.insert(0, "crates/lumis-py/tests/python")
from plugins_in_python import Lambert  # noqa: E402

lumis.register_bsdf("py-lambert", Lambert, params={"reflectance": [0.5, 0.5, 0.5]})
small = {"film.resolution": [128, 128], "sampler.type": "independent"}
python = {**small, **{f"bsdf.{wall}.type": "py-lambert" for wall in ("white", "red", "green")}}
for threads in (1, 2):
    for label, overrides in (("diffuse (Rust)", small), ("py-lambert (Python)", python)):
        scene = lumis.load_file("scenes/cornell-box.toml", **overrides)
        renders = [scene.render(spp=16, threads=threads, progress=False) for _ in range(3)]
        best = min(renders, key=lambda r: r.seconds)
        rate = best.stats["samples"] / best.seconds / 1e6
        print(f"{threads} thread(s), {label}: {best.seconds:.3f} s, {rate:.3f} Msamples/s")
