#!/usr/bin/env python3
"""Writes scenes/quick.json: a small scene that renders in moments, for tests.

    python3 tools/make_quick.py [-o scenes/quick.json]

Eight spheres in two staggered rows on a checker ground, one of every kind of
material and texture the scene format has, so that a single low-resolution
render exercises every shading path: lambertian, lambertian with an image
(planet.png, read as sRGB so that the conversion is exercised too; the seed57
scene reads its images as linear), lambertian with marble noise, mirror metal,
fuzzy metal, glass, a clear-coated diffuse, and an emitter. Russian roulette
starts early (bounce 3) so that it, too, is exercised within the short depth.
"""


import scenefile  # a sibling: the script's folder is on the path

RADIUS = 0.55
# (material, x, z): the back row sits wider than the front row, and the camera
# looks down steeply enough that the back row shows above the front one.
PLACES = [
    ("glass", -2.0, 1.0), ("globe", -0.65, 1.0), ("mirror", 0.65, 1.0), ("lacquer", 2.0, 1.0),
    ("matte", -2.8, -1.2), ("marble", -0.95, -1.2), ("lamp", 0.95, -1.2), ("brushed", 2.8, -1.2),
]


def build():
    textures = [
        {"name": "floor", "type": "checker", "size": 1, "even": [0.9, 0.9, 0.9], "odd": [0.2, 0.2, 0.2]},
        {"name": "veins", "type": "noise", "scale": 4, "octaves": 7, "high": [0.95, 0.95, 0.9],
         "low": [0.15, 0.2, 0.3]},
        {"name": "planet", "type": "image", "file": "textures/planet.png", "colorspace": "srgb"},
    ]
    materials = [
        {"name": "ground", "type": "lambertian", "albedo": [1, 1, 1], "texture": "floor"},
        {"name": "matte", "type": "lambertian", "albedo": [0.7, 0.3, 0.2]},
        {"name": "globe", "type": "lambertian", "albedo": [1, 1, 1], "texture": "planet"},
        {"name": "marble", "type": "lambertian", "albedo": [1, 1, 1], "texture": "veins"},
        {"name": "mirror", "type": "metal", "albedo": [0.9, 0.9, 0.9], "fuzz": 0},
        {"name": "brushed", "type": "metal", "albedo": [0.8, 0.6, 0.3], "fuzz": 0.3},
        {"name": "glass", "type": "dielectric", "ior": 1.5},
        {"name": "lacquer", "type": "coated", "albedo": [0.1, 0.3, 0.8], "ior": 1.5},
        {"name": "lamp", "type": "emissive", "emission": [4, 3.5, 2.5]},
    ]
    spheres = [{"center": [0, -1000, 0], "radius": 1000, "material": "ground"}]
    spheres += [{"center": [x, RADIUS, z], "radius": RADIUS, "material": m} for m, x, z in PLACES]
    return {
        "camera": {"look_from": [0, 4.5, 9], "look_at": [0, 0.4, 0], "up": [0, 1, 0],
                   "vfov": 28, "aperture": 0},
        "sky": {"type": "gradient", "horizon": [1, 1, 1], "zenith": [0.5, 0.7, 1]},
        "render": {"width": 160, "height": 90, "spp": 8, "depth": 8, "roulette_depth": 3, "seed": 1},
        "textures": textures,
        "materials": materials,
        "spheres": spheres,
    }


def summary(scene):
    return "%d spheres, %d materials" % (len(scene["spheres"]), len(scene["materials"]))


if __name__ == "__main__":
    scenefile.main(__doc__, build, scenefile.scene_path("quick.json"), summary)
