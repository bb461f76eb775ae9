#!/usr/bin/env python3
"""Writes scenes/materials.json, cornell-materials.json and their -single twins: conductor, glass, plastic.

    python3 tools/make_materials.py [-d scenes] [--regions OUT.json|-] [--width W --height H]

materials.json: a table of spheres standing on a ground sphere (radius 1000, a
lambertian checker) under the environment textures/sky_sun.hdr, nothing else
lighting it. Six columns, roughness 0, 0.1, 0.25, 0.5, 0.75, 1 from left to
right; the rows, top (far) to bottom (near):

    gold, silver, copper, aluminium, iron, chromium   `conductor`, `metal` presets
    glass                                             `glass`, ior 1.5
    plastic                                           `plastic`, albedo (0.8, 0.2, 0.1), ior 1.5
    thin glass | brushed aluminium |                  a `thin` glass sphere (roughness 0); `conductor`
      checker-rough gold | f0 conductor               aluminium, roughness 0.5, anisotropy 1;
                                                      `conductor` gold, roughness 0.5 times a
                                                      `roughness_texture` (a checker of 0.25: 1 and
                                                      0.2, so 0.5 and 0.1); `conductor`, f0 (0.96,
                                                      0.74, 0.64), roughness 0.25

Every sphere has radius 0.5 and rests on the ground (its centre 1000.5 from the
ground's). Columns are 1.5 apart, rows 2: far enough that no sphere stands in
another's shadow from the sun (29 degrees up, toward -z and +x). The camera
looks along +z (so +x is on the left and the sun behind its left shoulder) from
55 away and 45 degrees above the ground, at (0, 0.5, -0.9), vfov 13.5: all rows
in 16:9, the spheres 74 to 91 pixels across at the scene's size (1920 x 1080,
near rows larger), none hiding any part of another. At that size no two
spheres' pixel bounding boxes meet and none leaves the image, so each sphere's
pixels can be masked by its box: the script checks this and stops otherwise.
64 spp, depth 16, roulette from bounce 5.

Left of the table (+x) lies a normal-mapped plane: a 4 x 10 quad on y = 0,
x in [5.5, 9.5], z in [-5, 5] (above the ground sphere everywhere: the ground
is 0.015 and more below it), facing up, written as materials-plane.obj (two
triangles, UVs, no normals, no MTL) beside the scene. Its material is
`plastic`, albedo (0.25, 0.45, 0.7), roughness 0.3, with "normal_texture"
textures/bumps_normal.png (tools/make_textures.cpp; "colorspace": "linear",
"wrap": "repeat"). The UVs tile the map every 2 units (u 0 to 2, v 0 to 5):
u runs along -x (the image's right) and OBJ's v along +z (up the image), so
the map lies the way up it was drawn, seen from above, and the UV frame is
right-handed (the tangent dp/du, the bitangent cross(n, dp/du) up the
image: wavetrace's and Mitsuba's tangent frames agree there). Its projection
meets no sphere's box either, which the script checks too.

materials.json has wavetrace's defaults: height-correlated Smith masking, and
rough conductors and glass energy-compensated. materials-single.json is the
same scene in Mitsuba 3's exact models (bench/mitsuba_peer.py): every
conductor and glass "energy_compensation": false (single scattering only) and
every conductor, glass and plastic "masking": "separable" (G1(wo) G1(wi), as
Mitsuba's MicrofacetDistribution::G).

cornell-materials.json: the Cornell box of tools/make_cornell_box.py (its
geometry, materials, camera and render settings, from that script) with the
tall block rough gold (`conductor`, gold, roughness 0.3) and the short block
rough glass (`glass`, roughness 0.2). A mesh takes one scene material, so the
box is written as three OBJ files beside the scene: the room and the light
(cornell-materials-room.obj, materials in cornell-materials.mtl, the box's own
MTL) and each block on its own (cornell-materials-short-block.obj,
cornell-materials-tall-block.obj; no MTL: the scene's material is the mesh's).
The blocks are the data's open boxes (no bottom face; they stand on the floor).
cornell-materials-single.json: the same in Mitsuba's models, as
materials-single.json.

--regions OUT.json (or - for stdout) writes, for materials.json rendered at
--width x --height (default: the scene's 1920 x 1080), each sphere's index in
the scene's sphere list, material, row and roughness, centre and radius, the
pixel of its projected centre and two pixel boxes [x0, y0, x1, y1] (x1 and y1
exclusive, row 0 at the top as in wavetrace's images): `bbox`, every pixel the
sphere's silhouette touches (computed exactly, from the planes through the eye
that touch the sphere), and `inner`, a box of pixels wholly inside the
silhouette, for per-sphere means that take nothing of the ground. `planes`
does the same for the plane (its instance's index, material, corners, the
pixel of its centre, `bbox` and `inner`: the projected quad is convex, so a
box whose corners see the quad lies inside it).
"""

import argparse
import math
import os
import sys

import scenefile  # a sibling: the script's folder is on the path
import meshfile
import make_cornell_box

# ---------------------------------------------------------------- the sphere table

ROUGHNESS = [0, 0.1, 0.25, 0.5, 0.75, 1]
METALS = ["gold", "silver", "copper", "aluminium", "iron", "chromium"]
PLASTIC_ALBEDO = [0.8, 0.2, 0.1]
IOR = 1.5
# The last row: (material, column position in units of the column spacing,
# counted from the table's centre).
LAST_ROW = [
    ({"name": "thin-glass", "type": "glass", "ior": IOR, "thin": True}, -2.0),
    ({"name": "brushed-aluminium", "type": "conductor", "metal": "aluminium", "roughness": 0.5,
      "anisotropy": 1}, 0.0),
    ({"name": "f0-conductor", "type": "conductor", "f0": [0.96, 0.74, 0.64], "roughness": 0.25}, 2.0),
    ({"name": "checker-rough-gold", "type": "conductor", "metal": "gold", "roughness": 0.5,
      "roughness_texture": "roughness-checker"}, 1.0),   # last: the spheres before keep their indices
]

RADIUS = 0.5
COLUMN_PITCH = 1.5   # along x
ROW_PITCH = 2.0      # along z
GROUND_RADIUS = 1000.0
# The camera looks along +z (the sun of sky_sun.hdr is toward -z: behind it);
# its right is -x, so the columns run from +x (roughness 0) to -x.
LOOK_AT = (0.0, 0.5, -0.9)
ELEVATION = 45.0     # degrees above the ground
DISTANCE = 55.0
VFOV = 13.5
WIDTH, HEIGHT = 1920, 1080

# The textures: the ground's, the checker that scales checker-rough-gold's
# roughness (its green channel: 1 and 0.2) and the plane's normal map.
TEXTURES = [
    {"name": "tiles", "type": "checker", "size": 0.5, "even": [0.75, 0.75, 0.72], "odd": [0.35, 0.35, 0.33]},
    {"name": "roughness-checker", "type": "checker", "size": 0.25, "even": [1, 1, 1], "odd": [0.2, 0.2, 0.2]},
    {"name": "bumps", "type": "image", "file": "textures/bumps_normal.png", "colorspace": "linear",
     "wrap": "repeat"},
]

# The normal-mapped plane: x0..x1 by z0..z1 on y = 0, facing up; its UVs repeat
# the map every PLANE_TILE units.
PLANE_STEM = "materials-plane"
PLANE_X = (5.5, 9.5)
PLANE_Z = (-5.0, 5.0)
PLANE_TILE = 2.0
PLANE_MATERIAL = {"name": "bumpy-plastic", "type": "plastic", "albedo": [0.25, 0.45, 0.7], "ior": IOR,
                  "roughness": 0.3, "normal_texture": "bumps"}


def rows():
    """[(row label, [(material, column offset)])], top (far) row first."""
    out = []
    for metal in METALS:
        out.append((metal, [({"name": "%s-%g" % (metal, r), "type": "conductor", "metal": metal, "roughness": r},
                             c - 2.5) for c, r in enumerate(ROUGHNESS)]))
    out.append(("glass", [({"name": "glass-%g" % r, "type": "glass", "ior": IOR, "roughness": r}, c - 2.5)
                          for c, r in enumerate(ROUGHNESS)]))
    out.append(("plastic", [({"name": "plastic-%g" % r, "type": "plastic", "albedo": PLASTIC_ALBEDO, "ior": IOR,
                              "roughness": r}, c - 2.5) for c, r in enumerate(ROUGHNESS)]))
    out.append(("special", [(dict(m), c) for m, c in LAST_ROW]))
    return out


def on_ground(x, z):
    """The centre of a sphere of RADIUS resting on the ground sphere above (x, z)."""
    y = math.sqrt((GROUND_RADIUS + RADIUS) ** 2 - x * x - z * z) - GROUND_RADIUS
    return [x, y, z]


def camera():
    e = math.radians(ELEVATION)
    look_from = [LOOK_AT[0], LOOK_AT[1] + DISTANCE * math.sin(e), LOOK_AT[2] - DISTANCE * math.cos(e)]
    return {"look_from": [round(v, 4) for v in look_from], "look_at": list(LOOK_AT), "up": [0, 1, 0],
            "vfov": VFOV, "aperture": 0}


def mitsuba_model(material):
    """The material in Mitsuba's model: energy compensation off (conductor,
    glass) and separable masking (conductor, glass, plastic)."""
    m = dict(material)
    if m["type"] in ("conductor", "glass"):
        m["energy_compensation"] = False
    if m["type"] in ("conductor", "glass", "plastic"):
        m["masking"] = "separable"
    return m


def plane_corners():
    """The plane's corners (x, y, z) and their OBJ UVs, counter-clockwise seen
    from above: u grows along -x, OBJ's v along +z."""
    (x0, x1), (z0, z1) = PLANE_X, PLANE_Z
    corners = [(x1, 0.0, z0), (x0, 0.0, z0), (x0, 0.0, z1), (x1, 0.0, z1)]
    uvs = [((x1 - x) / PLANE_TILE, (z - z0) / PLANE_TILE) for x, _, z in corners]
    return corners, uvs


def write_plane(folder):
    """materials-plane.obj: the plane as two triangles with UVs. Returns its name."""
    corners, uvs = plane_corners()
    name = PLANE_STEM + ".obj"
    meshfile.write_obj(os.path.join(folder, name), corners, [(0, 1, 2), (0, 2, 3)], uvs=uvs,
                       header="the normal-mapped plane of materials.json (its material is the scene's): "
                              "y = 0, facing +y,\nUVs tiling every %g units; tools/make_materials.py" % PLANE_TILE)
    return name


def build_table(single=False):
    """materials.json, or (single) materials-single.json."""
    materials = [{"name": "ground", "type": "lambertian", "albedo": [1, 1, 1], "texture": "tiles"}]
    spheres = [{"center": [0, -GROUND_RADIUS, 0], "radius": GROUND_RADIUS, "material": "ground"}]
    table = rows()
    for i, (label, entries) in enumerate(table):
        z = (len(table) - 1) / 2.0 * ROW_PITCH - i * ROW_PITCH   # the first row farthest (+z)
        for m, offset in entries:
            materials.append(mitsuba_model(m) if single else m)
            spheres.append({"center": [round(v, 6) for v in on_ground(-offset * COLUMN_PITCH, z)],
                            "radius": RADIUS, "material": m["name"]})
    materials.append(mitsuba_model(PLANE_MATERIAL) if single else dict(PLANE_MATERIAL))
    return {
        "camera": camera(),
        "sky": {"type": "environment", "file": "textures/sky_sun.hdr", "mapping": "latlong", "rotation": 0,
                "intensity": 1},
        "render": {"width": WIDTH, "height": HEIGHT, "spp": 64, "depth": 16, "roulette_depth": 5, "seed": 1},
        # Mitsuba's bitmap has no mip-maps: the -single twin filters as it does.
        "textures": [dict(t, filter="bilinear") if single and t["type"] == "image" else dict(t) for t in TEXTURES],
        "materials": materials,
        "spheres": spheres,
        "meshes": [{"name": "plane", "file": PLANE_STEM + ".obj", "material": PLANE_MATERIAL["name"]}],
        "instances": [{"mesh": "plane", "translate": [0, 0, 0]}],
    }


# ---------------------------------------------------------------- projection (wavetrace's camera)

def _sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def _dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _unit(a):
    n = math.sqrt(_dot(a, a))
    return [x / n for x in a]


class Projection:
    """include/wavetrace/camera.hpp's pinhole camera: pixel (x, y), row 0 at the
    top, looks through image point s = x / width, t = y / height of the plane
    spanned by `horizontal` (left to right) and `vertical` (top to bottom)."""

    def __init__(self, cam, width, height):
        self.origin = [float(v) for v in cam["look_from"]]
        self.w = _unit(_sub(cam["look_from"], cam["look_at"]))
        self.u = _unit(_cross(cam.get("up", [0, 1, 0]), self.w))
        self.v = _cross(self.w, self.u)
        self.half_h = math.tan(math.radians(cam.get("vfov", 40)) / 2)
        self.half_w = self.half_h * width / height
        self.width, self.height = width, height

    def camera_space(self, p):
        """(right, up, forward) coordinates of a world point."""
        d = _sub(p, self.origin)
        return _dot(d, self.u), _dot(d, self.v), -_dot(d, self.w)

    def pixel(self, p):
        x, y, z = self.camera_space(p)
        return ((0.5 + x / z / (2 * self.half_w)) * self.width, (0.5 - y / z / (2 * self.half_h)) * self.height)

    def ray(self, px, py):
        a = (px / self.width - 0.5) * 2 * self.half_w
        b = (0.5 - py / self.height) * 2 * self.half_h
        return _unit([a * self.u[i] + b * self.v[i] - self.w[i] for i in range(3)])

    def sees(self, px, py, center, radius):
        """Whether the ray through image point (px, py) meets the sphere."""
        d = self.ray(px, py)
        oc = _sub(self.origin, center)
        b = _dot(oc, d)
        return b < 0 and b * b - (_dot(oc, oc) - radius * radius) >= 0

    def extent(self, center, radius):
        """(x_min, y_min, x_max, y_max) of the sphere's silhouette in continuous
        pixel coordinates: each bound from the plane through the eye, holding an
        image axis, that touches the sphere."""
        x, y, z = self.camera_space(center)

        def tangents(a):
            phi = math.atan2(a, z)
            delta = math.asin(min(1.0, radius / math.hypot(a, z)))
            if abs(phi) + delta >= math.pi / 2:
                raise ValueError("a sphere reaches behind the camera's image plane")
            return math.tan(phi - delta), math.tan(phi + delta)

        tx0, tx1 = tangents(x)
        ty0, ty1 = tangents(y)
        return ((0.5 + tx0 / (2 * self.half_w)) * self.width, (0.5 - ty1 / (2 * self.half_h)) * self.height,
                (0.5 + tx1 / (2 * self.half_w)) * self.width, (0.5 - ty0 / (2 * self.half_h)) * self.height)


def inner_box(sees, ext):
    """The largest box of whole pixels, centred in the silhouette's bounding box,
    whose four corners (and so, the silhouette being convex, all of it) lie
    inside. sees(px, py): whether image point (px, py) is inside."""
    cx, cy = 0.5 * (ext[0] + ext[2]), 0.5 * (ext[1] + ext[3])
    hx, hy = 0.5 * (ext[2] - ext[0]), 0.5 * (ext[3] - ext[1])
    best = None
    lo, hi = 0.0, 1.0
    for _ in range(40):
        s = 0.5 * (lo + hi)
        box = (math.ceil(cx - s * hx), math.ceil(cy - s * hy), math.floor(cx + s * hx), math.floor(cy + s * hy))
        corners = [(box[0], box[1]), (box[2], box[1]), (box[0], box[3]), (box[2], box[3])]
        if box[2] > box[0] and box[3] > box[1] and all(sees(px, py) for px, py in corners):
            best, lo = box, s
        else:
            hi = s
    return list(best) if best else None


def regions(scene, width, height):
    """Each sphere but the ground: where it lands in a width x height image."""
    proj = Projection(scene["camera"], width, height)
    labels = {}
    for label, entries in rows():
        for m, _ in entries:
            labels[m["name"]] = label
    out = []
    for index, s in enumerate(scene["spheres"]):
        if s["material"] == "ground":
            continue
        m = next(m for m in scene["materials"] if m["name"] == s["material"])
        ext = proj.extent(s["center"], s["radius"])
        bbox = [max(0, math.floor(ext[0])), max(0, math.floor(ext[1])),
                min(width, math.ceil(ext[2])), min(height, math.ceil(ext[3]))]
        cx, cy = proj.pixel(s["center"])
        out.append({"index": index, "material": s["material"], "row": labels[s["material"]], "type": m["type"],
                    "roughness": m.get("roughness", 0), "center": s["center"], "radius": s["radius"],
                    "center_px": [round(cx, 3), round(cy, 3)], "bbox": bbox,
                    "inner": inner_box(lambda px, py: proj.sees(px, py, s["center"], s["radius"]), ext)})
    return out


def plane_regions(scene, width, height):
    """The plane (each instance of the mesh PLANE_STEM.obj): where it lands in a
    width x height image."""
    proj = Projection(scene["camera"], width, height)
    corners, _ = plane_corners()
    (x0, x1), (z0, z1) = PLANE_X, PLANE_Z

    def sees(px, py):
        d = proj.ray(px, py)
        if d[1] >= 0:
            return False
        t = -proj.origin[1] / d[1]
        x, z = proj.origin[0] + t * d[0], proj.origin[2] + t * d[2]
        return x0 <= x <= x1 and z0 <= z <= z1

    meshes = {m["name"]: m for m in scene.get("meshes", [])}
    out = []
    for index, inst in enumerate(scene.get("instances", [])):
        mesh = meshes[inst["mesh"]]
        if mesh["file"] != PLANE_STEM + ".obj":
            continue
        material = inst.get("material", mesh.get("material"))
        m = next(m for m in scene["materials"] if m["name"] == material)
        pixels = [proj.pixel(c) for c in corners]
        ext = (min(p[0] for p in pixels), min(p[1] for p in pixels), max(p[0] for p in pixels),
               max(p[1] for p in pixels))
        bbox = [max(0, math.floor(ext[0])), max(0, math.floor(ext[1])),
                min(width, math.ceil(ext[2])), min(height, math.ceil(ext[3]))]
        cx, cy = proj.pixel([0.5 * (x0 + x1), 0.0, 0.5 * (z0 + z1)])
        out.append({"instance": index, "mesh": inst["mesh"], "material": material, "type": m["type"],
                    "roughness": m.get("roughness", 0), "corners": [list(c) for c in corners],
                    "center_px": [round(cx, 3), round(cy, 3)], "bbox": bbox, "inner": inner_box(sees, ext)})
    return out


def overlapping(regs, width, height):
    """Pairs of regions (spheres, the plane) whose boxes meet, and regions whose
    box leaves the image."""
    problems = []
    for r in regs:
        ext = r["bbox"]
        if ext[0] <= 0 or ext[1] <= 0 or ext[2] >= width or ext[3] >= height:
            problems.append("%s leaves the image" % r["material"])
    for i, a in enumerate(regs):
        for b in regs[i + 1:]:
            A, B = a["bbox"], b["bbox"]
            if A[0] < B[2] and B[0] < A[2] and A[1] < B[3] and B[1] < A[3]:
                problems.append("%s and %s" % (a["material"], b["material"]))
    return problems


# ---------------------------------------------------------------- the Cornell box

CORNELL_STEM = "cornell-materials"
BLOCK_MATERIALS = {
    "tall_block": {"name": "rough-gold", "type": "conductor", "metal": "gold", "roughness": 0.3},
    "short_block": {"name": "rough-glass", "type": "glass", "ior": IOR, "roughness": 0.2},
}


def _subset(positions, faces):
    """The corners FACES use, renumbered from 0, and the faces on them."""
    used = sorted({i for f in faces for i in f})
    where = {old: new for new, old in enumerate(used)}
    return [positions[i] for i in used], [tuple(where[i] for i in f) for f in faces]


def write_cornell_meshes(folder):
    """The box of make_cornell_box.py as three OBJ files (+ the MTL): the room
    with the light, and each block. Returns the files' names."""
    positions, groups = make_cornell_box.build_mesh()
    header = ("Cornell box (tools/make_cornell_box.py's data, in mm): %s\n"
              "counter-clockwise seen from the side each face faces; tools/make_materials.py")
    names = {"room": CORNELL_STEM + "-room.obj", "short_block": CORNELL_STEM + "-short-block.obj",
             "tall_block": CORNELL_STEM + "-tall-block.obj"}
    mtl = CORNELL_STEM + ".mtl"
    room = [g for g in groups if g[0] not in BLOCK_MATERIALS]
    # The room's groups share one list of corners: keep those they use, renumbered.
    pos, tris = _subset(positions, [f for g in room for f in g[2]])
    room, k = list(room), 0
    for i, (name, material, fs) in enumerate(room):
        room[i] = (name, material, tris[k:k + len(fs)])
        k += len(fs)
    meshfile.write_obj(os.path.join(folder, names["room"]), pos, None, mtllib=mtl, groups=room,
                       header=header % "the walls, floor, ceiling and light")
    with open(os.path.join(folder, mtl), "w") as f:
        f.write(make_cornell_box.MTL)
    for name, _, fs in groups:
        if name in BLOCK_MATERIALS:
            pos, tris = _subset(positions, fs)
            meshfile.write_obj(os.path.join(folder, names[name]), pos, tris,
                               header=header % ("the %s (its material is the scene's)" % name.replace("_", " ")))
    return names, mtl


def build_cornell(names, single=False):
    """cornell-materials.json, or (single) cornell-materials-single.json."""
    scene = make_cornell_box.build(names["room"])
    materials = [mitsuba_model(m) if single else m for m in BLOCK_MATERIALS.values()]
    meshes = [{"name": "room", "file": names["room"]}]
    instances = [{"mesh": "room", "translate": [0, 0, 0]}]
    for block in ("short_block", "tall_block"):
        meshes.append({"name": block, "file": names[block], "material": BLOCK_MATERIALS[block]["name"]})
        instances.append({"mesh": block, "translate": [0, 0, 0]})
    scene["materials"] = materials
    scene["meshes"] = meshes
    scene["instances"] = instances
    return scene


# ---------------------------------------------------------------- the command line

def write(path, scene):
    with open(path, "w") as f:
        f.write(scenefile.dumps_scene(scene))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-d", "--dir", default=os.path.join(scenefile.HERE, "..", "scenes"),
                    help="folder to write the scenes into (default: scenes/)")
    ap.add_argument("--regions", metavar="OUT.json",
                    help="also write each sphere's pixel boxes in materials.json (- for stdout)")
    ap.add_argument("--width", type=int, default=WIDTH, help="image width for --regions")
    ap.add_argument("--height", type=int, default=HEIGHT, help="image height for --regions")
    args = ap.parse_args()
    folder = args.dir
    table = build_table()
    problems = overlapping(regions(table, WIDTH, HEIGHT) + plane_regions(table, WIDTH, HEIGHT), WIDTH, HEIGHT)
    if problems:
        sys.exit("make_materials: at %d x %d, sphere or plane boxes overlap or leave the image: %s"
                 % (WIDTH, HEIGHT, "; ".join(problems)))
    write(os.path.join(folder, "materials.json"), table)
    write(os.path.join(folder, "materials-single.json"), build_table(single=True))
    plane = write_plane(folder)
    names, mtl = write_cornell_meshes(folder)
    write(os.path.join(folder, CORNELL_STEM + ".json"), build_cornell(names))
    write(os.path.join(folder, CORNELL_STEM + "-single.json"), build_cornell(names, single=True))
    counts = scenefile.counts_text(scenefile.spheres_by(table, lambda m: m["type"]))
    log = sys.stderr if args.regions == "-" else sys.stdout   # stdout may be the regions
    print("%s: %d spheres (%s), a plane (%s), and materials-single.json"
          % (os.path.normpath(os.path.join(folder, "materials.json")), len(table["spheres"]), counts, plane), file=log)
    print("%s: + %s, %s, %s, %s, and %s-single.json" % (
        os.path.normpath(os.path.join(folder, CORNELL_STEM + ".json")), names["room"], mtl, names["short_block"],
        names["tall_block"], CORNELL_STEM), file=log)
    if args.regions:
        regs = regions(table, args.width, args.height)
        planes = plane_regions(table, args.width, args.height)
        problems = overlapping(regs + planes, args.width, args.height)
        if problems:
            print("make_materials: warning: at %d x %d, boxes overlap or leave the image: %s"
                  % (args.width, args.height, "; ".join(problems)), file=sys.stderr)
        text = scenefile.dumps_scene({"scene": "materials.json", "width": args.width, "height": args.height,
                                      "spheres": regs, "planes": planes})
        if args.regions == "-":
            sys.stdout.write(text)
        else:
            with open(args.regions, "w") as f:
                f.write(text)


if __name__ == "__main__":
    main()
