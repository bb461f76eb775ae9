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

import json
import random

import scenefile  # a sibling: the script's folder is on the path

SEED = 1984


# Six decimals: plenty for float32 albedos and positions, and short lines.
q = scenefile.rounder(6)


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


def summary(scene):
    kinds = scenefile.spheres_by(scene, lambda m: m["type"])
    return "%d spheres (%s), %d materials" % (
        len(scene["spheres"]), scenefile.counts_text(kinds), len(scene["materials"]))


if __name__ == "__main__":
    scenefile.main(__doc__, build, scenefile.scene_path("rtiow-cover.json"), summary)
