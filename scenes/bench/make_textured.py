#!/usr/bin/env python3
"""Writes textured.glb for textured-gltf.toml: a floor with a checker
base-colour texture (uv 0..4, sampler REPEAT) and a cube mesh with an
asymmetric texture (four coloured quadrants and a bar near the top edge, so a
flipped or rotated lookup shows), used by two nodes (lumis instances it).
Every material is a smooth dielectric (metallic 0, roughness 0: lumis's
smooth `plastic`, coat IOR 1.5) whose base colour is the texture, sRGB,
bilinear. Both PNGs are written with zlib alone (no imaging library) and
stored in the .glb's binary chunk. Run from anywhere: python3 make_textured.py"""
import json
import math
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def png(width, height, pixel):
    """An 8-bit RGB PNG; pixel(x, y) -> (r, g, b), y = 0 the top row."""
    raw = bytearray()
    for y in range(height):
        raw.append(0)  # filter: none
        for x in range(width):
            raw.extend(pixel(x, y))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")


def checker(x, y):
    return (200, 190, 170) if ((x // 16) + (y // 16)) % 2 == 0 else (60, 70, 90)


def quadrants(x, y):
    if 6 <= y < 14 and 16 <= x < 48:  # a bar near the top edge (v small)
        return (250, 250, 250)
    left, top = x < 32, y < 32
    if top:
        return (210, 60, 40) if left else (230, 190, 40)
    return (40, 120, 210) if left else (60, 170, 80)


bin_ = bytearray()
views, accessors = [], []


def view(data):
    while len(bin_) % 4:
        bin_.append(0)
    views.append({"buffer": 0, "byteOffset": len(bin_), "byteLength": len(data)})
    bin_.extend(data)
    return len(views) - 1


def accessor(values, fmt, count, type_, component, minmax=False):
    acc = {"bufferView": view(struct.pack("<" + fmt * len(values), *values)),
           "componentType": component, "count": count, "type": type_}
    if minmax:
        k = len(values) // count
        acc["min"] = [min(values[i::k]) for i in range(k)]
        acc["max"] = [max(values[i::k]) for i in range(k)]
    accessors.append(acc)
    return len(accessors) - 1


def mesh(name, positions, normals, uvs, indices, material):
    flat = lambda a: [c for p in a for c in p]
    attrs = {
        "POSITION": accessor(flat(positions), "f", len(positions), "VEC3", 5126, True),
        "NORMAL": accessor(flat(normals), "f", len(normals), "VEC3", 5126),
        "TEXCOORD_0": accessor(flat(uvs), "f", len(uvs), "VEC2", 5126),
    }
    idx = accessor(indices, "I", len(indices), "SCALAR", 5125)
    return {"name": name, "primitives": [{"attributes": attrs, "indices": idx, "material": material}]}


# The floor: 8 x 8 at y = 0, facing up, uv 0..4 (the checker repeats 4 x 4).
floor = mesh("floor",
             [[-4, 0, -4], [-4, 0, 4], [4, 0, 4], [4, 0, -4]],
             [[0, 1, 0]] * 4,
             [[0, 0], [0, 4], [4, 4], [4, 0]],
             [0, 1, 2, 0, 2, 3], 0)

# A unit cube centred at the origin: 6 faces x 4 corners, own normals and uvs,
# CCW seen from outside; each face shows the whole texture, upright.
faces = [  # (normal, u axis, v axis): v runs down the face (glTF uv: v = 0 at the top)
    ([0, 0, 1], [1, 0, 0], [0, -1, 0]), ([0, 0, -1], [-1, 0, 0], [0, -1, 0]),
    ([1, 0, 0], [0, 0, -1], [0, -1, 0]), ([-1, 0, 0], [0, 0, 1], [0, -1, 0]),
    ([0, 1, 0], [1, 0, 0], [0, 0, 1]), ([0, -1, 0], [1, 0, 0], [0, 0, -1]),
]
cp, cn, cu, ci = [], [], [], []
for n, u, v in faces:
    base = len(cp)
    for su, sv in ((0, 0), (0, 1), (1, 1), (1, 0)):
        cp.append([0.5 * n[k] + (su - 0.5) * u[k] + (sv - 0.5) * v[k] for k in range(3)])
        cn.append(n)
        cu.append([su, sv])
    # Wind the two triangles so that they face n (CCW seen from outside).
    a, b, c, d = base, base + 1, base + 2, base + 3
    e1 = [cp[b][k] - cp[a][k] for k in range(3)]
    e2 = [cp[c][k] - cp[a][k] for k in range(3)]
    cross = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
    if sum(cross[k] * n[k] for k in range(3)) > 0:
        ci += [a, b, c, a, c, d]
    else:
        ci += [a, c, b, a, d, c]
cube = mesh("cube", cp, cn, cu, ci, 1)


def rot_y(deg):
    a = math.radians(deg) / 2
    return [0.0, math.sin(a), 0.0, math.cos(a)]


checker_png = png(64, 64, checker)
quadrants_png = png(64, 64, quadrants)
doc = {
    "asset": {"version": "2.0", "generator": "lumis scenes/bench/make_textured.py"},
    "scene": 0,
    "scenes": [{"nodes": [0, 1, 2]}],
    "nodes": [
        {"name": "floor", "mesh": 0},
        {"name": "cube-a", "mesh": 1, "translation": [-0.9, 0.6, 0.2], "rotation": rot_y(30), "scale": [1.2, 1.2, 1.2]},
        {"name": "cube-b", "mesh": 1, "translation": [0.9, 0.4, -0.3], "rotation": rot_y(-25), "scale": [0.8, 0.8, 0.8]},
    ],
    "meshes": [floor, cube],
    "materials": [
        {"name": "checker", "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0}, "metallicFactor": 0.0, "roughnessFactor": 0.0}},
        {"name": "quadrants", "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 1}, "metallicFactor": 0.0, "roughnessFactor": 0.0}},
    ],
    "samplers": [{"magFilter": 9729, "minFilter": 9729, "wrapS": 10497, "wrapT": 10497}],
    "images": [
        {"bufferView": view(checker_png), "mimeType": "image/png", "name": "checker"},
        {"bufferView": view(quadrants_png), "mimeType": "image/png", "name": "quadrants"},
    ],
    "textures": [{"sampler": 0, "source": 0}, {"sampler": 0, "source": 1}],
}
while len(bin_) % 4:
    bin_.append(0)
doc["buffers"] = [{"byteLength": len(bin_)}]
doc["bufferViews"] = views
doc["accessors"] = accessors
js = json.dumps(doc, separators=(",", ":")).encode()
js += b" " * ((-len(js)) % 4)
out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(bin_))
out += struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(bin_), 0x004E4942) + bytes(bin_)
with open(os.path.join(HERE, "textured.glb"), "wb") as f:
    f.write(out)
print(f"wrote textured.glb ({len(out)} bytes)")
