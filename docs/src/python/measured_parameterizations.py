"""Factored sampling of a measured table in the three parameterizations,
side by side at 16 spp: the measured sphere (direct light, BSDF sampling
only), relMSE against a 4096-spp reference, mean of four seeds.

Make the table, then run from the repository's root (with matplotlib):

    lumis brdf tabulate --bsdf conductor --set roughness=0.05 --set material=Cu \\
        -o conductor-0.05.binary
    python3 docs/src/python/measured_parameterizations.py conductor-0.05.binary
"""

import sys

import numpy as np

import lumis

TABLE = sys.argv[1]
SCENE = "scenes/measured-sphere.toml"
PARAMETERIZATIONS = ("half-diff", "pdv", "in-out")


def scene(**overrides):
    return lumis.load_file(SCENE, **{"bsdf.sample.file": TABLE}, **overrides)


reference = scene(**{"bsdf.sample.sampling": "tabulated"}).render(spp=4096, seed=1000, progress=False)
renders = {}
for p in PARAMETERIZATIONS:
    sampled = scene(**{"bsdf.sample.sampling": "factored", "bsdf.sample.parameterization": p})
    renders[p] = [sampled.render(spp=16, seed=s, progress=False) for s in range(4)]
    errors = [lumis.diff(r, reference)["rel_mse"] for r in renders[p]]
    print(f"{p}: relMSE {np.mean(errors):.4f}, by seed " + " ".join(f"{e:.4f}" for e in errors))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def srgb(image):
    x = np.clip(image, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


panels = [("reference, 4096 spp", reference.image)] + [
    (f"{p}, 16 spp", renders[p][0].image) for p in PARAMETERIZATIONS
]
figure, axes = plt.subplots(1, len(panels), figsize=(3 * len(panels), 3.5))
for axis, (title, image) in zip(axes, panels):
    axis.imshow(srgb(image))
    axis.set_title(title)
    axis.axis("off")
figure.tight_layout(pad=1.0)
figure.savefig("docs/src/figures/measured-parameterizations.png", dpi=80)
