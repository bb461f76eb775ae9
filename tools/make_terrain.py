#!/usr/bin/env python3
"""Writes scenes/terrain.json and its meshes: a million-triangle height field with rocks on it.

    python3 tools/make_terrain.py [-o scenes/terrain.json]

Meshes, written to generated/ beside the scene file (scenes/generated/, which
git ignores; about 30 MB, regenerated in ~10 s):

- generated/terrain.glb: a 200 m x 200 m height field, x and z in [-100, 100],
  a grid of 708 x 708 quads (709 x 709 vertices), two triangles a quad:
  1,002,528 triangles. Heights are six octaves of value noise (a lattice of
  seeded random values, quintic fade) written here, shaped into valleys and
  ridges, up to about 30 m. Smooth normals by central differences of the
  heights, UVs u = x, v = z across [0, 1], counter-clockwise seen from above.
  Material: pbrMetallicRoughness, base colour (0.36, 0.40, 0.26), metallic 0,
  roughness 0.9, so the loader reads it as a lambertian named "terrain".
- generated/rock.glb: a subdivided icosahedron (4 levels, 5,120 triangles),
  flattened and displaced by fractal noise, radius about 1 m; smooth normals,
  spherical UVs, a grey lambertian "rock" material.

The scene places the terrain once and ROCKS rock instances on it: positions
in the wedge the camera sees, each set on the height field (the height of
the very triangle under it, less a little, so that it sits in the ground),
random rotation about y (and up to 20 degrees of tilt), random scale 0.5 to
4 m, and a material override from four rock colours (a quarter keep the
file's own). Everything random comes from fixed seeds: the output is the same
on every run. A gradient sky, a camera low over the near edge looking across.
"""

import array
import math
import os
import random
import sys
import time

import scenefile  # a sibling: the script's folder is on the path
import meshfile

N = 708            # quads along a side: 2 * 708^2 = 1,002,528 triangles
SIZE = 200.0       # metres along a side, centred on the origin
HEIGHT = 30.0      # metres, the highest ridges
OCTAVES = [(3, 1.0), (6, 0.5), (12, 0.25), (24, 0.125), (48, 0.0625), (96, 0.03)]  # (cells, amplitude)
SEED = 1729
ROCKS = 400
ROCK_SEED = 2024
ROCK_MATERIALS = [None, "granite", "sandstone", "basalt", "mossy"]


def heights():
    """The (N + 1)^2 heights, row j (z) after row j - 1, as a flat list."""
    n = N + 1
    rng = random.Random(SEED)
    h = [0.0] * (n * n)
    for cells, amp in OCTAVES:
        lattice = [[rng.random() * 2 - 1 for _ in range(cells + 2)] for _ in range(cells + 2)]
        ci, wi = [], []
        for i in range(n):
            t = i * cells / N
            c = min(int(t), cells - 1)
            f = t - c
            ci.append(c)
            wi.append(f * f * f * (f * (f * 6 - 15) + 10))
        for j in range(n):
            cj, wj = ci[j], wi[j]       # the grid is square: rows use the columns' cells
            r0, r1 = lattice[cj], lattice[cj + 1]
            row = [a + (b - a) * wj for a, b in zip(r0, r1)]
            base = j * n
            vals = [row[c] + (row[c + 1] - row[c]) * w for c, w in zip(ci, wi)]
            h[base:base + n] = [x + amp * v for x, v in zip(h[base:base + n], vals)]
    lo, hi = min(h), max(h)
    # To [0, 1], then a power that flattens the valleys and sharpens the ridges.
    return [HEIGHT * ((x - lo) / (hi - lo)) ** 1.7 for x in h]


def terrain_part(h):
    n = N + 1
    d = SIZE / N
    xs = [-SIZE / 2 + i * d for i in range(n)]
    us = [i / N for i in range(n)]
    pos, nor, uv = array.array("f"), array.array("f"), array.array("f")
    for j in range(n):
        z = -SIZE / 2 + j * d
        row = h[j * n:(j + 1) * n]
        pos.extend([v for x, y in zip(xs, row) for v in (x, y, z)])
        up = h[min(j + 1, N) * n:min(j + 1, N) * n + n]
        dn = h[max(j - 1, 0) * n:max(j - 1, 0) * n + n]
        dz = d * (min(j + 1, N) - max(j - 1, 0))
        # dh/dx by central differences (one-sided at the borders).
        ddx = [(row[1] - row[0]) / d] + [(row[i + 1] - row[i - 1]) / (2 * d) for i in range(1, N)] + \
              [(row[N] - row[N - 1]) / d]
        for gx, a, b in zip(ddx, up, dn):
            gz = (a - b) / dz
            r = 1.0 / math.sqrt(gx * gx + 1 + gz * gz)
            nor.extend((-gx * r, r, -gz * r))
        v = j / N
        uv.extend([c for u in us for c in (u, v)])
    # Quad (i, j): corners a = (i, j), a + 1 = (i + 1, j), a + n = (i, j + 1);
    # (a, a + n, a + 1) and (a + 1, a + n, a + n + 1) face +y.
    pattern = [k for i in range(N) for k in (i, i + n, i + 1, i + 1, i + n, i + n + 1)]
    ind = array.array("I")
    for j in range(N):
        o = j * n
        ind.extend([k + o for k in pattern])
    material = meshfile.pbr_material("terrain", (0.36, 0.40, 0.26), metallic=0.0, roughness=0.9)
    return meshfile.Part(pos, nor, uv, ind, material)


def ground_height(h, x, z):
    """The height of the terrain's triangle under (x, z)."""
    n = N + 1
    d = SIZE / N
    fx, fz = (x + SIZE / 2) / d, (z + SIZE / 2) / d
    i, j = min(int(fx), N - 1), min(int(fz), N - 1)
    fx, fz = fx - i, fz - j
    h00, h10, h01, h11 = h[j * n + i], h[j * n + i + 1], h[(j + 1) * n + i], h[(j + 1) * n + i + 1]
    if fx + fz <= 1:    # triangle (a, a + n, a + 1)
        return h00 + fx * (h10 - h00) + fz * (h01 - h00)
    return h11 + (1 - fx) * (h01 - h11) + (1 - fz) * (h10 - h11)


def rock_instances(h, camera_z):
    rng = random.Random(ROCK_SEED)
    q = scenefile.rounder(3)
    out = []
    for _ in range(ROCKS):
        z = rng.uniform(-95, 80)
        half = min(95.0, 0.8 * (z - camera_z))   # about what the camera sees at that depth
        x = rng.uniform(-half, half)
        s = 0.5 + 3.5 * rng.random() ** 2.5      # mostly small, a few boulders
        sx, sy, sz = s * rng.uniform(0.8, 1.2), s * rng.uniform(0.7, 1.1), s * rng.uniform(0.8, 1.2)
        y = ground_height(h, x, z) + 0.3 * sy    # the rock's bottom (about -0.5 to -0.9) sinks in
        inst = {"mesh": "rock", "translate": [q(x), q(y), q(z)],
                "rotate": [q(rng.uniform(-20, 20)), q(rng.uniform(0, 360)), q(rng.uniform(-20, 20))],
                "scale": [q(sx), q(sy), q(sz)]}
        m = rng.choice(ROCK_MATERIALS)
        if m:
            inst["material"] = m
        out.append(inst)
    return out


def build(h, terrain_file, rock_file):
    camera_z = -128.0
    eye_y = max(ground_height(h, x, -98) for x in (-20, -10, 0, 10, 20)) + 16
    at_y = ground_height(h, 0, 10) + 2
    materials = [
        {"name": "granite", "type": "lambertian", "albedo": [0.52, 0.5, 0.47]},
        {"name": "sandstone", "type": "lambertian", "albedo": [0.62, 0.45, 0.32]},
        {"name": "basalt", "type": "lambertian", "albedo": [0.16, 0.16, 0.18]},
        {"name": "mossy", "type": "lambertian", "albedo": [0.3, 0.38, 0.2]},
    ]
    q = scenefile.rounder(3)
    return {
        "camera": {"look_from": [0, q(eye_y), camera_z], "look_at": [0, q(at_y), 10], "up": [0, 1, 0],
                   "vfov": 50, "aperture": 0},
        "sky": {"type": "gradient", "horizon": [1, 0.95, 0.9], "zenith": [0.4, 0.6, 1.0]},
        "render": {"width": 1280, "height": 720, "spp": 64, "depth": 8, "roulette_depth": 4, "seed": 1},
        "materials": materials,
        "meshes": [{"name": "terrain", "file": terrain_file}, {"name": "rock", "file": rock_file}],
        "instances": [{"mesh": "terrain", "translate": [0, 0, 0]}] + rock_instances(h, camera_z),
    }


def main():
    output, folder = meshfile.scene_command(__doc__, "terrain.json")
    start = time.time()
    h = heights()
    terrain = terrain_part(h)
    t_tris = meshfile.write_glb(os.path.join(folder, "terrain.glb"), [terrain], "terrain")
    del terrain
    r_tris = meshfile.write_glb(os.path.join(folder, "rock.glb"), [meshfile.rock_part(4, seed=7)], "rock")
    scene = build(h, "generated/terrain.glb", "generated/rock.glb")
    with open(output, "w") as f:
        f.write(scenefile.dumps_scene(scene))
    rocks = len(scene["instances"]) - 1
    print("%s: terrain %d triangles, rock %d triangles x %d instances; %d unique, %d instanced triangles; %.1f s"
          % (os.path.normpath(output), t_tris, r_tris, rocks, t_tris + r_tris, t_tris + rocks * r_tris,
             time.time() - start))


if __name__ == "__main__":
    main()
