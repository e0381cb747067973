#!/usr/bin/env python3
"""Writes boxes.gltf (buffer as a base64 data URI): one cube mesh without
normals used by three nodes (so lumis instances it), a floor, an emissive
panel and a camera named "view". Run from this directory:
python3 make_boxes.py"""
import base64, json, math, struct

bin_ = bytearray()
views, accessors = [], []

def add(data, fmt, count, type_, component, extra=None):
    while len(bin_) % 4:
        bin_.append(0)
    off = len(bin_)
    bin_.extend(struct.pack("<" + fmt * (len(data)), *data))
    views.append({"buffer": 0, "byteOffset": off, "byteLength": len(bin_) - off})
    acc = {"bufferView": len(views) - 1, "componentType": component, "count": count, "type": type_}
    acc.update(extra or {})
    accessors.append(acc)
    return len(accessors) - 1

def mesh(positions, indices, material, name):
    flat = [c for p in positions for c in p]
    lo = [min(p[k] for p in positions) for k in range(3)]
    hi = [max(p[k] for p in positions) for k in range(3)]
    pos = add(flat, "f", len(positions), "VEC3", 5126, {"min": lo, "max": hi})
    idx = add(indices, "I", len(indices), "SCALAR", 5125)
    return {"name": name, "primitives": [{"attributes": {"POSITION": pos}, "indices": idx, "material": material}]}

# A unit cube centred at the origin, outward CCW faces.
cube_p = [[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
cube_i = [i for a, b, c, d in quads for i in (a, b, c, a, c, d)]
floor_p = [[-3, 0, -3], [-3, 0, 3], [3, 0, 3], [3, 0, -3]]
floor_i = [0, 1, 2, 0, 2, 3]
# The panel faces down (-y).
panel_p = [[-0.6, 2.5, -0.6], [0.6, 2.5, -0.6], [0.6, 2.5, 0.6], [-0.6, 2.5, 0.6]]
panel_i = [0, 1, 2, 0, 2, 3]

def rot_y(deg):
    a = math.radians(deg) / 2
    return [0.0, math.sin(a), 0.0, math.cos(a)]

doc = {
    "asset": {"version": "2.0", "generator": "lumis scenes/gltf/make_boxes.py"},
    "scene": 0,
    "scenes": [{"nodes": [0, 1, 2, 3, 4, 5]}],
    "nodes": [
        {"name": "floor", "mesh": 1},
        {"name": "panel", "mesh": 2},
        {"name": "box-a", "mesh": 0, "translation": [-1.0, 0.5, 0.0], "rotation": rot_y(20)},
        {"name": "box-b", "mesh": 0, "translation": [0.9, 0.75, -0.4], "rotation": rot_y(-35), "scale": [1.0, 1.5, 1.0]},
        {"name": "box-c", "mesh": 0, "translation": [0.3, 0.25, 1.0], "scale": [0.5, 0.5, 0.5]},
        {"name": "view", "camera": 0, "translation": [0.0, 1.6, 5.5], "rotation": [-0.0998, 0.0, 0.0, 0.995]},
    ],
    "meshes": [
        mesh(cube_p, cube_i, 1, "cube"),
        mesh(floor_p, floor_i, 0, "floor"),
        mesh(panel_p, panel_i, 2, "panel"),
    ],
    "materials": [
        {"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0}},
        {"name": "terracotta", "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.3, 0.2, 1], "metallicFactor": 0}},
        {"name": "lamp", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.1, 0.1, 1], "metallicFactor": 0},
         "emissiveFactor": [1.0, 0.9, 0.75],
         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 12.0}}},
    ],
    "extensionsUsed": ["KHR_materials_emissive_strength"],
    "cameras": [{"name": "view", "type": "perspective", "perspective": {"yfov": 0.75, "znear": 0.1}}],
}
while len(bin_) % 4:
    bin_.append(0)
doc["buffers"] = [{"byteLength": len(bin_), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(bin_)).decode()}]
doc["bufferViews"] = views
doc["accessors"] = accessors
with open("boxes.gltf", "w") as f:
    json.dump(doc, f, indent=1)
