#!/usr/bin/env python3
"""Writes scenes/cornell-box.json, .obj and .mtl: the Cornell box from its measured data.

    python3 tools/make_cornell_box.py [-o scenes/cornell-box.json]

The geometry is the Cornell Program of Computer Graphics' published data for
the box (www.graphics.cornell.edu/online/box/data.html), in millimetres, copied
unrounded: floor, ceiling, back wall, red left wall (x = 550), green right wall
(x = 0), the short and the tall block, and the light, a 130 x 105 quad that the
data places at y = 548.8 and that is moved here 0.1 below the ceiling
(y = 548.7) so that the two never share a plane. Triangles only: every quad of
the data is two triangles, (a, b, c) and (a, c, d), wound counter-clockwise
seen from the side it faces: walls, floor and ceiling face into the box, the
blocks' faces out of the blocks, the light down. The box has no front wall.

The materials are in the MTL, one per part, and the scene adds none:
white Kd 0.73 0.73 0.73, red Kd 0.65 0.05 0.05, green Kd 0.12 0.45 0.15 (the
usual RGB reductions of the measured spectra), and the light Kd 0.78 with
Ke 17 12 4: the warm radiance of the classic RGB Cornell box (as in pbrt's and
Mitsuba's versions), which wavetrace maps to an emissive material.

The camera is the data's: at (278, 273, -800) looking along +z, focal length
35 mm on a 25 mm film, so vfov = 2 atan(12.5 / 35) = 39.3076 degrees; red is
on the left. Sky black; 512 x 512, 64 spp, depth 16, roulette from bounce 5.
The OBJ and MTL are written beside the scene file.
"""

import argparse
import math
import os

import scenefile  # a sibling: the script's folder is on the path
import meshfile

# (object name, material, inward/outward direction it must face, quads).
# Each quad: four corners in order around it, as the published data lists them.
LIGHT_Y = 548.8 - 0.1
PARTS = [
    ("floor", "white", (0, 1, 0), [
        [(552.8, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 559.2), (549.6, 0.0, 559.2)]]),
    ("ceiling", "white", (0, -1, 0), [
        [(556.0, 548.8, 0.0), (556.0, 548.8, 559.2), (0.0, 548.8, 559.2), (0.0, 548.8, 0.0)]]),
    ("back_wall", "white", (0, 0, -1), [
        [(549.6, 0.0, 559.2), (0.0, 0.0, 559.2), (0.0, 548.8, 559.2), (556.0, 548.8, 559.2)]]),
    ("right_wall", "green", (1, 0, 0), [
        [(0.0, 0.0, 559.2), (0.0, 0.0, 0.0), (0.0, 548.8, 0.0), (0.0, 548.8, 559.2)]]),
    ("left_wall", "red", (-1, 0, 0), [
        [(552.8, 0.0, 0.0), (549.6, 0.0, 559.2), (556.0, 548.8, 559.2), (556.0, 548.8, 0.0)]]),
    ("short_block", "white", None, [
        [(130.0, 165.0, 65.0), (82.0, 165.0, 225.0), (240.0, 165.0, 272.0), (290.0, 165.0, 114.0)],
        [(290.0, 0.0, 114.0), (290.0, 165.0, 114.0), (240.0, 165.0, 272.0), (240.0, 0.0, 272.0)],
        [(130.0, 0.0, 65.0), (130.0, 165.0, 65.0), (290.0, 165.0, 114.0), (290.0, 0.0, 114.0)],
        [(82.0, 0.0, 225.0), (82.0, 165.0, 225.0), (130.0, 165.0, 65.0), (130.0, 0.0, 65.0)],
        [(240.0, 0.0, 272.0), (240.0, 165.0, 272.0), (82.0, 165.0, 225.0), (82.0, 0.0, 225.0)]]),
    ("tall_block", "white", None, [
        [(423.0, 330.0, 247.0), (265.0, 330.0, 296.0), (314.0, 330.0, 456.0), (472.0, 330.0, 406.0)],
        [(423.0, 0.0, 247.0), (423.0, 330.0, 247.0), (472.0, 330.0, 406.0), (472.0, 0.0, 406.0)],
        [(472.0, 0.0, 406.0), (472.0, 330.0, 406.0), (314.0, 330.0, 456.0), (314.0, 0.0, 456.0)],
        [(314.0, 0.0, 456.0), (314.0, 330.0, 456.0), (265.0, 330.0, 296.0), (265.0, 0.0, 296.0)],
        [(265.0, 0.0, 296.0), (265.0, 330.0, 296.0), (423.0, 330.0, 247.0), (423.0, 0.0, 247.0)]]),
    ("light", "light", (0, -1, 0), [
        [(343.0, LIGHT_Y, 227.0), (343.0, LIGHT_Y, 332.0), (213.0, LIGHT_Y, 332.0), (213.0, LIGHT_Y, 227.0)]]),
]

MTL = """# Cornell box materials; tools/make_cornell_box.py
newmtl white
Kd 0.73 0.73 0.73

newmtl red
Kd 0.65 0.05 0.05

newmtl green
Kd 0.12 0.45 0.15

newmtl light
Kd 0.78 0.78 0.78
Ke 17 12 4
"""


def normal(a, b, c):
    e1 = [b[k] - a[k] for k in range(3)]
    e2 = [c[k] - a[k] for k in range(3)]
    return (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def oriented(quad, facing, block_center):
    """QUAD's corners in the order that makes (a, b, c) x (a, c, d) face
    FACING, or away from BLOCK_CENTER where FACING is None."""
    n = normal(quad[0], quad[1], quad[2])
    if facing is None:
        centroid = [sum(p[k] for p in quad) / 4 for k in range(3)]
        facing = [centroid[k] - block_center[k] for k in range(3)]
    return quad if dot(n, facing) > 0 else quad[::-1]


def build_mesh():
    """(positions, groups) of the box; shared corners are written once per part."""
    positions, groups = [], []
    for name, material, facing, quads in PARTS:
        corners = [p for q in quads for p in q]
        center = [sum(p[k] for p in corners) / len(corners) for k in range(3)]
        faces = []
        for quad in quads:
            q = oriented(quad, facing, center)
            base = len(positions)
            positions += q
            faces += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
            for tri in ((q[0], q[1], q[2]), (q[0], q[2], q[3])):  # both halves agree
                n = normal(*tri)
                want = facing or [sum(tri[i][k] for i in range(3)) / 3 - center[k] for k in range(3)]
                assert dot(n, want) > 0, name
        groups.append((name, material, faces))
    return positions, groups


def build(obj_name):
    return {
        "camera": {"look_from": [278, 273, -800], "look_at": [278, 273, 0], "up": [0, 1, 0],
                   "vfov": round(math.degrees(2 * math.atan(12.5 / 35)), 4), "aperture": 0},
        "sky": {"type": "uniform", "radiance": [0, 0, 0]},
        "render": {"width": 512, "height": 512, "spp": 64, "depth": 16, "roulette_depth": 5, "seed": 1},
        "materials": [],
        "meshes": [{"name": "cornell-box", "file": obj_name}],
        "instances": [{"mesh": "cornell-box", "translate": [0, 0, 0]}],
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", default=scenefile.scene_path("cornell-box.json"), help="scene file to write")
    args = ap.parse_args()
    stem = os.path.splitext(args.output)[0]
    obj_name, mtl_name = os.path.basename(stem) + ".obj", os.path.basename(stem) + ".mtl"
    positions, groups = build_mesh()
    meshfile.write_obj(stem + ".obj", positions, None, mtllib=mtl_name, groups=groups,
                       header="Cornell box, measured data in mm (www.graphics.cornell.edu/online/box/data.html)\n"
                              "counter-clockwise seen from the side each face faces; tools/make_cornell_box.py")
    with open(stem + ".mtl", "w") as f:
        f.write(MTL)
    scene = build(obj_name)
    with open(args.output, "w") as f:
        f.write(scenefile.dumps_scene(scene))
    triangles = sum(len(g[2]) for g in groups)
    print("%s: %d triangles in %d parts (+ %s, %s)" % (os.path.normpath(args.output), triangles, len(groups),
                                                         obj_name, mtl_name))


if __name__ == "__main__":
    main()
