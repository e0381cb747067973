#!/usr/bin/env python3
"""Render the reference image of scenes/cornell-box.toml with Mitsuba 3.

The scene is built from the repository's own OBJ files
(`scenes/cornell-box/*.obj`, found next to this script) and the same numbers
as `scenes/cornell-box.toml`: one-sided Lambertian walls, a
one-sided area emitter that also reflects as the white material, a pinhole
camera with a box pixel filter, unidirectional path tracing with max_depth 8
and Russian roulette from depth 5.

    python3 -m pip install mitsuba==3.9.1
    python3 scenes/reference/cornell_box_mitsuba.py --spp 8192 \
        -o scenes/reference/cornell-box-mitsuba.exr
"""
import argparse
import os

import mitsuba as mi

HERE = os.path.dirname(os.path.abspath(__file__))
OBJ_DIR = os.path.join(HERE, "..", "cornell-box")

ALBEDO = {
    "white": [0.885809, 0.698859, 0.666422],
    "red": [0.570068, 0.0430135, 0.0443706],
    "green": [0.105421, 0.37798, 0.076425],
}
SHAPES = [
    ("floor", "white"),
    ("ceiling", "white"),
    ("back", "white"),
    ("green_wall", "green"),
    ("red_wall", "red"),
    ("small_box", "white"),
    ("large_box", "white"),
    ("light", "white"),
]
LIGHT_RADIANCE = [18.387, 13.9873, 6.75357]


def scene_dict(spp, seed):
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 8, "rr_depth": 5},
        "sensor": {
            "type": "perspective",
            "fov": 39.3077,
            "fov_axis": "smaller",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=[0.0, 0.0, 3.9], target=[0.0, 0.0, 2.9], up=[0.0, 1.0, 0.0]
            ),
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
            "film": {
                "type": "hdrfilm",
                "width": 256,
                "height": 256,
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
                "component_format": "float32",
            },
        },
    }
    for name, material in SHAPES:
        shape = {
            "type": "obj",
            "filename": os.path.join(OBJ_DIR, name + ".obj"),
            "face_normals": True,
            "bsdf": {
                "type": "diffuse",
                "reflectance": {"type": "rgb", "value": ALBEDO[material]},
            },
        }
        if name == "light":
            shape["emitter"] = {
                "type": "area",
                "radiance": {"type": "rgb", "value": LIGHT_RADIANCE},
            }
        scene[name] = shape
    return scene


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=8192)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--variant", default="scalar_rgb")
    parser.add_argument("-o", "--output", default=os.path.join(HERE, "cornell-box-mitsuba.exr"))
    args = parser.parse_args()
    mi.set_variant(args.variant)
    scene = mi.load_dict(scene_dict(args.spp, args.seed))
    image = mi.render(scene, spp=args.spp)
    mi.util.write_bitmap(args.output, image)
    print(f"wrote {args.output} ({args.spp} spp, {args.variant})")


if __name__ == "__main__":
    main()
