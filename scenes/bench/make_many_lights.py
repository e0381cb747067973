#!/usr/bin/env python3
"""Writes many-lights/lights-{warm,cool,red,green}.obj for many-lights.toml:
a 32 x 32 grid of small equal triangles (1,024 in all, 256 per file) at
y = 2.5 over x, z in [-3, 3], every one facing down (CCW seen from below),
the four colour groups interleaved over the grid. Each triangle becomes one
area light in lumis. Run from anywhere: python3 make_many_lights.py"""
import os

HERE = os.path.dirname(os.path.abspath(__file__))
N, EXTENT, Y, SIZE = 32, 3.0, 2.5, 0.09
GROUPS = ["warm", "cool", "red", "green"]

os.makedirs(os.path.join(HERE, "many-lights"), exist_ok=True)
files = {g: [] for g in GROUPS}
for i in range(N):
    for j in range(N):
        x = -EXTENT + (i + 0.5) * 2 * EXTENT / N
        z = -EXTENT + (j + 0.5) * 2 * EXTENT / N
        group = GROUPS[(i % 2) * 2 + (j % 2)]
        # Seen from below (looking up +y), CCW: normal -y.
        files[group].append([(x - SIZE / 2, Y, z - SIZE / 2), (x + SIZE / 2, Y, z - SIZE / 2), (x, Y, z + SIZE / 2)])
for g, tris in files.items():
    with open(os.path.join(HERE, "many-lights", f"lights-{g}.obj"), "w") as f:
        f.write(f"# many-lights.toml, group {g}: {len(tris)} emissive triangles facing -y "
                "(made by make_many_lights.py)\n")
        for t in tris:
            for p in t:
                f.write("v %.6f %.6f %.6f\n" % p)
        for k in range(len(tris)):
            f.write(f"f {3 * k + 1} {3 * k + 2} {3 * k + 3}\n")
print("wrote", ", ".join(f"many-lights/lights-{g}.obj" for g in GROUPS))
