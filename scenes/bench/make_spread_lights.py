#!/usr/bin/env python3
"""Writes assets/spread-lights-{dim,warm,cool,bright}.obj for
spread-lights.toml: 12,288 small emissive triangles (3,072 per file) spread
through a room, of random sizes (edges 0.03 to 0.15) and random facings
(one-sided), the bright group gathered in four clusters. Each triangle
becomes one area light in lumis; the files' radiances span two decades, so
which lights matter depends on where the shading point is, which way the
lights face, and their power. The OBJs (about 1.3 MB) are generated, not
committed (scenes/bench/assets/ is ignored). Seeded: every run writes the
same files. Run from anywhere: python3 make_spread_lights.py"""
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
PER_GROUP = 3072
GROUPS = ["dim", "warm", "cool", "bright"]
# Where the lights of each group may be: (x, y, z) ranges of the room.
ROOM = ((-5.5, 5.5), (0.15, 4.0), (-3.3, 2.5))
CLUSTERS = [(-3.5, 3.2, -2.5), (3.8, 0.6, -1.0), (0.5, 3.6, 1.5), (-1.0, 0.4, -3.0)]

rng = random.Random(15)


def unit_vector():
    z = 2 * rng.random() - 1
    phi = 2 * math.pi * rng.random()
    r = math.sqrt(max(0.0, 1 - z * z))
    return (r * math.cos(phi), r * math.sin(phi), z)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)


def triangle(center, size):
    """A triangle of edge about `size` around `center`, facing a random way
    (its normal is (p1 - p0) x (p2 - p0))."""
    n = unit_vector()
    helper = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
    t = normalize(cross(helper, n))
    b = cross(n, t)
    pts = []
    for k in range(3):
        a = 2 * math.pi * k / 3
        pts.append(tuple(center[i] + size / math.sqrt(3) * (math.cos(a) * t[i] + math.sin(a) * b[i]) for i in range(3)))
    return pts


def position(group):
    if group == "bright":
        c = CLUSTERS[rng.randrange(len(CLUSTERS))]
        return tuple(c[i] + rng.gauss(0.0, 0.35) for i in range(3))
    return tuple(lo + (hi - lo) * rng.random() for lo, hi in ROOM)


os.makedirs(os.path.join(HERE, "assets"), exist_ok=True)
for group in GROUPS:
    path = os.path.join(HERE, "assets", f"spread-lights-{group}.obj")
    with open(path, "w") as f:
        f.write(f"# spread-lights.toml, group {group}: {PER_GROUP} emissive triangles "
                "(made by make_spread_lights.py)\n")
        for _ in range(PER_GROUP):
            for p in triangle(position(group), 0.03 + 0.12 * rng.random()):
                f.write("v %.5f %.5f %.5f\n" % p)
        for k in range(PER_GROUP):
            f.write(f"f {3 * k + 1} {3 * k + 2} {3 * k + 3}\n")
print("wrote", ", ".join(f"assets/spread-lights-{g}.obj" for g in GROUPS))
