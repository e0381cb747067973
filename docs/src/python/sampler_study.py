"""The samplers study from Python: the relative MSE of the Cornell box
against a reference, over samples per pixel, for three samplers.

Run from the repository's root: `python3 docs/src/python/sampler_study.py`
(with matplotlib installed) draws docs/src/figures/python-samplers.png.
"""

import numpy as np

import lumis

SCENE = "scenes/cornell-box.toml"
SAMPLERS = ("independent", "stratified", "sobol")


def study(spps=(1, 4, 16, 64), seeds=4, resolution=64, reference_spp=4096):
    """Mean relMSE over `seeds` renders, per sampler and spp."""
    small = {"film.resolution": [resolution, resolution]}
    reference = lumis.load_file(SCENE, **small).render(spp=reference_spp, seed=99, progress=False)
    errors = {}
    for sampler in SAMPLERS:
        scene = lumis.load_file(SCENE, **small, **{"sampler.type": sampler})
        errors[sampler] = [
            np.mean([lumis.diff(scene.render(spp=n, seed=s, progress=False), reference)["rel_mse"]
                     for s in range(seeds)])
            for n in spps
        ]
    return errors


if __name__ == "__main__":
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    spps = (1, 4, 16, 64)
    for sampler, errors in study(spps).items():
        plt.loglog(spps, errors, "o-", label=sampler)
        print(sampler, " ".join(f"{e:.3e}" for e in errors))
    plt.xlabel("samples per pixel")
    plt.ylabel("relMSE against a 4096-spp reference")
    plt.title("Cornell box, 64x64, mean of 4 seeds")
    plt.legend()
    plt.savefig("docs/src/figures/python-samplers.png", dpi=100)
