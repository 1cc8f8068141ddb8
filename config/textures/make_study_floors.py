#!/usr/bin/env python3
"""Writes the two floors of the paper's shadow and caustics study (section 4.2), as greyscale
1024x1024 floor photos (luminance L_r, 1 m x 1 m on the table):

- wood-grain.png: synthetic wood, boards 125 mm wide running away from the viewer, each with
  its own annual rings (a log's rings cut lengthwise, bent by smooth noise), pores and a board
  brightness; a uniform, low-contrast pattern like the paper's wood grain.
- stone-tiles.png: stone tiles 250 mm square with 6 mm grout, each tile a differently placed
  and turned piece of the real gravel photo (gravel.png, CC0, scikit-image) with its own
  brightness; a high-frequency, high-contrast pattern like the paper's stone tiles.

Standard library only; rerun to regenerate byte-identical output (fixed seeds).
"""
import math
import random
import struct
import zlib

SIZE = 1024  # pixels per metre of floor


def write_png(path, width, height, grey):
    """8-bit greyscale PNG from a list of rows of ints."""
    raw = b"".join(b"\x00" + bytes(row) for row in grey)

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", header))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def read_grey_png(path):
    """Reads an 8-bit greyscale, non-interlaced PNG (as gravel.png is)."""
    data = open(path, "rb").read()
    pos, idat = 8, b""
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert (depth, colour, interlace) == (8, 0, 0), "8-bit grey, not interlaced"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    rows, prev, stride = [], [0] * width, width + 1
    for y in range(height):
        kind, line = raw[y * stride], list(raw[y * stride + 1 : (y + 1) * stride])
        for x in range(width):
            a = line[x - 1] if x else 0
            b, c = prev[x], prev[x - 1] if x else 0
            if kind == 1:
                line[x] = (line[x] + a) & 255
            elif kind == 2:
                line[x] = (line[x] + b) & 255
            elif kind == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[x] = (line[x] + pred) & 255
        rows.append(line)
        prev = line
    return width, height, rows


class Noise:
    """Smooth 2-D value noise (bilinear over a random lattice with smoothstep)."""

    def __init__(self, seed, cells):
        rng = random.Random(seed)
        self.cells = cells
        self.values = [[rng.random() for _ in range(cells + 1)] for _ in range(cells + 1)]

    def __call__(self, u, v):
        x, y = (u % 1.0) * self.cells, (v % 1.0) * self.cells
        i, j = min(int(x), self.cells - 1), min(int(y), self.cells - 1)
        fx, fy = x - i, y - j
        sx, sy = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy)
        v00, v10 = self.values[j][i], self.values[j][i + 1]
        v01, v11 = self.values[j + 1][i], self.values[j + 1][i + 1]
        top = v00 + (v10 - v00) * sx
        bottom = v01 + (v11 - v01) * sx
        return top + (bottom - top) * sy


def wood():
    boards = 8
    rng = random.Random(1954)
    bend = Noise(7, 6)
    fine = Noise(8, 160)
    params = [
        (rng.uniform(-0.4, 0.4), rng.uniform(0.02, 0.06), rng.uniform(0.85, 1.1), rng.uniform(0, 1))
        for _ in range(boards)
    ]
    rows = []
    for y in range(SIZE):
        v = y / SIZE
        row = []
        for x in range(SIZE):
            u = x / SIZE
            b = min(int(u * boards), boards - 1)
            centre, ring_mm, light, shift = params[b]
            across = (u * boards - b - 0.5) / boards + centre * 0.1  # metres from the pith
            # The log's rings cut lengthwise: distance from the pith, bent along the board.
            r = math.hypot(across, 0.03 + 0.02 * bend(u, v + shift)) + 0.01 * bend(v, u)
            ring = 0.5 + 0.5 * math.cos(2 * math.pi * r / (ring_mm * 0.1))
            late = ring ** 3  # dark latewood, a thin part of each ring
            grain = 0.9 + 0.1 * fine(u * 0.3, v * 3.0)
            value = light * grain * (150 - 55 * late)
            if abs((u * boards) - round(u * boards)) * SIZE / boards < 1.5:
                value *= 0.45  # the joint between boards
            row.append(max(0, min(255, round(value))))
        rows.append(row)
    write_png("wood-grain.png", SIZE, SIZE, rows)


def stone():
    gw, gh, gravel = read_grey_png("gravel.png")
    tiles, grout_px = 4, 6
    tile_px = SIZE // tiles
    rng = random.Random(2021)
    placements = [
        (rng.randrange(gw - tile_px), rng.randrange(gh - tile_px), rng.randrange(4), rng.uniform(0.75, 1.25))
        for _ in range(tiles * tiles)
    ]
    rows = []
    for y in range(SIZE):
        row = []
        ty, py = divmod(y, tile_px)
        for x in range(SIZE):
            tx, px = divmod(x, tile_px)
            edge = min(px, py, tile_px - 1 - px, tile_px - 1 - py)
            if edge < grout_px // 2:
                row.append(70)
                continue
            ox, oy, turn, gain = placements[ty * tiles + tx]
            a, b = px, py
            for _ in range(turn):
                a, b = tile_px - 1 - b, a
            value = gravel[oy + b][ox + a] * gain
            if edge < grout_px // 2 + 2:
                value *= 0.8  # the tile's bevel
            row.append(max(0, min(255, round(value))))
        rows.append(row)
    write_png("stone-tiles.png", SIZE, SIZE, rows)


if __name__ == "__main__":
    wood()
    stone()
