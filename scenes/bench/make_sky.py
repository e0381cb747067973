#!/usr/bin/env python3
"""Writes sky.exr for envmap-sky.toml: a procedural sky in the
equirectangular layout of lumis's and Mitsuba's `envmap` (+y up, the image
centre looking along +z, the top row at the zenith): a blue gradient that
whitens toward the horizon, a dim ground below it, and a sun 35 degrees up,
1.5 degrees in radius with a soft glow around it. The EXR is half-float RGB,
one scanline per ZIP block, written with numpy and zlib alone (no imaging
library). Run from anywhere: python3 make_sky.py"""
import os
import struct
import zlib

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
WIDTH, HEIGHT = 512, 256
SUN_ELEVATION, SUN_AZIMUTH = np.radians(35.0), np.radians(60.0)
SUN_RADIUS = np.radians(1.5)
SUN_RADIANCE = np.array([4000.0, 3600.0, 3000.0])


def sky():
    """Linear RGB radiance, shape (HEIGHT, WIDTH, 3), row 0 at the zenith."""
    u = (np.arange(WIDTH) + 0.5) / WIDTH
    v = (np.arange(HEIGHT) + 0.5) / HEIGHT
    phi, theta = np.meshgrid(2.0 * np.pi * u, np.pi * v)
    # Mitsuba's envmap: d = (sin theta sin phi, cos theta, -sin theta cos phi).
    d = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], -1)
    up = d[..., 1:2]
    zenith = np.array([0.10, 0.25, 0.70])
    horizon = np.array([0.75, 0.85, 1.00])
    t = np.clip(up, 0.0, 1.0) ** 0.4
    rgb = horizon * (1.0 - t) + zenith * t
    ground = np.array([0.12, 0.10, 0.08])
    rgb = np.where(up > 0.0, rgb, ground)
    s = np.array([
        np.cos(SUN_ELEVATION) * np.sin(SUN_AZIMUTH),
        np.sin(SUN_ELEVATION),
        -np.cos(SUN_ELEVATION) * np.cos(SUN_AZIMUTH),
    ])
    angle = np.arccos(np.clip(d @ s, -1.0, 1.0))[..., None]
    rgb = rgb + np.where(angle < SUN_RADIUS, SUN_RADIANCE, 0.0)
    rgb = rgb + 8.0 * np.exp(-angle / np.radians(4.0)) * np.array([1.0, 0.9, 0.7])
    return rgb


def attribute(name, kind, value):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def zip_block(raw):
    """OpenEXR's ZIP compression: bytes split in even and odd halves, delta
    coded, deflated (kept raw if that is not smaller)."""
    data = np.frombuffer(raw, np.uint8)
    split = np.concatenate([data[0::2], data[1::2]]).astype(np.int32)
    delta = split.copy()
    delta[1:] = (split[1:] - split[:-1] + 128) & 0xFF
    packed = zlib.compress(delta.astype(np.uint8).tobytes(), 9)
    return packed if len(packed) < len(raw) else raw


def write_exr(path, rgb):
    height, width, _ = rgb.shape
    channels = b"".join(
        name + b"\0" + struct.pack("<iB3xii", 1, 0, 1, 1) for name in (b"B", b"G", b"R")
    ) + b"\0"
    window = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = b"".join([
        b"\x76\x2f\x31\x01", struct.pack("<i", 2),
        attribute("channels", "chlist", channels),
        attribute("compression", "compression", b"\x02"),
        attribute("dataWindow", "box2i", window),
        attribute("displayWindow", "box2i", window),
        attribute("lineOrder", "lineOrder", b"\x00"),
        attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)),
        attribute("screenWindowWidth", "float", struct.pack("<f", 1.0)),
        b"\0",
    ])
    half = rgb.astype("<f2")
    blocks = []
    for y in range(height):
        line = b"".join(half[y, :, c].tobytes() for c in (2, 1, 0))
        data = zip_block(line)
        blocks.append(struct.pack("<ii", y, len(data)) + data)
    offset = len(header) + 8 * height
    table = b""
    for block in blocks:
        table += struct.pack("<Q", offset)
        offset += len(block)
    with open(path, "wb") as f:
        f.write(header + table + b"".join(blocks))


if __name__ == "__main__":
    write_exr(os.path.join(HERE, "sky.exr"), sky())
