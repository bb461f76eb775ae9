#!/usr/bin/env python3
"""Makes the converged reference images of tests/data/references/: the scenes
(and the small meshes, texture and environment they read), one reference image
each at a high sample count, and manifest.json, which says how each was made and
how a test should render against it.

    python3 tools/make_references.py scenes                 # the scene files and their data (plain Python)
    python3 tools/make_references.py render [NAME ...]      # the references and the manifest
    python3 tools/make_references.py check [NAME ...]       # wavetrace against each Mitsuba reference
    python3 tools/make_references.py time [NAME ...]        # the test's 16 renders per scene, on one core
    python3 tools/make_references.py manifest               # rewrite the manifest's fields that follow from
                                                            # scenes() (spp, covers, notes), keeping the rest
    python3 tools/make_references.py all                    # scenes, render, check, time

Options: --wavetrace BIN (default: build/wavetrace, copied to a temporary file
first so that a rebuild cannot change it under a render), --threads N (CPU
threads of the wavetrace renders, default all), --variant (Mitsuba's, default
llvm_ad_rgb; scalar_rgb also works, slowly).

Where wavetrace and Mitsuba 3 have the same models (Lambertian, perfect mirror,
emitters, uniform sky, lat-long environment, meshes, instances, image textures),
the reference is rendered by Mitsuba 3 through the peer (bench/mitsuba_peer.py,
which converts wavetrace scenes) with at least REFERENCE_FACTOR times the test's
total samples. Where they differ (glass: Schlick's Fresnel in wavetrace; fuzzy
metal; the gradient sky, which the peer approximates), the reference is rendered
by wavetrace itself on the CPU at 64 times the test's total samples
(WAVETRACE_FACTOR; more where a scene's test samples were lowered afterwards:
the manifest's reference_factor), with a seed that no test uses
(REFERENCE_SEED), and is marked "wavetrace-64x".

`render` and `check` need Python 3.12 with Mitsuba 3.7.1, Dr.Jit 1.2.0 and numpy
(only here, never in CI; the tests read the committed images):

    python3.12 -m pip install mitsuba==3.7.1 drjit==1.2.0 numpy
    python3.12 tools/make_references.py all

`scenes` needs plain Python only. Every render runs under `nice -n 10`.

The images are PFM as wavetrace writes them (`-o x.pfm`): "PF", width, height,
scale -1 (little-endian float32 RGB, linear), then the rows bottom row first;
tests/test_support.cpp's read_pfm returns them top row first, as renders hold
them.

The check (`check`) renders each scene with wavetrace over 16 seeds (101..116)
at 16 times the test's samples, light sampling on and off, and compares per 8x8
tile and channel: z = (mean of the seeds' tile means - the reference's tile
mean) / sigma, sigma = their standard deviation / sqrt(16) with a floor of
SIGMA_FLOOR x the reference's tile mean added in quadrature, and the mean image
ratio. Against a Mitsuba image that checks the model; against a wavetrace-64x
image only the statistic. The textured scenes are rendered a second time with
the texture flipped top to bottom, which shows what a texture drawn upside down
(issue 23's defect, fixed in b4da708) looks like to the comparison.
"""

import argparse
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, ".."))
OUT = os.path.join(ROOT, "tests", "data", "references")
sys.path.insert(0, HERE)
import scenefile  # noqa: E402  (a sibling: tools/scenefile.py)

# The test: SEEDS renders of SPP samples each per scene and light-sampling
# setting (seeds 1..SEEDS). A wavetrace reference is rendered with
# REFERENCE_SEED, which no test render may use, at WAVETRACE_FACTOR x
# SEEDS x spp samples; a Mitsuba reference at REFERENCE_FACTOR x that.
SEEDS = 16
WAVETRACE_FACTOR = 64
REFERENCE_FACTOR = 256
REFERENCE_SEED = 1000003
TILE = 8
WIDTH, HEIGHT = 64, 48
MITSUBA_VERSION, DRJIT_VERSION = "3.7.1", "1.2.0"
# Samples per mi.render call of a Mitsuba reference (each call its own seed).
MITSUBA_PASS_SPP = 256


# --------------------------------------------------------------------------
# Small files: PNG, OpenEXR, OBJ, glTF (plain Python)
# --------------------------------------------------------------------------

def write_png(path, width, height, rows):
    """8-bit RGB PNG; rows: top first, each a list of (r, g, b) in 0..255."""
    raw = b"".join(b"\0" + bytes(c for px in row for c in px) for row in rows)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(png)


def write_exr(path, width, height, rows):
    """Uncompressed scanline OpenEXR, channels B, G, R as float32; rows: top
    first, each a list of (r, g, b) floats."""
    def attr(name, kind, data):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(data)) + data

    chlist = b"".join(c + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in (b"B", b"G", b"R")) + b"\0"
    box = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = (struct.pack("<ii", 20000630, 2)
              + attr("channels", "chlist", chlist) + attr("compression", "compression", b"\0")
              + attr("dataWindow", "box2i", box) + attr("displayWindow", "box2i", box)
              + attr("lineOrder", "lineOrder", b"\0") + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    line_bytes = 8 + 12 * width
    start = len(header) + 8 * height
    table = b"".join(struct.pack("<Q", start + y * line_bytes) for y in range(height))
    body = b""
    for y, row in enumerate(rows):
        body += struct.pack("<ii", y, 12 * width)
        for ch in (2, 1, 0):
            body += struct.pack("<%df" % width, *[px[ch] for px in row])
    with open(path, "wb") as f:
        f.write(header + table + body)


def write_obj(path, positions, faces, uvs=None, groups=None, mtllib=None, header=None):
    """OBJ without normals (flat shading in both renderers). faces: index
    triples or quads (0-based), each index naming a position and, where uvs
    are given, the uv of the same number. groups: (material, faces) pairs."""
    lines = ["# " + h for h in (header or "").splitlines()]
    if mtllib:
        lines.append("mtllib " + mtllib)
    lines += ["v %.6g %.6g %.6g" % tuple(p) for p in positions]
    if uvs:
        lines += ["vt %.6g %.6g" % tuple(t) for t in uvs]
    for material, fs in (groups if groups is not None else [(None, faces)]):
        if material:
            lines.append("usemtl " + material)
        for f in fs:
            refs = ["%d/%d" % (i + 1, i + 1) if uvs else "%d" % (i + 1) for i in f]
            lines.append("f " + " ".join(refs))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def write_gltf(path, positions, normals, uvs, indices, texture_uri, material_name):
    """A .gltf (JSON) with its buffer in a .bin beside it and one textured
    Lambertian material whose baseColorTexture is the image texture_uri
    (relative to the file): metallic 0, roughness 1 and KHR_materials_specular's
    specularFactor 0, which leave glTF's BRDF its diffuse base alone, the model
    Mitsuba's reference renders. uvs in glTF's convention: v = 0 is the image's
    top row."""
    binname = os.path.splitext(os.path.basename(path))[0] + ".bin"
    blobs = [struct.pack("<%df" % (3 * len(positions)), *[c for p in positions for c in p]),
             struct.pack("<%df" % (3 * len(normals)), *[c for n in normals for c in n]),
             struct.pack("<%df" % (2 * len(uvs)), *[c for t in uvs for c in t]),
             struct.pack("<%dI" % len(indices), *indices)]
    views, offset = [], 0
    for b, target in zip(blobs, (34962, 34962, 34962, 34963)):
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(b), "target": target})
        offset += len(b)
    n = len(positions)
    doc = {
        "asset": {"version": "2.0", "generator": "wavetrace tools/make_references.py"},
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "quad"}],
        "meshes": [{"name": "quad", "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0, "mode": 4}]}],
        "extensionsUsed": ["KHR_materials_specular"],
        "materials": [{"name": material_name, "pbrMetallicRoughness": {
            "baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.0, "roughnessFactor": 1.0,
            "baseColorTexture": {"index": 0}}, "doubleSided": True,
            "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "minFilter": 9729, "wrapS": 10497, "wrapT": 10497}],
        "images": [{"uri": texture_uri}],
        "buffers": [{"uri": binname, "byteLength": offset}],
        "bufferViews": views,
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
             "min": [min(p[k] for p in positions) for k in range(3)],
             "max": [max(p[k] for p in positions) for k in range(3)]},
            {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5125, "count": len(indices), "type": "SCALAR"},
        ],
    }
    with open(path, "w") as f:
        f.write(json.dumps(doc, indent=1) + "\n")
    with open(os.path.join(os.path.dirname(path), binname), "wb") as f:
        f.write(b"".join(blobs))


# --------------------------------------------------------------------------
# The data files
# --------------------------------------------------------------------------

TEXTURE_SIZE = 16


def texture_rows():
    """16 x 16: a grey frame one texel wide (so that Mitsuba's wrapping of v,
    where wavetrace clamps, meets the same colour at the top and bottom edges),
    the top half red, the bottom half blue, a yellow block in the top-left
    corner and a white one in the bottom-left: upright, upside down and
    mirrored all look different."""
    n = TEXTURE_SIZE
    grey, red, blue = (160, 160, 160), (220, 40, 30), (30, 60, 210)
    yellow, white = (240, 220, 40), (250, 250, 250)
    rows = []
    for y in range(n):
        row = []
        for x in range(n):
            if x == 0 or y == 0 or x == n - 1 or y == n - 1:
                c = grey
            elif 2 <= y <= 4 and 2 <= x <= 6:
                c = yellow
            elif 11 <= y <= 13 and 2 <= x <= 4:
                c = white
            else:
                c = red if y < n // 2 else blue
            row.append(c)
        rows.append(row)
    return rows


ENV_W, ENV_H = 32, 16
SUN_DIR = (0.55, 0.62, 0.35)   # toward +x, up, a little toward +z (the camera's side)


def half(x):
    """x rounded to the nearest half float: wavetrace reads OpenEXR through
    Imf::RgbaInputFile, which hands every value over as a half, so a float32
    value that is not a half would be rounded there (by up to 2^-11) and not in
    Mitsuba."""
    return struct.unpack("<e", struct.pack("<e", x))[0]


def environment_rows():
    """A 32 x 16 lat-long sky (linear radiance): a blue zenith fading to a pale
    horizon, a brown ground below, a small bright sun up and toward +x, and a
    green patch on the horizon toward -x so that a mirrored or turned map is
    seen. Every value is a half float (see half()). Texel (i, j) looks along theta = (i + 0.5) / 16 pi, phi = (j + 0.5) /
    32 2 pi, direction (sin theta sin phi, cos theta, -sin theta cos phi)."""
    n = math.sqrt(sum(c * c for c in SUN_DIR))
    sun = [c / n for c in SUN_DIR]
    rows = []
    for i in range(ENV_H):
        theta = math.pi * (i + 0.5) / ENV_H
        row = []
        for j in range(ENV_W):
            phi = 2 * math.pi * (j + 0.5) / ENV_W
            d = (math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))
            if d[1] > 0:
                t = d[1]
                c = [0.9 - 0.6 * t, 0.95 - 0.45 * t, 1.0]
            else:
                c = [0.35, 0.25, 0.15]
            if abs(d[1]) < 0.3 and d[0] < -0.8:
                c = [0.1, 0.9, 0.15]
            cos_sun = sum(a * b for a, b in zip(d, sun))
            if cos_sun > 0.97:
                c = [14.0, 12.6, 10.5]
            row.append([half(x) for x in c])
        rows.append(row)
    return rows


def cube(lo=(-1, -1, -1), hi=(1, 1, 1)):
    """Positions and 6 quads of a box, counter-clockwise seen from outside."""
    p = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    idx = lambda x, y, z: 4 * x + 2 * y + z  # noqa: E731
    quads = [
        (idx(0, 0, 0), idx(0, 0, 1), idx(0, 1, 1), idx(0, 1, 0)),  # -x
        (idx(1, 0, 0), idx(1, 1, 0), idx(1, 1, 1), idx(1, 0, 1)),  # +x
        (idx(0, 0, 0), idx(1, 0, 0), idx(1, 0, 1), idx(0, 0, 1)),  # -y
        (idx(0, 1, 0), idx(0, 1, 1), idx(1, 1, 1), idx(1, 1, 0)),  # +y
        (idx(0, 0, 0), idx(0, 1, 0), idx(1, 1, 0), idx(1, 0, 0)),  # -z
        (idx(0, 0, 1), idx(1, 0, 1), idx(1, 1, 1), idx(0, 1, 1)),  # +z
    ]
    return p, quads


def icosahedron():
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
         (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    v = [tuple(c / math.sqrt(1 + t * t) for c in p) for p in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    return v, f


def write_data(out):
    """The meshes, texture and environment the scenes read."""
    made = []

    def name(f):
        made.append(f)
        return os.path.join(out, f)

    write_png(name("texture.png"), TEXTURE_SIZE, TEXTURE_SIZE, texture_rows())
    write_exr(name("sky.exr"), ENV_W, ENV_H, environment_rows())

    # A unit quad in x, y (z = 0) facing +z, OBJ's UVs: v = 0 at the bottom
    # (the image's bottom row), so the texture stands upright seen from +z.
    quad = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
    quad_uv = [(0, 0), (1, 0), (1, 1), (0, 1)]
    with open(name("textured-quad.mtl"), "w") as f:
        f.write("# tools/make_references.py: a white Lambertian with the test texture\n"
                "newmtl picture\nKd 1 1 1\nmap_Kd texture.png\n")
    write_obj(name("textured-quad.obj"), quad, [(0, 1, 2, 3)], uvs=quad_uv, groups=[("picture", [(0, 1, 2, 3)])],
              mtllib="textured-quad.mtl",
              header="unit quad, x and y in [-1, 1], z = 0, facing +z; OBJ UVs (v = 0: the image's bottom row)\n"
                     "tools/make_references.py")
    # The same quad as glTF: v = 0 is the image's top row there.
    write_gltf(name("textured-quad.gltf"), quad, [(0, 0, 1)] * 4, [(u, 1 - v) for u, v in quad_uv],
               [0, 1, 2, 0, 2, 3], "texture.png", "picture")
    made.append("textured-quad.bin")

    # A ground quad facing up (x, z in [-1, 1]).
    write_obj(name("ground.obj"), [(-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1)], [(0, 1, 2, 3)],
              header="ground quad: x, z in [-1, 1], y = 0, facing +y; tools/make_references.py")
    # A unit cube and an icosahedron (flat, no normals), placed by instances.
    p, q = cube()
    write_obj(name("cube.obj"), p, q, header="cube, [-1, 1]^3, faces outward; tools/make_references.py")
    v, f = icosahedron()
    write_obj(name("icosahedron.obj"), v, f, header="icosahedron, corners on the unit sphere; tools/make_references.py")

    # A Cornell-like room, x and z in [0, 2], y in [0, 2], open at z = 2
    # (toward the camera), with a square lamp filling a hole in the ceiling. The
    # lamp faces down (its geometric normal, (b - a) x (c - a), is -y), and has
    # nothing above it: Mitsuba's area lights emit on the front side only,
    # wavetrace's triangles on both, and here the back side lights nothing.
    a, b = 0.7, 1.3   # the lamp's square, in x and z
    pts = []

    def pt(x, y, z):
        pts.append((x, y, z))
        return len(pts) - 1

    def quad_xz(x0, x1, z0, z1, y, down):
        c = [pt(x0, y, z0), pt(x1, y, z0), pt(x1, y, z1), pt(x0, y, z1)]
        return tuple(c) if down else (c[0], c[3], c[2], c[1])

    floor = [quad_xz(0, 2, 0, 2, 0, False)]
    ceiling = [quad_xz(0, 2, 0, a, 2, True), quad_xz(0, 2, b, 2, 2, True),
               quad_xz(0, a, a, b, 2, True), quad_xz(b, 2, a, b, 2, True)]
    lamp = [quad_xz(a, b, a, b, 2, True)]
    back = [(pt(0, 0, 0), pt(2, 0, 0), pt(2, 2, 0), pt(0, 2, 0))]
    left = [(pt(0, 0, 0), pt(0, 2, 0), pt(0, 2, 2), pt(0, 0, 2))]
    right = [(pt(2, 0, 0), pt(2, 0, 2), pt(2, 2, 2), pt(2, 2, 0))]
    with open(name("room.mtl"), "w") as f:
        f.write("# tools/make_references.py: the room's materials\n"
                "newmtl white\nKd 0.75 0.75 0.72\n\n"
                "newmtl red\nKd 0.7 0.08 0.06\n\n"
                "newmtl green\nKd 0.12 0.5 0.15\n\n"
                "newmtl lamp\nKd 0 0 0\nKe 12 10 7\n")
    write_obj(name("room.obj"), pts, None, groups=[("white", floor + ceiling + back), ("red", left),
                                                  ("green", right), ("lamp", lamp)],
              mtllib="room.mtl",
              header="room: x, y, z in [0, 2], open at z = 2; lamp in a hole of the ceiling, facing down\n"
                     "tools/make_references.py")

    # A closed box seen from inside (faces inward): the deep-path scene.
    p, q = cube((0, 0, 0), (2, 2, 2))
    write_obj(name("closed-box.obj"), p, [tuple(reversed(x)) for x in q],
              header="closed box, [0, 2]^3, faces inward; tools/make_references.py")
    return made


# --------------------------------------------------------------------------
# The scenes
# --------------------------------------------------------------------------

def render_section(spp, depth, roulette_depth):
    return {"width": WIDTH, "height": HEIGHT, "spp": spp, "depth": depth, "roulette_depth": roulette_depth,
            "seed": 1, "nee": 1}


# Each: name -> (scene dict, renderer, test spp per seed, what it covers).
def scenes():
    s = {}
    # Black sky: the lamps are the only lights, so light sampling picks them
    # (by power) and every tile sees the ground or a sphere. The lamps are large
    # (radius 0.6): the mirror's caustics of small bright lamps on the ground are
    # found only by the BSDF's paths, rarely and brightly, and at the test's sample
    # count their tiles' means and variances both fall short (z down to -6 with
    # lamps of radius 0.3, where 16 times the samples shows no bias).
    s["spheres"] = ({
        "camera": {"look_from": [0, 4.0, 3.9], "look_at": [0, 0.55, 0], "vfov": 36},
        "sky": {"type": "uniform", "radiance": [0, 0, 0]},
        "render": render_section(32, 8, 4),
        "materials": [
            {"name": "ground", "type": "lambertian", "albedo": [0.6, 0.6, 0.55]},
            {"name": "clay", "type": "lambertian", "albedo": [0.8, 0.35, 0.2]},
            {"name": "teal", "type": "lambertian", "albedo": [0.15, 0.55, 0.6]},
            {"name": "mirror", "type": "metal", "albedo": [0.9, 0.9, 0.9], "fuzz": 0},
            {"name": "warm", "type": "emissive", "emission": [4, 3, 2]},
            {"name": "cool", "type": "emissive", "emission": [1.25, 2, 4]},
        ],
        "spheres": [
            {"center": [0, -30, 0], "radius": 30, "material": "ground"},
            {"center": [-1.3, 0.6, 0], "radius": 0.6, "material": "clay"},
            {"center": [0, 0.6, -0.4], "radius": 0.6, "material": "mirror"},
            {"center": [1.3, 0.6, 0], "radius": 0.6, "material": "teal"},
            {"center": [-1.9, 1.5, 0.9], "radius": 0.6, "material": "warm"},
            {"center": [1.7, 1.6, -1.1], "radius": 0.6, "material": "cool"},
        ],
    }, "mitsuba", "spheres; Lambertian, perfect mirror; emissive spheres of two powers (the only lights)")

    s["room"] = ({
        "camera": {"look_from": [1, 1, 4.4], "look_at": [1, 0.95, 0], "vfov": 36},
        "sky": {"type": "uniform", "radiance": [0, 0, 0]},
        "render": render_section(6, 10, 4),
        "materials": [
            {"name": "block", "type": "lambertian", "albedo": [0.7, 0.7, 0.65]},
            {"name": "mirror", "type": "metal", "albedo": [0.85, 0.85, 0.85], "fuzz": 0},
        ],
        "meshes": [
            {"name": "room", "file": "room.obj"},
            {"name": "cube", "file": "cube.obj", "material": "block"},
            {"name": "ico", "file": "icosahedron.obj"},
        ],
        "instances": [
            {"mesh": "room"},
            {"mesh": "cube", "translate": [0.6, 0.6, 0.6], "rotate": [0, 20, 0], "scale": [0.3, 0.6, 0.3]},
            {"mesh": "cube", "translate": [1.4, 0.28, 1.2], "rotate": [0, -25, 0], "scale": [-0.28, 0.28, 0.28]},
            {"mesh": "ico", "material": "mirror",
             "matrix": [0.35, 0, 0, 1.45, 0, 0.35, 0, 1.0, 0, 0, 0.35, 0.5, 0, 0, 0, 1]},
        ],
    }, "mitsuba", "OBJ meshes with MTL materials (Lambertian, emissive); emissive triangles (area light); "
                  "instances (translate/rotate/scale, a mirroring scale, a matrix); mirror on a mesh; no sky")

    textured_common = {
        "sky": {"type": "uniform", "radiance": [0.45, 0.45, 0.45]},
        "render": render_section(24, 6, 4),
        "materials": [
            {"name": "floor", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]},
            {"name": "wall", "type": "lambertian", "albedo": [0.7, 0.68, 0.6]},
            {"name": "lamp", "type": "emissive", "emission": [6, 6, 5]},
        ],
        "spheres": [{"center": [-1.6, 2.0, 1.4], "radius": 0.3, "material": "lamp"}],
    }
    for fmt, ext in (("obj", "obj"), ("gltf", "gltf")):
        d = {"camera": {"look_from": [0.3, 1.0, 4.0], "look_at": [0, 0.95, 0], "vfov": 34}}
        d.update(json.loads(json.dumps(textured_common)))
        d["meshes"] = [{"name": "picture", "file": "textured-quad." + ext},
                       {"name": "ground", "file": "ground.obj", "material": "floor"}]
        # The ground, and a wall behind the picture (the ground quad stood up,
        # facing +z), so that no tile sees only the sky.
        d["instances"] = [{"mesh": "picture", "translate": [0, 1.05, 0], "rotate": [0, 12, 0],
                           "scale": [1.2, 0.9, 1]},
                          {"mesh": "ground", "scale": [4, 1, 4]},
                          {"mesh": "ground", "translate": [0, 2, -1.2], "rotate": [90, 0, 0], "scale": [4, 1, 2],
                           "material": "wall"}]
        what = ("OBJ with MTL map_Kd" if fmt == "obj" else "glTF with baseColorTexture")
        s["texture-" + fmt] = (d, "mitsuba", "a textured mesh from %s (sRGB PNG, upright: red half on top, "
                                             "yellow block top left); uniform sky; emissive sphere" % what)

    s["environment"] = ({
        "camera": {"look_from": [0, 1.1, 4.6], "look_at": [0, 0.6, 0], "vfov": 32},
        "sky": {"type": "environment", "file": "sky.exr", "mapping": "latlong", "rotation": 0, "intensity": 1},
        "render": render_section(48, 8, 4),
        "materials": [
            {"name": "floor", "type": "lambertian", "albedo": [0.6, 0.6, 0.6]},
            {"name": "white", "type": "lambertian", "albedo": [0.8, 0.8, 0.8]},
            {"name": "mirror", "type": "metal", "albedo": [0.95, 0.95, 0.95], "fuzz": 0},
        ],
        "spheres": [
            {"center": [-0.7, 0.6, 0], "radius": 0.6, "material": "white"},
            {"center": [0.7, 0.6, 0], "radius": 0.6, "material": "mirror"},
        ],
        "meshes": [{"name": "ground", "file": "ground.obj", "material": "floor"}],
        "instances": [{"mesh": "ground", "scale": [2.2, 1, 1.6]}],
    }, "mitsuba", "lat-long environment sky (OpenEXR, importance sampled) with a sun, seen in a mirror sphere; "
                  "spheres and an OBJ ground")

    s["deep"] = ({
        "camera": {"look_from": [1, 1, 1.95], "look_at": [1, 0.9, 0], "vfov": 62},
        "sky": {"type": "uniform", "radiance": [0, 0, 0]},
        "render": render_section(4, 64, 1),
        "materials": [
            {"name": "wall", "type": "lambertian", "albedo": [0.88, 0.86, 0.8]},
            {"name": "ball", "type": "lambertian", "albedo": [0.3, 0.6, 0.85]},
            {"name": "lamp", "type": "emissive", "emission": [5, 4.5, 4]},
        ],
        "spheres": [
            {"center": [1.4, 1.55, 0.6], "radius": 0.22, "material": "lamp"},
            {"center": [0.65, 0.45, 0.7], "radius": 0.45, "material": "ball"},
        ],
        "meshes": [{"name": "box", "file": "closed-box.obj", "material": "wall"}],
        "instances": [{"mesh": "box"}],
    }, "mitsuba", "deep paths: a closed box of albedo 0.88 seen from inside, depth 64, Russian roulette from "
                  "bounce 1; emissive sphere")

    s["glass"] = ({
        "camera": {"look_from": [0, 1.2, 5], "look_at": [0, 0.7, 0], "vfov": 30},
        "sky": {"type": "gradient", "horizon": [1, 0.95, 0.9], "zenith": [0.35, 0.55, 1.0]},
        "render": render_section(32, 12, 5),
        "textures": [{"name": "tiles", "type": "checker", "size": 0.5, "even": [0.85, 0.85, 0.85],
                      "odd": [0.15, 0.15, 0.2]}],
        "materials": [
            {"name": "ground", "type": "lambertian", "albedo": [1, 1, 1], "texture": "tiles"},
            {"name": "glass", "type": "dielectric", "ior": 1.5},
            {"name": "tinted", "type": "dielectric", "ior": 1.33, "albedo": [0.8, 0.95, 0.85]},
            {"name": "red", "type": "lambertian", "albedo": [0.85, 0.2, 0.15]},
            {"name": "lamp", "type": "emissive", "emission": [8, 7, 5]},
        ],
        "spheres": [
            {"center": [0, -30, 0], "radius": 30, "material": "ground"},
            {"center": [-0.5, 0.7, 0.4], "radius": 0.7, "material": "glass"},
            {"center": [1.1, 0.45, 0.2], "radius": 0.45, "material": "tinted"},
            {"center": [-0.2, 0.5, -1.6], "radius": 0.5, "material": "red"},
            {"center": [1.2, 1.9, -0.8], "radius": 0.3, "material": "lamp"},
        ],
    }, "wavetrace-64x", "glass (Schlick's Fresnel: wavetrace's model), a tinted dielectric; gradient sky (not "
                        "sampled); checker texture; emissive sphere")

    s["metal"] = ({
        "camera": {"look_from": [0, 1.4, 4.8], "look_at": [0, 0.6, 0], "vfov": 32},
        "sky": {"type": "uniform", "radiance": [0.12, 0.12, 0.15]},
        "render": render_section(20, 10, 3),
        "materials": [
            {"name": "floor", "type": "metal", "albedo": [0.75, 0.75, 0.8], "fuzz": 0.35},
            {"name": "gold", "type": "metal", "albedo": [0.95, 0.75, 0.35], "fuzz": 0.1},
            {"name": "steel", "type": "metal", "albedo": [0.8, 0.8, 0.8], "fuzz": 0.5},
            {"name": "copper", "type": "metal", "albedo": [0.9, 0.5, 0.35], "fuzz": 1.0},
            {"name": "lacquer", "type": "coated", "albedo": [0.2, 0.35, 0.8], "ior": 1.5},
            {"name": "wall", "type": "lambertian", "albedo": [0.55, 0.6, 0.65]},
            {"name": "panel", "type": "emissive", "emission": [6, 6, 5.5]},
        ],
        "spheres": [
            {"center": [-1.35, 0.5, 0], "radius": 0.5, "material": "gold"},
            {"center": [-0.35, 0.5, -0.3], "radius": 0.5, "material": "steel"},
            {"center": [0.65, 0.5, 0], "radius": 0.5, "material": "copper"},
            {"center": [1.55, 0.4, 0.5], "radius": 0.4, "material": "lacquer"},
        ],
        "meshes": [{"name": "ground", "file": "ground.obj", "material": "floor"},
                   {"name": "panel", "file": "ground.obj", "material": "panel"}],
        "instances": [{"mesh": "ground", "scale": [3, 1, 2]},
                      {"mesh": "ground", "translate": [0, 2, -2], "rotate": [90, 0, 0], "scale": [3, 1, 2],
                       "material": "wall"},
                      {"mesh": "panel", "translate": [0.3, 2.2, 0.6], "rotate": [180, 0, 0], "scale": [0.8, 1, 0.4]}],
    }, "wavetrace-64x", "fuzzy metal (fuzz 0.1 to 1, on spheres and a mesh floor: wavetrace's model), a coated "
                        "sphere; emissive triangles (a panel, sampled by the fuzzy metals too); uniform sky")
    return s


def write_scenes(out=OUT):
    os.makedirs(out, exist_ok=True)
    made = write_data(out)
    for name, (doc, renderer, what) in scenes().items():
        with open(os.path.join(out, name + ".json"), "w") as f:
            f.write(scenefile.dumps_scene(doc))
        made.append(name + ".json")
    for f in made:
        print("%s: %d bytes" % (os.path.relpath(os.path.join(out, f), ROOT), os.path.getsize(os.path.join(out, f))))


# --------------------------------------------------------------------------
# Images (numpy from here on)
# --------------------------------------------------------------------------

def read_pfm(path):
    """A PFM as an H x W x 3 float32 array, top row first."""
    import numpy as np
    with open(path, "rb") as f:
        data = f.read()
    parts, pos = [], 0
    while len(parts) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        parts.append(data[pos:end].decode())
        pos = end
    pos += 1
    kind, w, h, scale = parts[0], int(parts[1]), int(parts[2]), float(parts[3])
    if kind != "PF":
        raise ValueError("%s: not an RGB PFM" % path)
    img = np.frombuffer(data[pos:pos + 12 * w * h], dtype="<f4" if scale < 0 else ">f4").reshape(h, w, 3)
    return img[::-1].astype(np.float32)


def write_pfm(path, img):
    """H x W x 3, top row first -> PFM, bottom row first, little-endian (as wavetrace writes)."""
    import numpy as np
    h, w, _ = img.shape
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())
    os.replace(tmp, path)


def write_preview(path, img):
    """An 8-bit sRGB PNG of a linear image (for looking at it)."""
    import numpy as np
    x = np.clip(img, 0, 1)
    x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    b = np.round(x * 255).astype(int)
    write_png(path, img.shape[1], img.shape[0], [[tuple(px) for px in row] for row in b])


def tile_means(img):
    h, w, c = img.shape
    return img.reshape(h // TILE, TILE, w // TILE, TILE, c).mean(axis=(1, 3))


# --------------------------------------------------------------------------
# Renderers
# --------------------------------------------------------------------------

class Wavetrace:
    def __init__(self, binary, threads):
        self.binary, self.threads = binary, threads

    def render(self, scene, out, spp, seed, nee, extra=()):
        cmd = ["nice", "-n", "10", self.binary, "render", scene, "-o", out, "--backend", "cpu",
               "--spp", str(spp), "--seed", str(seed), "--nee", str(nee)] + list(extra)
        if self.threads:
            cmd += ["--threads", str(self.threads)]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError("%s\n%s" % (" ".join(cmd), r.stderr))
        return read_pfm(out)


def wavetrace_binary(path):
    """A private copy of the binary: build/ may be rebuilt while we render."""
    fd, copy = tempfile.mkstemp(prefix="wt-ref-bin-")
    os.close(fd)
    shutil.copy2(path, copy)
    os.chmod(copy, 0o755)
    return copy


def renice():
    try:
        os.nice(10)
    except OSError:
        pass


def mitsuba_render(scene_path, spp_total, variant, seed_base=REFERENCE_SEED, nee=1, doc=None):
    """Mitsuba 3 through the peer's conversion: passes of MITSUBA_PASS_SPP
    samples, each with its own seed, averaged in double."""
    import numpy as np
    sys.path.insert(0, os.path.join(ROOT, "bench"))
    import mitsuba_peer
    conv = mitsuba_peer.convert(scene_path, spp=MITSUBA_PASS_SPP, nee=nee, doc=doc)
    import mitsuba as mi
    import drjit as dr
    mi.set_variant(variant)
    scene = mitsuba_peer.load_scene(conv, variant)
    acc = None
    done, k = 0, 0
    while done < spp_total:
        n = min(MITSUBA_PASS_SPP, spp_total - done)
        img = np.array(mi.render(scene, spp=n, seed=seed_base + k), dtype=np.float64)
        acc = img * n if acc is None else acc + img * n
        done += n
        k += 1
    info = {"mitsuba": mi.__version__, "drjit": dr.__version__, "variant": variant, "notes": conv.notes}
    return (acc / done).astype(np.float32), info


# --------------------------------------------------------------------------
# Environment images for Mitsuba: the same radiance function
# --------------------------------------------------------------------------

def mitsuba_environment(path, cache):
    """wavetrace looks a lat-long image up bilinearly with texel centres at
    ((j + 0.5) / W, (i + 0.5) / H), u wrapping, v clamped. Mitsuba 3.7.1's
    envmap has the same columns but puts its rows at v = i / (H - 1)
    (bench/README.md; measured through the emitter's eval). An image of the
    same columns and 2H + 1 rows holds wavetrace's function exactly in
    Mitsuba: row 2i + 1 is texel row i (at v = (2i + 1) / 2H), row 2i + 2 the
    mean of rows i and i + 1 (wavetrace is linear in v between them), and the
    first and last rows repeat the edge rows (wavetrace clamps within half a
    texel of the poles). Returns the path of that image (OpenEXR, float32)."""
    import numpy as np
    import mitsuba as mi
    src = np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False), dtype=np.float64)
    h, w, _ = src.shape
    out = np.empty((2 * h + 1, w, 3))
    out[1::2] = src
    out[2:-1:2] = 0.5 * (src[:-1] + src[1:])
    out[0], out[-1] = src[0], src[-1]
    dst = os.path.join(cache, "mitsuba-" + os.path.splitext(os.path.basename(path))[0] + ".exr")
    write_exr(dst, w, 2 * h + 1, out.tolist())
    return dst


def mitsuba_doc(scene_path, cache):
    """The scene as the peer should see it: an environment sky's image
    replaced by its exact Mitsuba equivalent (mitsuba_environment)."""
    with open(scene_path) as f:
        doc = json.load(f)
    sky = doc.get("sky", {})
    if sky.get("type") == "environment":
        if sky.get("mapping", "latlong") != "latlong":
            raise ValueError("only lat-long environments are converted exactly")
        sky["file"] = mitsuba_environment(os.path.join(os.path.dirname(scene_path), sky["file"]), cache)
    return doc


# --------------------------------------------------------------------------
# Commands
# --------------------------------------------------------------------------

def manifest_path():
    return os.path.join(OUT, "manifest.json")


def load_manifest():
    if os.path.exists(manifest_path()):
        with open(manifest_path()) as f:
            return json.load(f)
    return {"references": []}


# What a render, a check or a timing added to an entry (the rest follows from
# scenes() and is written afresh).
MEASURED = ("renderer", "reference_spp", "reference_seconds", "notes", "agreement", "test_seconds")


def save_manifest(m):
    m["about"] = ("Converged references: tools/make_references.py. Images are PFM as wavetrace writes them "
                  "(little-endian float32 RGB, linear, bottom row first; tests/test_support.cpp read_pfm "
                  "returns row 0 = top). A test renders each scene with test.seeds seeds (first_seed on), "
                  "test.spp_per_seed samples each, with light sampling on and off, at width x height, depth "
                  "and roulette_depth, and compares per tile x tile against the image. Seed %d made the "
                  "wavetrace references: no test may use it. In agreement, worst_tile is [column, row, "
                  "channel] of 8 x 8 tiles, counted from the top left." % REFERENCE_SEED)
    for old in m["references"]:   # in place: callers hold these dicts
        e = entry(old["name"])
        e.update({k: old[k] for k in MEASURED if k in old})
        if "reference_spp" in e:
            e["reference_factor"] = round(e["reference_spp"] / (SEEDS * e["test"]["spp_per_seed"]), 1)
        old.clear()
        old.update(e)
    m["references"].sort(key=lambda r: list(scenes()).index(r["name"]))
    with open(manifest_path() + ".tmp", "w") as f:
        json.dump(m, f, indent=1)
        f.write("\n")
    os.replace(manifest_path() + ".tmp", manifest_path())


def git_commit():
    """HEAD, with "+changes" where the sources the binary is built from differ
    from it (the binary may have been built from the working tree)."""
    r = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    if r.returncode != 0:
        return None
    d = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--", "src", "include", "CMakeLists.txt"],
                       capture_output=True, text=True)
    return r.stdout.strip() + ("+changes" if d.stdout.strip() else "")


def sha256(path):
    import hashlib
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def entry(name):
    doc, renderer, what = scenes()[name]
    r = doc["render"]
    return {"name": name, "scene": name + ".json", "image": name + ".pfm",
            "width": r["width"], "height": r["height"], "depth": r["depth"], "roulette_depth": r["roulette_depth"],
            "test": {"spp_per_seed": r["spp"], "seeds": SEEDS, "first_seed": 1, "nee": [0, 1],
                     "backend": "cpu", "tile": TILE},
            "covers": what, "data_notes": data_notes(doc, renderer)}


def data_notes(doc, renderer):
    """How the scene's data are made so that both renderers see the same thing."""
    notes = []
    files = [m["file"] for m in doc.get("meshes", [])]
    if any(f.startswith("textured-quad") for f in files):
        notes.append("texture.png (16 x 16, sRGB) has a grey frame one texel wide: Mitsuba's bitmap wraps v where "
                     "wavetrace clamps it, and meets the same colour either way. Upright means red half on top, "
                     "yellow block top left, white block bottom left, as in the file")
    if doc.get("sky", {}).get("type") == "environment":
        notes.append("sky.exr's values are half floats (wavetrace reads OpenEXR as halves). Mitsuba was handed it "
                     "resampled to 2H + 1 rows (make_references.py mitsuba_environment): Mitsuba's envmap puts row i "
                     "at v = i / (H - 1), wavetrace at (i + 0.5) / H, and the resampled image is wavetrace's bilinear "
                     "function exactly (the peer's own conversion differs by up to 9% in a tile here)")
    if "room.obj" in files:
        notes.append("the lamp (MTL Ke) faces down, filling a hole of the ceiling, with nothing behind it: Mitsuba's "
                     "area lights emit on their front side only, wavetrace's triangles on both")
    if renderer == "mitsuba":
        notes.append("Mitsuba rendered with light sampling on; the reference holds for either setting")
    return notes


def cmd_render(args, names):
    import numpy as np
    renice()
    m = load_manifest()
    by_name = {r["name"]: r for r in m["references"]}
    cache = tempfile.mkdtemp(prefix="wt-references-")
    wt = Wavetrace(args.binary, args.threads)
    for name in names:
        doc, renderer, what = scenes()[name]
        e = entry(name)
        scene_path = os.path.join(OUT, name + ".json")
        test_total = SEEDS * e["test"]["spp_per_seed"]
        t0 = time.time()
        if renderer == "mitsuba":
            spp = REFERENCE_FACTOR * test_total
            img, info = mitsuba_render(scene_path, spp, args.variant, doc=mitsuba_doc(scene_path, cache))
            e["renderer"] = {"name": "mitsuba", "version": info["mitsuba"], "drjit": info["drjit"],
                             "variant": info["variant"], "integrator": "path (bench/mitsuba_peer.py's conversion)",
                             "nee": 1}
            e["notes"] = info["notes"]
        else:
            spp = WAVETRACE_FACTOR * test_total
            out = os.path.join(cache, name + ".pfm")
            img = wt.render(scene_path, out, spp, REFERENCE_SEED, 1)
            e["renderer"] = {"name": "wavetrace-64x", "commit": git_commit(), "binary_sha256": sha256(args.binary),
                             "backend": "cpu", "kernel": "megakernel", "seed": REFERENCE_SEED, "nee": 1}
            e["notes"] = ["rendered by wavetrace itself (its models of glass, fuzzy metal and the gradient sky "
                          "differ from Mitsuba's): a change detector at converged precision, not an independent "
                          "reference"]
        e["reference_spp"] = spp
        e["reference_seconds"] = round(time.time() - t0, 1)
        if not np.all(np.isfinite(img)):
            raise RuntimeError("%s: non-finite pixels" % name)
        write_pfm(os.path.join(OUT, name + ".pfm"), img)
        write_preview(os.path.join(OUT, "preview", name + ".png"), img)
        old = by_name.get(name, {})
        for k in ("agreement", "test_seconds"):
            if k in old:
                e[k] = old[k]
        by_name[name] = e
        m["references"] = list(by_name.values())
        save_manifest(m)
        print("%s: %s, %d spp, %.1f s, mean %s" % (name, e["renderer"]["name"], spp, time.time() - t0,
                                                   np.round(img.mean(axis=(0, 1)), 4)), flush=True)
    shutil.rmtree(cache, ignore_errors=True)


def flipped_copy(folder):
    """A copy of the references folder with texture.png flipped top to bottom."""
    dst = tempfile.mkdtemp(prefix="wt-references-flipped-")
    for f in os.listdir(OUT):
        if os.path.isfile(os.path.join(OUT, f)) and not f.endswith(".pfm"):
            shutil.copy2(os.path.join(OUT, f), dst)
    write_png(os.path.join(dst, "texture.png"), TEXTURE_SIZE, TEXTURE_SIZE, texture_rows()[::-1])
    return dst


# A floor under a tile's sigma, relative to the reference's tile mean: a tile
# whose estimate hardly varies (a uniform sky's radiance, seen directly, is the
# same in every sample) would otherwise fail on the two renderers' float
# rounding (a few 1e-6 relative, measured).
SIGMA_FLOOR = 1e-4


def compare(renders, ref):
    """renders: seeds x H x W x 3. Per tile and channel: z of the seeds' mean
    against the reference, sigma = the seeds' standard deviation / sqrt(seeds)
    with the floor SIGMA_FLOOR x |reference| added in quadrature; the mean image
    ratio, and the largest relative difference of a tile."""
    import numpy as np
    t = np.stack([tile_means(r) for r in renders])        # seeds x th x tw x 3
    mean, sd = t.mean(axis=0), t.std(axis=0, ddof=1)
    rt = tile_means(ref)
    sigma = np.sqrt(sd ** 2 / len(renders) + (SIGMA_FLOOR * np.abs(rt)) ** 2)
    z = (mean - rt) / np.maximum(sigma, 1e-30)
    i = np.unravel_index(np.argmax(np.abs(z)), z.shape)
    rel = (mean - rt) / np.maximum(np.abs(rt), 1e-12)
    ratio = float(np.mean(renders) / np.mean(ref))
    return {"max_abs_z": round(float(np.abs(z).max()), 2), "worst_tile": [int(i[1]), int(i[0]), "rgb"[i[2]]],
            "tiles_over_4": int(np.sum(np.abs(z) > 4)), "mean_ratio": round(ratio, 5),
            "worst_tile_rel_diff": round(float(rel[i]), 5),
            "max_abs_rel_diff": round(float(np.abs(rel).max()), 5),
            "floor_bound_tiles": int(np.sum(sd / math.sqrt(len(renders)) < SIGMA_FLOOR * np.abs(rt)))}, z


def cmd_check(args, names):
    import numpy as np
    renice()
    m = load_manifest()
    by_name = {r["name"]: r for r in m["references"]}
    work = tempfile.mkdtemp(prefix="wt-check-")
    flipped = flipped_copy(OUT)
    wt = Wavetrace(args.binary, args.threads)
    for name in names:
        e = by_name.get(name)
        if e is None:
            print("%s: no reference yet (run render first)" % name)
            continue
        ref = read_pfm(os.path.join(OUT, e["image"]))
        spp = args.check_factor * e["test"]["spp_per_seed"]
        folders = [("as_is", OUT)]
        if name.startswith("texture-"):
            folders.append(("texture_flipped", flipped))
        agreement = {"renders": "%d seeds x %d spp (%d x the test's), wavetrace CPU megakernel, seeds 101.." % (
            SEEDS, spp, args.check_factor), "commit": git_commit(), "binary_sha256": sha256(args.binary),
            "tile": TILE, "sigma_floor": SIGMA_FLOOR}
        if e["renderer"]["name"] != "mitsuba":
            agreement["what"] = ("wavetrace against its own image: a check of the statistic (z over 16 seeds, the "
                                 "floor), not of the model")
        if len(folders) > 1:
            agreement["texture_flipped"] = ("the same renders with texture.png flipped top to bottom: what a texture "
                                            "shown upside down (issue 23's defect, the 'texture v flipped' mutant) "
                                            "looks like to this comparison")
        for label, folder in folders:
            for nee in (1, 0):
                renders = []
                for s in range(SEEDS):
                    out = os.path.join(work, "%s-%s-%d-%d.pfm" % (name, label, nee, s))
                    renders.append(wt.render(os.path.join(folder, name + ".json"), out, spp, 101 + s, nee))
                res, z = compare(renders, ref)
                key = "nee%d" % nee + ("" if label == "as_is" else "_" + label)
                agreement[key] = res
                if args.previews:
                    write_preview(os.path.join(args.previews, "%s-wavetrace-%s.png" % (name, key)),
                                  np.mean(renders, axis=0))
                print("%-12s %-22s max|z| %6.2f at tile %s, tiles |z|>4: %3d, mean ratio %.4f" % (
                    name, key, res["max_abs_z"], res["worst_tile"], res["tiles_over_4"], res["mean_ratio"]),
                    flush=True)
        e["agreement"] = agreement
        save_manifest(m)
    shutil.rmtree(work, ignore_errors=True)
    shutil.rmtree(flipped, ignore_errors=True)


def cmd_time(args, names):
    """The test's renders on one core: SEEDS renders of spp_per_seed, each
    setting of nee, one thread. Reported as the CPU time (user + system) of the
    commands, start-up and scene load included, which another load on the
    machine changes less, and as wall clock; the least of --repeats tries."""
    import resource
    renice()
    m = load_manifest()
    by_name = {r["name"]: r for r in m["references"]}
    work = tempfile.mkdtemp(prefix="wt-time-")
    wt = Wavetrace(args.binary, 1)

    def cpu():
        r = resource.getrusage(resource.RUSAGE_CHILDREN)
        return r.ru_utime + r.ru_stime

    for name in names:
        doc = scenes()[name][0]
        spp = doc["render"]["spp"]
        secs = {}
        for _ in range(args.repeats):
            for nee in (1, 0):
                t0, c0 = time.time(), cpu()
                for s in range(SEEDS):
                    wt.render(os.path.join(OUT, name + ".json"), os.path.join(work, "t.pfm"), spp, 1 + s, nee)
                for key, value in (("nee%d_cpu" % nee, cpu() - c0), ("nee%d_wall" % nee, time.time() - t0)):
                    secs[key] = round(min(secs.get(key, value), value), 2)
        print("%-12s %d x %d spp, one thread: nee 1 %.2f s CPU (%.2f s wall), nee 0 %.2f s CPU (%.2f s wall)" % (
            name, SEEDS, spp, secs["nee1_cpu"], secs["nee1_wall"], secs["nee0_cpu"], secs["nee0_wall"]), flush=True)
        if name in by_name:
            by_name[name]["test_seconds"] = dict(secs, what="%d renders of %d spp with --threads 1 --backend cpu: "
                                                 "CPU time (user + system) and wall clock of the commands, "
                                                 "process start and scene load included; the least of %d "
                                                 "tries" % (SEEDS, spp, args.repeats))
            save_manifest(m)
    shutil.rmtree(work, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("command", choices=("scenes", "render", "check", "time", "manifest", "all"))
    ap.add_argument("names", nargs="*", help="references (default: all)")
    ap.add_argument("--wavetrace", default=os.path.join(ROOT, "build", "wavetrace"))
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--check-factor", type=int, default=16,
                    help="the check renders this many times the test's samples per seed")
    ap.add_argument("--previews", help="folder for PNGs of the check's wavetrace means")
    ap.add_argument("--repeats", type=int, default=3, help="tries of each timing (the least is kept)")
    args = ap.parse_args()
    names = args.names or list(scenes())
    unknown = [n for n in names if n not in scenes()]
    if unknown:
        sys.exit("unknown references: %s (known: %s)" % (", ".join(unknown), ", ".join(scenes())))
    if args.command in ("scenes", "all"):
        write_scenes()
    if args.command == "scenes":
        return
    if args.command == "manifest":   # rewrite the fields that follow from scenes(), keep what was measured
        save_manifest(load_manifest())
        return
    if args.previews:
        os.makedirs(args.previews, exist_ok=True)
    os.makedirs(os.path.join(OUT, "preview"), exist_ok=True)
    args.binary = wavetrace_binary(args.wavetrace)
    try:
        if args.command in ("render", "all"):
            cmd_render(args, names)
        if args.command in ("check", "all"):
            cmd_check(args, names)
        if args.command in ("time", "all"):
            cmd_time(args, names)
    finally:
        os.unlink(args.binary)


if __name__ == "__main__":
    main()
