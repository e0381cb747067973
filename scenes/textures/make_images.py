#!/usr/bin/env python3
"""Writes quadrants.png for textured-quads.toml: a 64 x 64 8-bit sRGB image
of four coloured quadrants with a white bar near the top edge, so that a
flipped or rotated lookup shows. Written with zlib alone (no imaging
library). Run from anywhere: python3 make_images.py"""
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
