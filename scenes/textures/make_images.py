#!/usr/bin/env python3
"""Writes quadrants.png for textured-quads.toml: a 64 x 64 8-bit sRGB image
of four coloured quadrants with a white bar near the top edge, so that a
flipped or rotated lookup shows; and bumps.png for normal-map.toml: a
128 x 128 tangent-space normal map (linear, (n + 1) / 2, x right and y up
the image) of a 4 x 4 grid of domes, the upper-left one a dimple, so that
a flipped axis shows. Written with zlib alone (no imaging library). Run
from anywhere: python3 make_images.py"""
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


def quadrants(x, y):
    if 6 <= y < 14 and 16 <= x < 48:  # a bar near the top edge (v small)
        return (250, 250, 250)
    left, top = x < 32, y < 32
    if top:
        return (200, 60, 50) if left else (60, 170, 70)
    return (50, 80, 200) if left else (220, 200, 60)


with open(os.path.join(HERE, "quadrants.png"), "wb") as f:
    f.write(png(64, 64, quadrants))


def bumps(x, y, size=128, cells=4):
    """The normal of a height field of domes: n = normalize(-dh/dx, dh/dy, 1)
    with y the image row (down), so that n's y points up the image."""
    cell = size / cells
    cx, cy = (x + 0.5) % cell - cell / 2, (y + 0.5) % cell - cell / 2
    radius = 0.4 * cell
    d2 = cx * cx + cy * cy
    n = (0.0, 0.0, 1.0)
    if d2 < radius * radius:
        sign = -1.0 if (x < cell and y < cell) else 1.0  # the upper-left cell is a dimple
        h = math.sqrt(radius * radius - d2)
        # h = sqrt(r^2 - d^2): dh/dx = -cx / h, dh/dy = -cy / h, scaled to a
        # dome half as high as it is wide.
        dhdx, dhdy = sign * -0.5 * cx / h, sign * -0.5 * cy / h
        n = (-dhdx, dhdy, 1.0)
    length = math.sqrt(sum(c * c for c in n))
    return tuple(round((c / length * 0.5 + 0.5) * 255) for c in n)


with open(os.path.join(HERE, "bumps.png"), "wb") as f:
    f.write(png(128, 128, bumps))
