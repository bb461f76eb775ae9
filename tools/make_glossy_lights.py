#!/usr/bin/env python3
"""Writes scenes/glossy-lights.json and .obj: four glossy plates under four lights of one power.

    python3 tools/make_glossy_lights.py [-o scenes/glossy-lights.json]

The layout of the classic test of multiple importance sampling (Veach and
Guibas, 1995): four wide metal plates in a row, stepped back and up like
stairs, each tilted so that it mirrors the camera's view toward the lights, and
four spherical lights above and behind them. The plates go from sharp to rough
(fuzz 0.02, 0.08, 0.25, 0.6, front to back) and the lights from small to large
(radius 0.03, 0.1, 0.3, 0.9, left to right); each light's emission is scaled by
1 / radius^2, so all four emit the same power, and its colour differs (each
colour's channels average 1) so that its reflections can be told apart. Every
plate shows all four lights: a small light in a sharp plate is a small bright
spot, a large light in a rough plate a wide dim glow. Sampling the plate's
reflection finds the large lights and misses the small ones; sampling the
lights does the opposite; only a weighting of the two is good everywhere.

The steps, the tilts and the camera are set so that, seen across the plates
(in y and z), no plate hides any part of another from the camera or from the
middle of the row of lights, the four plates do not overlap in the picture,
and the lights show along its top.

The room is dark: a dim grey lambertian ground (albedo 0.15; a sphere of radius
1000) and a black sky, so the reflections of the lights dominate the image. (A
dim sky would be a sampled light too, and its power, estimated over the bounding
sphere of the ground's radius 1000, would take nearly every light sample from
the four lights.) The plate is one unit quad (the OBJ written beside the
scene file, no materials) placed four times, each instance with its own metal
material. 960 x 540, 64 spp, depth 8, roulette from bounce 4.
"""

import argparse
import math
import os

import meshfile
import scenefile  # a sibling: the script's folder is on the path

LOOK_FROM = (0.0, 2.2, 10.2)
LOOK_AT = (0.0, 3.1, 0.0)
VFOV = 41.0

# Lights: (radius, colour with channel mean 1) left to right, all at LIGHT_Y, LIGHT_Z.
LIGHTS = [
    (0.03, (1.5, 0.9, 0.6)),   # orange
    (0.1, (1.3, 1.2, 0.5)),    # yellow
    (0.3, (0.6, 1.5, 0.9)),    # green
    (0.9, (0.6, 0.9, 1.5)),    # blue
]
LIGHT_X = [-3.75, -1.25, 1.25, 3.75]
LIGHT_Y, LIGHT_Z = 7.2, -2.0
POWER = 2.0  # emission x radius^2 of every light (its colour's mean)

# Plates, front to back: (fuzz, centre). Each is WIDTH wide (along x) and DEPTH
# deep, tilted about x so that its normal halves the angle between the camera and
# the middle of the row of lights, seen from its centre.
PLATES = [
    (0.02, (0.0, 0.8, 3.4)),
    (0.08, (0.0, 1.8, 1.8)),
    (0.25, (0.0, 2.8, 0.2)),
    (0.6, (0.0, 3.8, -1.4)),
]
WIDTH, DEPTH = 8.0, 1.3


def unit(v):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


def tilt(center):
    """Degrees about +x that turn the quad's normal (+y) to the plate's normal."""
    to_camera = unit([LOOK_FROM[k] - center[k] for k in range(3)])
    to_lights = unit([(0.0, LIGHT_Y, LIGHT_Z)[k] - center[k] for k in range(3)])
    n = unit([to_camera[k] + to_lights[k] for k in range(3)])
    # Rx(a) takes (0, 1, 0) to (0, cos a, sin a).
    return math.degrees(math.atan2(n[2], n[1]))


def build(obj_name):
    q = scenefile.rounder(4)
    materials = [{"name": "ground", "type": "lambertian", "albedo": [0.15, 0.15, 0.15]}]
    materials += [{"name": "plate_%d" % i, "type": "metal", "albedo": [0.8, 0.8, 0.8], "fuzz": fuzz}
                  for i, (fuzz, _) in enumerate(PLATES)]
    materials += [{"name": "light_%d" % i, "type": "emissive",
                   "emission": [q(POWER / (r * r) * c) for c in colour]}
                  for i, (r, colour) in enumerate(LIGHTS)]
    spheres = [{"center": [0, -1000, 0], "radius": 1000, "material": "ground"}]
    spheres += [{"center": [x, LIGHT_Y, LIGHT_Z], "radius": r, "material": "light_%d" % i}
                for i, ((r, _), x) in enumerate(zip(LIGHTS, LIGHT_X))]
    instances = [{"mesh": "plate", "material": "plate_%d" % i, "translate": list(center),
                  "rotate": [q(tilt(center)), 0, 0], "scale": [WIDTH, 1, DEPTH]}
                 for i, (_, center) in enumerate(PLATES)]
    return {
        "camera": {"look_from": list(LOOK_FROM), "look_at": list(LOOK_AT), "up": [0, 1, 0],
                   "vfov": VFOV, "aperture": 0},
        "sky": {"type": "uniform", "radiance": [0, 0, 0]},
        "render": {"width": 960, "height": 540, "spp": 64, "depth": 8, "roulette_depth": 4, "seed": 1},
        "materials": materials,
        "spheres": spheres,
        "meshes": [{"name": "plate", "file": obj_name}],
        "instances": instances,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", default=scenefile.scene_path("glossy-lights.json"), help="scene file to write")
    args = ap.parse_args()
    stem = os.path.splitext(args.output)[0]
    obj_name = os.path.basename(stem) + ".obj"
    # A unit quad in x and z at y = 0, facing +y (counter-clockwise seen from above).
    meshfile.write_obj(stem + ".obj", [(-0.5, 0, -0.5), (-0.5, 0, 0.5), (0.5, 0, 0.5), (0.5, 0, -0.5)],
                       [(0, 1, 2), (0, 2, 3)],
                       header="a unit quad in x and z at y = 0, facing +y; tools/make_glossy_lights.py")
    scene = build(obj_name)
    with open(args.output, "w") as f:
        f.write(scenefile.dumps_scene(scene))
    print("%s: %d spheres, %d plates, %d materials (+ %s)" % (
        os.path.normpath(args.output), len(scene["spheres"]), len(scene["instances"]), len(scene["materials"]),
        obj_name))


if __name__ == "__main__":
    main()
