#!/usr/bin/env python3
"""Writes scenes/seed57.json, the 57-sphere reference scene, from its sphere list.

    python3 tools/make_seed57.py SEED57_SPHERES_JSON [-o scenes/seed57.json]

The sphere list gives every sphere's centre, radius, material kind, albedo, fuzz,
index of refraction and texture index exactly as the reference renderer built
them. This script turns it into a scene file (docs/scene-format.md) and checks
the counts against the reference's table, so that a changed or truncated input
cannot slip through unnoticed. The scene file is generated once and committed:
wavetrace never reads the sphere list at run time.

Numbers are copied as parsed (Python floats, written back with repr by the json
module), so every float32 value of the reference survives the round trip.
"""

import collections
import math

import scenefile  # a sibling: the script's folder is on the path

# Texture index in the sphere list -> the project's own image. Their order in
# the scene's texture list keeps the reference's index, so texture i of the
# reference is texture i of the scene.
IMAGES = [
    ("probe_beach", "textures/probe_beach.png"),
    ("probe_building", "textures/probe_building.png"),
    ("probe_campus", "textures/probe_campus.png"),
    ("probe_kitchen", "textures/probe_kitchen.png"),
    ("planet", "textures/planet.png"),
]
CHECKER = "ground_checker"

LOOK_FROM = [0, 5, -20]
LOOK_AT = [0, 0.5, 0]


def material_for(index, s):
    name = "m%02d_%s" % (index, s["material"])
    kind = s["material"]
    if kind == "checker":
        return {"name": name, "type": "lambertian", "albedo": s["albedo"], "texture": CHECKER}
    if kind == "textured":
        return {"name": name, "type": "lambertian", "albedo": s["albedo"], "texture": IMAGES[s["texture"]][0]}
    if kind == "lambertian":
        return {"name": name, "type": "lambertian", "albedo": s["albedo"]}
    if kind == "metal":
        return {"name": name, "type": "metal", "albedo": s["albedo"], "fuzz": s["fuzz"]}
    if kind == "dielectric":
        # The reference's dielectric carries an albedo of white and ignores it;
        # white is also the scene format's default transmission tint.
        if s["albedo"] != [1, 1, 1]:
            raise ValueError("sphere %d: dielectric with a tint %r" % (index, s["albedo"]))
        return {"name": name, "type": "dielectric", "ior": s["ior"]}
    raise ValueError("sphere %d: unknown material %r" % (index, kind))


def check_counts(spheres):
    """The counts of the reference's table, by role."""
    def small(s):
        return s["radius"] < 0.5

    roles = collections.Counter()
    for s in spheres:
        kind = s["material"]
        if kind == "checker":
            roles["ground"] += 1
        elif kind == "textured":
            roles["textured"] += 1
        elif kind == "metal" and not small(s):
            roles["mirror"] += 1
        elif small(s):
            roles["small " + kind] += 1
        else:
            roles["other"] += 1
    expected = {"ground": 1, "textured": 5, "mirror": 2, "small lambertian": 31,
                "small metal": 12, "small dielectric": 6}
    if len(spheres) != 57 or dict(roles) != expected:
        raise ValueError("sphere counts %s (%d spheres) differ from the reference's %s"
                         % (dict(roles), len(spheres), expected))
    textures = sorted(s["texture"] for s in spheres if s["material"] == "textured")
    if textures != [0, 1, 2, 3, 4]:
        raise ValueError("textured spheres use textures %r, expected 0..4" % textures)


def build(spheres):
    check_counts(spheres)
    focus = math.sqrt(sum((a - b) ** 2 for a, b in zip(LOOK_FROM, LOOK_AT)))
    # The study sampled its images bilinearly at full size: its scenes say so, and
    # keep its images (wavetrace's default is the trilinear, mip-mapped lookup).
    textures = [{"name": name, "type": "image", "file": path, "colorspace": "linear", "filter": "bilinear"}
                for name, path in IMAGES]
    textures.append({"name": CHECKER, "type": "checker", "size": 4,
                     "even": [0.95, 0.95, 0.95], "odd": [0.05, 0.05, 0.05]})
    materials = [material_for(i, s) for i, s in enumerate(spheres)]
    return {
        "camera": {"look_from": LOOK_FROM, "look_at": LOOK_AT, "up": [0, 1, 0],
                   "vfov": 20, "aperture": 0.03, "focus_distance": focus},
        "sky": {"type": "gradient", "horizon": [1, 1, 1], "zenith": [0.5, 0.7, 1]},
        # The reference has no Russian roulette: roulette from the depth limit
        # on never fires, so paths end exactly where the reference's do.
        "render": {"width": 1920, "height": 1080, "spp": 300, "depth": 30,
                   "roulette_depth": 30, "seed": 1},
        "textures": textures,
        "materials": materials,
        "spheres": [{"center": s["center"], "radius": s["radius"], "material": m["name"]}
                    for s, m in zip(spheres, materials)],
    }


def summary(scene):
    kinds = collections.Counter(m["type"] for m in scene["materials"])
    return "%d spheres, materials %s" % (len(scene["spheres"]), dict(sorted(kinds.items())))


if __name__ == "__main__":
    scenefile.main(__doc__, build, scenefile.scene_path("seed57.json"), summary,
                   input_arg=("spheres", "the reference's sphere list (seed57_spheres.json)"))
