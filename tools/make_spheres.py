#!/usr/bin/env python3
"""Writes a scene of N random spheres over four materials, for timing scene loading.

    python3 tools/make_spheres.py N [-o spheres-N.json] [--seed S]

The spheres lie in a cube whose volume grows with N, so that their density (and
the BVH's shape) stays the same at every size. bench/load_scaling.sh uses it.
"""

import argparse
import os
import random

import scenefile  # a sibling: the script's folder is on the path

MATERIALS = [
    {"name": "matte", "type": "lambertian", "albedo": [0.7, 0.3, 0.2]},
    {"name": "mirror", "type": "metal", "albedo": [0.9, 0.9, 0.9], "fuzz": 0.1},
    {"name": "glass", "type": "dielectric", "ior": 1.5},
    {"name": "lamp", "type": "emissive", "emission": [4, 4, 4]},
]


def build(n, seed):
    rng = random.Random(seed)
    q = scenefile.rounder(3)
    side = 2.0 * n ** (1.0 / 3.0)
    spheres = [{"center": [q(rng.uniform(0, side)) for _ in range(3)], "radius": q(rng.uniform(0.1, 0.4)),
                "material": MATERIALS[rng.randrange(len(MATERIALS))]["name"]} for _ in range(n)]
    return {
        "camera": {"look_from": [-side, side, -side], "look_at": [side / 2, side / 2, side / 2], "vfov": 40},
        "materials": MATERIALS,
        "spheres": spheres,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n", type=int, help="number of spheres")
    ap.add_argument("-o", "--output", help="scene file to write (default: spheres-N.json)")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    out = args.output or "spheres-%d.json" % args.n
    with open(out, "w") as f:
        f.write(scenefile.dumps_scene(build(args.n, args.seed)))
    print("%s: %d spheres" % (os.path.normpath(out), args.n))


if __name__ == "__main__":
    main()
