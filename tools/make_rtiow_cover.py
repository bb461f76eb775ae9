#!/usr/bin/env python3
"""Writes scenes/rtiow-cover.json: the cover scene of "Ray Tracing in One Weekend".

    python3 tools/make_rtiow_cover.py [-o scenes/rtiow-cover.json]

The layout is that of the book's well-known CUDA port, which is the second
reference the project measures against: 488 spheres, namely the ground, a 22 x 22
grid of small spheres and three large ones, all of them present (the CPU
version of the book drops the small spheres that come too close to the large
metal one; the CUDA port keeps every grid position).

The port draws its random numbers from cuRAND, which this script does not
reproduce: the placements and colours come from Python's random.Random with a
fixed seed instead, so the scene has the same structure and statistics (and
the same cost to render) but not the same pixels. Running the script again
writes the identical file.
"""

import argparse
import collections
import json
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_OUT = os.path.join(HERE, "..", "scenes", "rtiow-cover.json")
SEED = 1984


def dumps_scene(scene):
    """JSON text with one list entry per line: diffs stay readable."""
    parts = []
    for key, value in scene.items():
        if isinstance(value, list):
            body = ",\n".join("    " + json.dumps(v) for v in value)
            parts.append("  %s: [\n%s\n  ]" % (json.dumps(key), body))
        else:
            parts.append("  %s: %s" % (json.dumps(key), json.dumps(value)))
    return "{\n" + ",\n".join(parts) + "\n}\n"


def q(x):
    """Six decimals: plenty for float32 albedos and positions, and short lines."""
    return round(x, 6)


class Materials:
    """Named materials, one entry per distinct definition: identical spheres
    (all the small glass ones, say) share a material."""

    def __init__(self):
        self.list = []
        self.by_key = {}

    def get(self, prefix, **fields):
        key = json.dumps(fields, sort_keys=True)
        if key not in self.by_key:
            name = "%s%d" % (prefix, len(self.list))
            self.by_key[key] = name
            self.list.append(dict({"name": name}, **fields))
        return self.by_key[key]


def build():
    rng = random.Random(SEED)
    mats = Materials()
    spheres = [{"center": [0, -1000, 0], "radius": 1000,
                "material": mats.get("ground", type="lambertian", albedo=[0.5, 0.5, 0.5])}]
    for a in range(-11, 11):
        for b in range(-11, 11):
            # The material's kind is drawn first, then the position, then the
            # material's own numbers.
            choose = rng.random()
            center = [q(a + 0.9 * rng.random()), 0.2, q(b + 0.9 * rng.random())]
            if choose < 0.8:
                albedo = [q(rng.random() * rng.random()) for _ in range(3)]
                m = mats.get("diffuse", type="lambertian", albedo=albedo)
            elif choose < 0.95:
                albedo = [q(0.5 * (1 + rng.random())) for _ in range(3)]
                m = mats.get("metal", type="metal", albedo=albedo, fuzz=q(0.5 * rng.random()))
            else:
                m = mats.get("glass", type="dielectric", ior=1.5)
            spheres.append({"center": center, "radius": 0.2, "material": m})
    spheres.append({"center": [0, 1, 0], "radius": 1, "material": mats.get("glass", type="dielectric", ior=1.5)})
    spheres.append({"center": [-4, 1, 0], "radius": 1,
                    "material": mats.get("diffuse", type="lambertian", albedo=[0.4, 0.2, 0.1])})
    spheres.append({"center": [4, 1, 0], "radius": 1,
                    "material": mats.get("metal", type="metal", albedo=[0.7, 0.6, 0.5], fuzz=0)})
    assert len(spheres) == 488

    return {
        "camera": {"look_from": [13, 2, 3], "look_at": [0, 0, 0], "up": [0, 1, 0],
                   "vfov": 30, "aperture": 0.1, "focus_distance": 10},
        "sky": {"type": "gradient", "horizon": [1, 1, 1], "zenith": [0.5, 0.7, 1]},
        # The port has no Russian roulette: from the depth limit on it never fires.
        "render": {"width": 1920, "height": 1080, "spp": 100, "depth": 50,
                   "roulette_depth": 50, "seed": 1},
        "materials": mats.list,
        "spheres": spheres,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", default=DEFAULT_OUT, help="scene file to write")
    args = ap.parse_args()
    scene = build()
    with open(args.output, "w") as f:
        f.write(dumps_scene(scene))
    by_type = {m["name"]: m["type"] for m in scene["materials"]}
    kinds = collections.Counter(by_type[s["material"]] for s in scene["spheres"])
    print("%s: %d spheres (%s), %d materials" % (
        os.path.normpath(args.output), len(scene["spheres"]),
        ", ".join("%s %d" % kv for kv in sorted(kinds.items())), len(scene["materials"])))


if __name__ == "__main__":
    main()
