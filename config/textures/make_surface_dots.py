#!/usr/bin/env python3
"""Writes surface-dots.png: the gaze-cue pattern printed on the virtual glass sphere.

A 512x256 equirectangular (u = longitude, v = latitude) texture: anti-aliased light-grey dots
every 32 px with thin latitude lines, on black (black adds no light on an optical see-through
display). Standard library only; rerun to regenerate byte-identical output.
"""
import math
import struct
import zlib

W, H = 512, 256
SPACING, RADIUS = 32, 5.0


def coverage(x, y):
    cx = (x // SPACING) * SPACING + SPACING / 2
    cy = (y // SPACING) * SPACING + SPACING / 2
    d = math.hypot(x + 0.5 - cx, y + 0.5 - cy)
    dot = min(1.0, max(0.0, RADIUS + 0.5 - d))
    line = 0.5 if y % (SPACING * 2) == 0 else 0.0
    return max(dot, line)


rows = []
for y in range(H):
    row = bytearray([0])  # filter type: none
    for x in range(W):
        v = round(220 * coverage(x, y))
        row += bytes([v, v, v, 255])
    rows.append(bytes(row))


def chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)


png = b"\x89PNG\r\n\x1a\n"
png += chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 6, 0, 0, 0))
png += chunk(b"IDAT", zlib.compress(b"".join(rows), 9))
png += chunk(b"IEND", b"")
with open("surface-dots.png", "wb") as f:
    f.write(png)
