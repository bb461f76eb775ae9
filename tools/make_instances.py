#!/usr/bin/env python3
"""Writes scenes/instances.json and its meshes: a forest of more than 10 million instanced triangles.

    python3 tools/make_instances.py [-o scenes/instances.json]

A stress test for instancing: few unique triangles, many placed. Meshes,
written to generated/ beside the scene file (scenes/generated/, ignored by
git; a few MB, regenerated in about a second):

- generated/tree.glb, generated/tree-autumn.glb: a procedural tree, about 6 m
  tall, base at the origin: a tapered trunk (768 triangles, material "bark")
  and a crown of four noise-displaced icospheres (20,480 triangles, material
  "leaves", green or orange); 21,248 triangles each, two glTF primitives.
- generated/rock.glb: the rock of make_terrain.py (5,120 triangles).
- generated/ground-quad.obj: a unit quad facing up (2 triangles, no MTL).

The scene: the ground quad scaled to 240 m x 240 m with a scene material;
GRID x GRID trees (a jittered 8 m grid, one in five autumn-coloured, random
turn about y, up to 4 degrees of lean, size 0.7 to 1.3), and ROCKS rocks
between them. Trees are placed with translate/rotate/scale, the rocks with
the "matrix" form (the same transform, T * Rz * Ry * Rx * S, written
row-major by meshfile.trs_matrix), so that the scene exercises both. Fixed
seeds: the output is the same on every run. The summary line gives the
unique and the instanced triangle counts.
"""

import os
import random
import time

import scenefile  # a sibling: the script's folder is on the path
import meshfile

GRID = 24           # 576 trees x 21,248 triangles = 12.2 M
SPACING = 8.0
ROCKS = 300
SEED = 4242


def build(tris):
    rng = random.Random(SEED)
    q = scenefile.rounder(3)
    half = SPACING * (GRID - 1) / 2
    instances = [{"mesh": "ground", "material": "grass", "translate": [0, 0, 0], "scale": [120, 1, 120]}]
    for gz in range(GRID):
        for gx in range(GRID):
            x = -half + gx * SPACING + rng.uniform(-2.5, 2.5)
            z = -half + gz * SPACING + rng.uniform(-2.5, 2.5)
            mesh = "tree-autumn" if rng.random() < 0.2 else "tree"
            instances.append({"mesh": mesh, "translate": [q(x), 0, q(z)],
                              "rotate": [q(rng.uniform(-4, 4)), q(rng.uniform(0, 360)), q(rng.uniform(-4, 4))],
                              "scale": q(rng.uniform(0.7, 1.3))})
    for _ in range(ROCKS):
        x, z = rng.uniform(-half, half), rng.uniform(-half, half)
        s = rng.uniform(0.3, 1.2)
        m = meshfile.trs_matrix((x, 0.25 * s, z), (0, rng.uniform(0, 360), 0), (s, 0.8 * s, s))
        instances.append({"mesh": "rock", "material": "stone", "matrix": [q(v) for v in m]})
    meshes = [
        {"name": "ground", "file": "generated/ground-quad.obj"},
        {"name": "tree", "file": "generated/tree.glb"},
        {"name": "tree-autumn", "file": "generated/tree-autumn.glb"},
        {"name": "rock", "file": "generated/rock.glb"},
    ]
    return {
        "camera": {"look_from": [-30, 26, -125], "look_at": [0, 3, -40], "up": [0, 1, 0],
                   "vfov": 45, "aperture": 0},
        "sky": {"type": "gradient", "horizon": [1, 1, 1], "zenith": [0.5, 0.7, 1.0]},
        "render": {"width": 1280, "height": 720, "spp": 32, "depth": 8, "roulette_depth": 4, "seed": 1},
        "materials": [
            {"name": "grass", "type": "lambertian", "albedo": [0.3, 0.42, 0.18]},
            {"name": "stone", "type": "lambertian", "albedo": [0.5, 0.48, 0.45]},
        ],
        "meshes": meshes,
        "instances": instances,
    }


def counts(scene, tris):
    """(unique triangles, instanced triangles): each mesh once, each placement."""
    unique = sum(tris[m["name"]] for m in scene["meshes"])
    placed = sum(tris[i["mesh"]] for i in scene["instances"])
    return unique, placed


def main():
    output, folder = meshfile.scene_command(__doc__, "instances.json")
    start = time.time()
    tris = {"ground": 2}
    meshfile.write_ground_obj(os.path.join(folder, "ground-quad.obj"))
    tris["tree"] = meshfile.write_glb(os.path.join(folder, "tree.glb"), meshfile.tree_parts(seed=3), "tree")
    tris["tree-autumn"] = meshfile.write_glb(os.path.join(folder, "tree-autumn.glb"),
                                             meshfile.tree_parts(seed=11, leaves=(0.62, 0.3, 0.06)), "tree-autumn")
    tris["rock"] = meshfile.write_glb(os.path.join(folder, "rock.glb"), [meshfile.rock_part(4, seed=7)], "rock")
    scene = build(tris)
    with open(output, "w") as f:
        f.write(scenefile.dumps_scene(scene))
    unique, placed = counts(scene, tris)
    print("%s: %d instances of %d meshes; %d unique triangles, %d instanced triangles; %.1f s"
          % (os.path.normpath(output), len(scene["instances"]), len(scene["meshes"]), unique, placed,
             time.time() - start))


if __name__ == "__main__":
    main()
