#!/usr/bin/env python3
"""Writes scenes/divergent.json: a scene built to make shading divergent.

    python3 tools/make_divergent.py [-o scenes/divergent.json]

A camera looks down on a field of small spheres packed densely enough to fill
the whole frame. Each sphere's material kind is drawn at random, so
neighbouring pixels, and the paths that leave them, meet different kinds of
material: a GPU warp that shades them together has to run several material
branches. The kinds (ten of them) differ in how much work a hit costs:

  plain lambertian, checker lambertian, marble-noise lambertian (turbulence with
  many octaves: heavy per-hit work), image lambertian (texture fetches),
  mirror metal, fuzzy metal, glass (many small spheres and a few large ones:
  long chains of refraction and internal reflection), clear-coated diffuse,
  clear-coated with marble noise, and emitters (paths end there early).

The sky is dim, so the light that matters comes from the emitters, and paths
that escape contribute little. Everything comes from random.Random with a
fixed seed: running the script again writes the identical file.
"""

import collections
import math
import random

import scenefile  # a sibling: the script's folder is on the path

SEED = 20240611

WIDTH, HEIGHT = 1920, 1080
LOOK_FROM = (0.0, 10.0, 12.0)
LOOK_AT = (0.0, 0.0, -2.0)
VFOV = 40.0

SPACING = 1.1  # grid pitch of the small spheres
JITTER = 0.1   # with radii up to 0.45, neighbours can touch but never overlap
VARIANTS = 4   # materials per kind: colour variety without a material per sphere

# Kind -> probability; glass is the most common so that long paths are common.
KINDS = [
    ("lambertian", 0.11), ("checker", 0.08), ("noise", 0.12), ("image", 0.10),
    ("metal", 0.09), ("fuzzy_metal", 0.09), ("glass", 0.19), ("coated", 0.08),
    ("coated_noise", 0.08), ("emissive", 0.06),
]
IMAGES = ["probe_beach", "probe_building", "probe_campus", "probe_kitchen", "planet"]


q = scenefile.rounder(4)


def colour(rng, lo=0.05, hi=0.95):
    return [q(rng.uniform(lo, hi)) for _ in range(3)]


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    n = math.sqrt(dot(a, a))
    return [x / n for x in a]


def in_view(center, radius):
    """Whether any of a sphere shows in the frame (pinhole camera), so that only
    visible spheres are written: the field is exactly as large as the frame."""
    w = unit(sub(LOOK_FROM, LOOK_AT))
    u = unit(cross([0, 1, 0], w))
    v = cross(w, u)
    d = sub(center, LOOK_FROM)
    depth = -dot(d, w)
    if depth <= radius:
        return False
    half_h = math.tan(math.radians(VFOV) / 2)
    half_w = half_h * WIDTH / HEIGHT
    pad = radius / depth
    return abs(dot(d, u) / depth) <= half_w + pad and abs(dot(d, v) / depth) <= half_h + pad


def build():
    rng = random.Random(SEED)
    # Bilinear at full size, as the study's scenes have it (and the golden images).
    textures = [{"name": n, "type": "image", "file": "textures/%s.png" % n, "colorspace": "srgb",
                 "filter": "bilinear"} for n in IMAGES]
    textures.append({"name": "ground_checker", "type": "checker", "size": 2,
                     "even": [0.5, 0.5, 0.5], "odd": [0.15, 0.15, 0.15]})
    materials = [{"name": "ground", "type": "lambertian", "albedo": [1, 1, 1], "texture": "ground_checker"}]

    def noise_texture(name):
        # Many octaves: every hit runs the whole turbulence loop.
        textures.append({"name": name, "type": "noise", "scale": q(rng.uniform(3, 9)),
                         "octaves": rng.randint(8, 10), "high": colour(rng, 0.6, 1.0),
                         "low": colour(rng, 0.0, 0.3)})
        return name

    by_kind = collections.defaultdict(list)
    for kind, _ in KINDS:
        count = len(IMAGES) if kind == "image" else VARIANTS
        for i in range(count):
            name = "%s_%d" % (kind, i)
            if kind == "lambertian":
                m = {"type": "lambertian", "albedo": colour(rng)}
            elif kind == "checker":
                # Squares smaller than the spheres: stripes and patches on each one.
                t = "squares_%d" % i
                textures.append({"name": t, "type": "checker", "size": q(rng.uniform(0.08, 0.16)),
                                 "even": colour(rng, 0.6, 0.95), "odd": colour(rng, 0.02, 0.3)})
                m = {"type": "lambertian", "albedo": [1, 1, 1], "texture": t}
            elif kind == "noise":
                m = {"type": "lambertian", "albedo": [1, 1, 1], "texture": noise_texture("marble_%d" % i)}
            elif kind == "image":
                m = {"type": "lambertian", "albedo": [1, 1, 1], "texture": IMAGES[i]}
            elif kind == "metal":
                m = {"type": "metal", "albedo": colour(rng, 0.6, 0.95), "fuzz": 0}
            elif kind == "fuzzy_metal":
                m = {"type": "metal", "albedo": colour(rng, 0.5, 0.95), "fuzz": q(rng.uniform(0.2, 0.6))}
            elif kind == "glass":
                # Slight tints; indices from water to dense flint glass.
                m = {"type": "dielectric", "ior": q(rng.uniform(1.3, 1.8)), "albedo": colour(rng, 0.85, 1.0)}
            elif kind == "coated":
                m = {"type": "coated", "albedo": colour(rng), "ior": 1.5}
            elif kind == "coated_noise":
                m = {"type": "coated", "albedo": [1, 1, 1], "ior": q(rng.uniform(1.4, 1.6)),
                     "texture": noise_texture("coat_marble_%d" % i)}
            elif kind == "emissive":
                strength = rng.uniform(2, 8)
                m = {"type": "emissive", "emission": [q(strength * c) for c in colour(rng, 0.4, 1.0)]}
            materials.append(dict({"name": name}, **m))
            by_kind[kind].append(name)

    spheres = [{"center": [0, -1000, 0], "radius": 1000, "material": "ground"}]

    # A few large glass balls among the small ones: long refraction chains and
    # caustics of the emitters around them.
    big = []
    while len(big) < 8:
        r = rng.uniform(1.0, 1.8)
        c = [rng.uniform(-9, 9), r, rng.uniform(-14, 4)]
        if in_view(c, 0) and all(math.dist(c, b[0]) > r + b[1] + 0.5 for b in big):
            big.append((c, r))
    for c, r in big:
        spheres.append({"center": [q(x) for x in c], "radius": q(r), "material": rng.choice(by_kind["glass"])})

    # Three brighter lamps hovering above the field.
    lamps = [([-6.0, 4.0, -8.0], 0.8), ([5.0, 3.5, -4.0], 0.7), ([0.5, 4.5, -15.0], 1.0)]
    for i, (c, r) in enumerate(lamps):
        materials.append({"name": "lamp_%d" % i, "type": "emissive", "emission": [12, 10, 8]})
        spheres.append({"center": c, "radius": r, "material": "lamp_%d" % i})

    names, weights = zip(*KINDS)
    n = int(40 / SPACING)
    for gz in range(-n, n + 1):
        for gx in range(-n, n + 1):
            r = rng.uniform(0.25, 0.45)
            x = gx * SPACING + rng.uniform(-JITTER, JITTER)
            z = gz * SPACING + rng.uniform(-JITTER, JITTER)
            kind = rng.choices(names, weights)[0]
            variant = rng.choice(by_kind[kind])
            c = [x, r, z]
            if not in_view(c, r):
                continue
            if any(math.dist(c, b[0]) < r + b[1] + 0.05 for b in big):
                continue
            spheres.append({"center": [q(x), q(r), q(z)], "radius": q(r), "material": variant})

    return {
        "camera": {"look_from": list(LOOK_FROM), "look_at": list(LOOK_AT), "up": [0, 1, 0],
                   "vfov": VFOV, "aperture": 0},
        # Dim: the emitters, not the sky, light the scene.
        "sky": {"type": "gradient", "horizon": [0.05, 0.05, 0.07], "zenith": [0.01, 0.02, 0.06]},
        "render": {"width": WIDTH, "height": HEIGHT, "spp": 64, "depth": 16, "roulette_depth": 4, "seed": 1},
        "textures": textures,
        "materials": materials,
        "spheres": spheres,
    }


def summary(scene):
    # A material's kind is its name without the variant number.
    kinds = scenefile.spheres_by(scene, lambda m: m["name"].rsplit("_", 1)[0])
    return "%d spheres, %d materials, %d textures\n  spheres by material: %s" % (
        len(scene["spheres"]), len(scene["materials"]), len(scene["textures"]), scenefile.counts_text(kinds))


if __name__ == "__main__":
    scenefile.main(__doc__, build, scenefile.scene_path("divergent.json"), summary)
