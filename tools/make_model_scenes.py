#!/usr/bin/env python3
"""Writes scenes/generated/<model>.json: one scene per shared test mesh, standing on a ground.

    python3 tools/make_model_scenes.py MODELS_DIR [-o scenes/generated]

MODELS_DIR is the folder of shared test meshes (../shared/models from the
repository root; its README.md lists them). For each model found there:

| model | triangles | up axis | placed with |
| --- | --- | --- | --- |
| stanford-bunny.obj | 69,451 | +y | scene material "clay" (lambertian) |
| nefertiti.obj | 99,938 | +z, face toward -y | rotate [-90, 0, 0]: up to +y, face to +z; "plaster" (coated) |
| teapot.obj | 6,320 | +y | "porcelain" (coated) |
| spot.obj | 5,856 | +y | spot_texture.png as an image texture (sRGB) in a lambertian "spot" |

The OBJs carry no MTL, so each mesh gets its material through the mesh's
"material" override. Units differ between the files: the script reads each
OBJ's `v` lines for its bounding box, rotates it to y-up, scales it to
TALL = 2 units and moves it so that it stands on y = 0, centred on x = z = 0
(one instance: translate * rotate * scale). The ground is
generated/ground-quad.obj (a unit quad facing up, written into the output
folder) scaled to 100 x 100 with a grey lambertian. The camera looks at the
model's middle from the front and a little to the side and above, far enough
that the model's bounding sphere fills about 80% of the frame's height.

Paths in the written scenes are relative to the output folder (so to reach
MODELS_DIR from scenes/generated/ they climb out of the repository). A model
absent from MODELS_DIR is skipped with a notice on stderr; the generated scenes
are not committed (scenes/generated/ is ignored by git).
"""

import argparse
import math
import os
import sys
import time

import scenefile  # a sibling: the script's folder is on the path
import meshfile

TALL = 2.0
VFOV = 30.0
# name: (rotate in degrees, the direction the camera looks from, material, texture image or None)
MODELS = {
    "stanford-bunny": ([0, 0, 0], (-0.45, 0.3, 1.0),
                       {"name": "clay", "type": "lambertian", "albedo": [0.8, 0.55, 0.42]}, None),
    "nefertiti": ([-90, 0, 0], (0.5, 0.2, 1.0),
                  {"name": "plaster", "type": "coated", "albedo": [0.85, 0.78, 0.68], "ior": 1.5}, None),
    "teapot": ([0, 0, 0], (0.3, 0.45, 1.0),
               {"name": "porcelain", "type": "coated", "albedo": [0.9, 0.9, 0.87], "ior": 1.5}, None),
    "spot": ([0, 0, 0], (0.7, 0.35, 1.0),
             {"name": "spot", "type": "lambertian", "albedo": [1, 1, 1], "texture": "spot"}, "spot_texture.png"),
}


def apply(m, p):
    """The 3 x 4 part of the row-major 4 x 4 matrix M applied to point P."""
    return [m[4 * i] * p[0] + m[4 * i + 1] * p[1] + m[4 * i + 2] * p[2] + m[4 * i + 3] for i in range(3)]


def placement(lo, hi, rotate):
    """(translate, scale) that make the box (LO, HI), rotated by ROTATE, TALL
    units high, standing on y = 0 and centred on x = z = 0; and the placed box."""
    corners = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    r = meshfile.trs_matrix((0, 0, 0), rotate, 1)
    rc = [apply(r, c) for c in corners]
    rlo = [min(c[k] for c in rc) for k in range(3)]
    rhi = [max(c[k] for c in rc) for k in range(3)]
    s = TALL / (rhi[1] - rlo[1])
    t = [-s * (rlo[0] + rhi[0]) / 2, -s * rlo[1], -s * (rlo[2] + rhi[2]) / 2]
    m = meshfile.trs_matrix(t, rotate, s)
    placed = [apply(m, c) for c in corners]
    plo = [min(c[k] for c in placed) for k in range(3)]
    phi = [max(c[k] for c in placed) for k in range(3)]
    return t, s, plo, phi


def build(name, model_file, ground_file, texture_file, lo, hi):
    rotate, view, material, _ = MODELS[name]
    t, s, plo, phi = placement(lo, hi, rotate)
    def q(x):
        return float("%.9g" % x) + 0.0   # 9 digits: float32 exact enough; + 0.0: no -0.0
    center = [(a + b) / 2 for a, b in zip(plo, phi)]
    radius = 0.5 * math.sqrt(sum((b - a) ** 2 for a, b in zip(plo, phi)))
    dist = radius / math.sin(math.radians(0.8 * VFOV / 2))
    vn = math.sqrt(sum(c * c for c in view))
    eye = [center[k] + dist * view[k] / vn for k in range(3)]
    textures = []
    if texture_file:
        textures.append({"name": material["texture"], "type": "image", "file": texture_file, "colorspace": "srgb"})
    scene = {
        "camera": {"look_from": [q(c) for c in eye], "look_at": [q(c) for c in center], "up": [0, 1, 0],
                   "vfov": VFOV, "aperture": 0},
        "sky": {"type": "gradient", "horizon": [1, 1, 1], "zenith": [0.5, 0.7, 1.0]},
        "render": {"width": 960, "height": 720, "spp": 64, "depth": 16, "roulette_depth": 5, "seed": 1},
    }
    if textures:
        scene["textures"] = textures
    scene["materials"] = [{"name": "ground", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}, material]
    scene["meshes"] = [{"name": "ground", "file": ground_file, "material": "ground"},
                       {"name": name, "file": model_file, "material": material["name"]}]
    scene["instances"] = [{"mesh": "ground", "translate": [0, 0, 0], "scale": [50, 1, 50]},
                          {"mesh": name, "translate": [q(c) for c in t], "rotate": rotate, "scale": q(s)}]
    return scene, plo, phi


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("models_dir", metavar="MODELS_DIR", help="folder of the shared test meshes")
    ap.add_argument("-o", "--output", default=os.path.join(scenefile.HERE, "..", "scenes", "generated"),
                    help="folder to write the scenes (and ground-quad.obj) into")
    args = ap.parse_args()
    out = os.path.abspath(args.output)
    os.makedirs(out, exist_ok=True)
    ground = "ground-quad.obj"
    meshfile.write_ground_obj(os.path.join(out, ground))
    written = 0
    for name in MODELS:
        start = time.time()
        path = os.path.join(os.path.abspath(args.models_dir), name + ".obj")
        texture = MODELS[name][3]
        missing = [p for p in [path] + ([os.path.join(os.path.dirname(path), texture)] if texture else [])
                   if not os.path.isfile(p)]
        if missing:
            print("%s: skipped, %s not found" % (name, ", ".join(missing)), file=sys.stderr)
            continue
        lo, hi, nv, nt = meshfile.obj_stats(path)
        tex_rel = os.path.relpath(os.path.join(os.path.dirname(path), texture), out) if texture else None
        scene, plo, phi = build(name, os.path.relpath(path, out), ground, tex_rel, lo, hi)
        target = os.path.join(out, name + ".json")
        with open(target, "w") as f:
            f.write(scenefile.dumps_scene(scene))
        written += 1
        print("%s: %d triangles, %d vertices; box %s .. %s, placed %s .. %s; %.2f s"
              % (os.path.normpath(target), nt, nv, [round(v, 4) for v in lo], [round(v, 4) for v in hi],
                 [round(v, 3) for v in plo], [round(v, 3) for v in phi], time.time() - start))
    if not written:
        sys.exit("no model found in %s" % args.models_dir)


if __name__ == "__main__":
    main()
