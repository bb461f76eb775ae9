#!/usr/bin/env python3
"""Writes scenes/textures/bumps_normal.png: a tileable tangent-space normal map of round bumps.

    python3 tools/make_normal_map.py [-o scenes/textures/bumps_normal.png]

256 x 256 texels, 8-bit RGB, the normal n encoded as n * 0.5 + 0.5 (flat is
(128, 128, 255)), in the OpenGL / glTF convention that wavetrace's
`normal_texture` reads (docs/scene-format.md): +x (red) along +u, to the right
of the image, +y (green) up the image (towards decreasing v: wavetrace's v = 0
is the top row), +z (blue) out of the surface. Read it with
"colorspace": "linear".

The height field: 16 round bumps in four rows of four, one every 64 texels,
every other row shifted by half a bump (32 texels), so the image tiles on both
axes (four rows: an even number, so the stagger repeats too). A bump of radius
R = 26 texels has the height h(r) = H (1 - (r / R)^2)^2, H = 0.6 R: smooth
(its slope is 0 at the top and at the rim, where it meets the flat ground), at
most 1.54 H / R = 0.92 at r = R / sqrt(3) (43 degrees of tilt). The normal is
(-dh/dx, dh/drow, 1) normalized (x right, rows down: up the image is -row),
evaluated analytically at each texel's centre, so nothing is sampled and there
is no aliasing to filter.

Plain Python (zlib and struct): no numpy, no image library. The same bytes on
every run (for one zlib: the PNG's rows are filtered by a fixed rule and
compressed at level 9); read_png() decodes such a file back, for the tests.
"""

import argparse
import math
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_OUT = os.path.join(HERE, "..", "scenes", "textures", "bumps_normal.png")

SIZE = 256            # texels on each side
PITCH = 64            # bump spacing (SIZE / PITCH bumps a row, and rows)
RADIUS = 26.0         # bump radius, texels
HEIGHT = 0.6 * RADIUS  # bump height, texels


def bump_centres():
    """The bumps' centres (x, row) in texels, in one tile."""
    n = SIZE // PITCH
    return [((i + 0.5 + 0.5 * (j % 2)) * PITCH % SIZE, (j + 0.5) * PITCH) for j in range(n) for i in range(n)]


def gradient(x, y, centres):
    """(dh/dx, dh/drow) of the periodic height field at (x, y), texels."""
    gx = gy = 0.0
    for cx, cy in centres:
        # The nearest copy of the bump on the torus.
        dx = (x - cx + SIZE / 2) % SIZE - SIZE / 2
        dy = (y - cy + SIZE / 2) % SIZE - SIZE / 2
        s = (dx * dx + dy * dy) / (RADIUS * RADIUS)
        if s < 1.0:
            # h = H (1 - s)^2, s = r^2 / R^2: dh/dx = -4 H (1 - s) dx / R^2.
            k = -4.0 * HEIGHT * (1.0 - s) / (RADIUS * RADIUS)
            gx += k * dx
            gy += k * dy
    return gx, gy


def encode(c):
    """A component in [-1, 1] as an 8-bit value of c * 0.5 + 0.5."""
    return min(255, max(0, int(math.floor((c * 0.5 + 0.5) * 255.0 + 0.5))))


def normal_map():
    """The image: SIZE rows (top first) of SIZE * 3 bytes."""
    centres = bump_centres()
    rows = []
    for row in range(SIZE):
        line = bytearray()
        for col in range(SIZE):
            gx, gy = gradient(col + 0.5, row + 0.5, centres)
            nx, ny, nz = -gx, gy, 1.0     # up the image is -row: n.y = -dh/d(-row)
            inv = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
            line += bytes((encode(nx * inv), encode(ny * inv), encode(nz * inv)))
        rows.append(bytes(line))
    return rows


# ---------------------------------------------------------------- PNG

def _chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    return a if pa <= pb and pa <= pc else (b if pb <= pc else c)


def _filtered(kind, line, prev, bpp):
    out = bytearray(len(line))
    for i, v in enumerate(line):
        a = line[i - bpp] if i >= bpp else 0
        b = prev[i]
        c = prev[i - bpp] if i >= bpp else 0
        pred = (0, a, b, (a + b) // 2, _paeth(a, b, c))[kind]
        out[i] = (v - pred) & 0xFF
    return bytes(out)


def _unfiltered(kind, data, prev, bpp):
    out = bytearray(len(data))
    for i, v in enumerate(data):
        a = out[i - bpp] if i >= bpp else 0
        b = prev[i]
        c = prev[i - bpp] if i >= bpp else 0
        pred = (0, a, b, (a + b) // 2, _paeth(a, b, c))[kind]
        out[i] = (v + pred) & 0xFF
    return bytes(out)


def png_bytes(rows, width, height):
    """An 8-bit RGB PNG of ROWS (top first). Each row takes the filter whose
    output has the smallest sum of absolute values (libpng's heuristic)."""
    prev = bytes(3 * width)
    raw = bytearray()
    for line in rows:
        best = None
        for kind in range(5):
            f = _filtered(kind, line, prev, 3)
            cost = sum(v if v < 128 else 256 - v for v in f)
            if best is None or cost < best[0]:
                best = (cost, kind, f)
        raw += bytes((best[1],)) + best[2]
        prev = line
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr) + _chunk(b"IDAT", zlib.compress(bytes(raw), 9))
            + _chunk(b"IEND", b""))


def read_png(path):
    """(width, height, rows) of an 8-bit RGB, non-interlaced PNG (what
    png_bytes writes)."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("%s: not a PNG file" % path)
    pos, idat, head = 8, bytearray(), None
    while pos < len(data):
        (length,) = struct.unpack_from(">I", data, pos)
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            head = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = head
    if (depth, colour, interlace) != (8, 2, 0):
        raise ValueError("%s: not an 8-bit RGB non-interlaced PNG" % path)
    raw = zlib.decompress(bytes(idat))
    stride = 3 * width
    rows, prev = [], bytes(stride)
    for y in range(height):
        line = raw[y * (stride + 1):(y + 1) * (stride + 1)]
        prev = _unfiltered(line[0], line[1:], prev, 3)
        rows.append(prev)
    return width, height, rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", default=DEFAULT_OUT, help="PNG file to write")
    args = ap.parse_args()
    data = png_bytes(normal_map(), SIZE, SIZE)
    with open(args.output, "wb") as f:
        f.write(data)
    print("%s: %d x %d normal map, %d bumps, %d bytes" % (os.path.normpath(args.output), SIZE, SIZE,
                                                           len(bump_centres()), len(data)))


if __name__ == "__main__":
    main()
