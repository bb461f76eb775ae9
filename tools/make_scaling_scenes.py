#!/usr/bin/env python3
"""Writes the scene-size series of the scaling benchmark: N spheres and N triangles, N = 10 ... 10^7.

    python3 tools/make_scaling_scenes.py [--spheres N,N,...] [--triangles N,N,...] [--out DIR] [--check]

Written to scenes/generated/scaling/ (git ignores scenes/generated/) by default:
spheres-1e1.json ... spheres-1e6.json and triangles-1e1.json ... triangles-1e7.json
(each with its triangles-1eK.glb), and manifest.json, which lists every file with
what it holds. bench/scaling-size.json times them; scripts/scaling.sh runs it all.

Both series show the same thing at every N, so that a change of cost comes from N
and not from what is seen: the same camera (looking down at about 55 degrees), the
same patch of ground, x in [-18.5, 18.5] and z in [-8, 13.5] (37 x 21.5 units;
about two thirds of it is in the frame, which it fills), a gradient sky and
no emitters (as seed57), and the same material mix, seed57's small spheres' mix:
31 : 12 : 6 lambertian : metal : dielectric (63% : 24% : 12%).

- spheres-N: N unique spheres (every one a record of the scene file: the scene
  format has no instancing of spheres; instances place meshes only) on a jittered
  grid of about square cells over the patch, one sphere in each of N cells, each
  resting on the ground. The radius shrinks as 1 / sqrt(N), so that the spheres
  cover 45% of the patch seen from above at every N (10 spheres of radius 3.33 ...
  10^6 of radius 0.0107, 10^7 of 0.0034). Plus one ground sphere (radius 1000,
  seed57's checker): N + 1 spheres in all, one level of BVH over the spheres.
  Materials: 8 lambertian colours, 4 metals (fuzz 0 to 0.09), one glass (ior 1.5),
  a sphere's kind from a low-discrepancy sequence, so that even N = 10 has the mix
  (7 lambertian, 2 metal, 1 glass). Spheres smaller than about 0.01 (N >= 10^6) are
  within ten times the fixed offset (1e-3) by which secondary rays leave a sphere
  (docs/scene-format.md), so their refraction is approximate; the work is not.
  Files: about 75 bytes a sphere (75 MB at 10^6, 0.75 GB at 10^7), written at about
  1.7 us a sphere. wavetrace parses a sphere in about 2 us on the build machine
  and 2.5-3 us on the H100's host (bench/RESULTS.md, "Scene loading"), and builds
  the BVH in about 1 us more: 10^6 spheres load in 3.5-5 s, 10^7 take about 20 s
  to write and 40-60 s to load on the GPU machine (6 GB of host memory), for one
  bench point. So
  spheres-1e7 is written only when asked for (--spheres 10,...,10000000;
  SCALING_SPHERES_1E7=1 scripts/scaling.sh).
- triangles-N: one mesh of exactly N unique triangles (no instancing), placed once:
  a height field (smooth rolling hills, 0 to 4.3 units high) over the same patch,
  a grid of a x b quads, two triangles a quad, 2ab = N with a / b as near 37 / 21.5
  as N's divisors allow (N = 10: 5 x 1 quads; 10^7: 3125 x 1600). The surface is the
  same function at every N, only finer; the camera sees nothing else. Materials by
  world-space patches of about 5 x 5 units (7 x 4 of them, the same at every N; a
  triangle takes the patch of its block of quads, so at N = 10 the 5 quads show 5 of
  the 28 patches), the patch's kind from the same sequence; glTF has no
  dielectric (docs/scene-format.md: glTF maps to lambertian, metal or coated), and
  a dielectric height field would be an open sheet of glass, so the 12% share of
  glass is `coated` (a clear coat over a diffuse base) on the triangles. The GLB
  holds positions and indices only (no normals or UVs: shading uses the flat
  geometric normal), one primitive per patch; 18 bytes a triangle (180 MB at 10^7),
  a few seconds to write.

The whole default set (10^7 triangles, 10^6 spheres) is written in about 6 s on
the 2-core build machine, 280 MB; a file that is already there and was written by
this version of the script is kept (manifest.json says which; --force rewrites). Everything is deterministic (fixed seeds).
--check re-reads the files and counts what they hold (spheres by reading the
scene file, triangles by reading the GLB, meshfile.check_glb).
"""

import argparse
import array
import hashlib
import json
import math
import os
import random
import sys
import time

import meshfile  # siblings: the script's folder is on the path
import scenefile

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_OUT = os.path.normpath(os.path.join(HERE, "..", "scenes", "generated", "scaling"))
DEFAULT_SPHERES = [10 ** k for k in range(1, 7)]
DEFAULT_TRIANGLES = [10 ** k for k in range(1, 8)]

# The patch every scene covers, and the camera that sees it.
X0, X1 = -18.5, 18.5
Z0, Z1 = -8.0, 13.5
WIDTH, DEPTH = X1 - X0, Z1 - Z0
CAMERA = {"look_from": [0, 20, -12], "look_at": [0, 0, 1.5], "up": [0, 1, 0], "vfov": 34, "aperture": 0}
SKY = {"type": "gradient", "horizon": [1, 1, 1], "zenith": [0.5, 0.7, 1]}
RENDER = {"width": 1920, "height": 1080, "spp": 32, "depth": 16, "roulette_depth": 16, "seed": 1}

GROUND_RADIUS = 1000.0
COVER = 0.45        # the share of the patch the spheres cover, seen from above
MAX_FILL = 0.45     # radius at most this much of a cell's shorter side
SPHERE_SEED = 57

# seed57's small spheres: 31 lambertian, 12 metal, 6 dielectric of 49.
SHARE_LAMBERTIAN = 31 / 49
SHARE_METAL = 12 / 49
GOLDEN = 0.6180339887498949
PLASTIC = 0.7548776662466927   # a second irrational, for the variant within a kind

LAMBERTIAN = [[0.8, 0.3, 0.2], [0.2, 0.6, 0.3], [0.3, 0.4, 0.8], [0.9, 0.8, 0.3],
              [0.6, 0.2, 0.7], [0.5, 0.5, 0.5], [0.1, 0.7, 0.7], [0.9, 0.5, 0.1]]
METAL = [([0.9, 0.9, 0.9], 0.0), ([0.8, 0.6, 0.5], 0.03), ([0.6, 0.8, 0.8], 0.06), ([0.7, 0.7, 0.9], 0.09)]
GLASS_IOR = 1.5
COATED = [0.7, 0.1, 0.1]   # the triangles' stand-in for glass: a red lacquer, clear coat ior 1.5
PATCH = 5.0                # triangles: material patches of 5 x 5 units


def label(n):
    """10 -> '1e1', 10^7 -> '1e7'; other counts as they are."""
    k = round(math.log10(n)) if n > 0 else 0
    return "1e%d" % k if 10 ** k == n else str(n)


def kind_of(k):
    """The material of item k: ('lambertian', i), ('metal', i) or ('glass', 0),
    from a low-discrepancy sequence, so that any run of items has the mix."""
    u = (0.5 + k * GOLDEN) % 1.0
    v = (0.5 + k * PLASTIC) % 1.0
    if u < SHARE_LAMBERTIAN:
        return "lambertian", int(v * len(LAMBERTIAN))
    if u < SHARE_LAMBERTIAN + SHARE_METAL:
        return "metal", int(v * len(METAL))
    return "glass", 0


# ---------------------------------------------------------------- spheres

def sphere_materials():
    mats = [{"name": "ground", "type": "lambertian", "albedo": [1, 1, 1], "texture": "checker"}]
    mats += [{"name": "l%d" % i, "type": "lambertian", "albedo": c} for i, c in enumerate(LAMBERTIAN)]
    mats += [{"name": "m%d" % i, "type": "metal", "albedo": c, "fuzz": f} for i, (c, f) in enumerate(METAL)]
    mats.append({"name": "g", "type": "dielectric", "ior": GLASS_IOR})
    return mats


def sphere_grid(n):
    """(gx, gz, radius): a grid of gx x gz >= n cells of about square shape over
    the patch, and the radius that covers COVER of the patch with n spheres."""
    gz = max(1, round(math.sqrt(n * DEPTH / WIDTH)))
    gx = -(-n // gz)
    cell = min(WIDTH / gx, DEPTH / gz)
    radius = min(MAX_FILL * cell, math.sqrt(COVER * WIDTH * DEPTH / (n * math.pi)))
    return gx, gz, radius


def write_spheres(path, n):
    """Writes the scene of n spheres (and the ground); returns (spheres, radius)."""
    gx, gz, r = sphere_grid(n)
    cx, cz = WIDTH / gx, DEPTH / gz
    jx, jz = 0.9 * (cx / 2 - r), 0.9 * (cz / 2 - r)   # the jitter that keeps neighbours apart
    cells = gx * gz
    rng = random.Random(SPHERE_SEED * 1000003 + n)
    uniform = rng.random
    R2 = GROUND_RADIUS * GROUND_RADIUS
    rtext = "%.6g" % r
    head = {"camera": CAMERA, "sky": SKY, "render": RENDER,
            "textures": [{"name": "checker", "type": "checker", "size": 4,
                          "even": [0.95, 0.95, 0.95], "odd": [0.05, 0.05, 0.05]}],
            "materials": sphere_materials()}
    count = 0
    with open(path, "w") as f:
        f.write("{\n" + "".join("  %s: %s,\n" % (json.dumps(k), json.dumps(v)) for k, v in head.items()))
        f.write('  "spheres": [\n    {"center": [0, -1000, 0], "radius": 1000, "material": "ground"}')
        lines = []
        for cell in range(cells):
            # One sphere in each of n cells of the gx * gz, spread evenly over them.
            if cells != n and (cell + 1) * n // cells == cell * n // cells:
                continue
            j, i = divmod(cell, gx)
            x = X0 + (i + 0.5) * cx + jx * (2 * uniform() - 1)
            z = Z0 + (j + 0.5) * cz + jz * (2 * uniform() - 1)
            y = math.sqrt(R2 - x * x - z * z) - GROUND_RADIUS + r   # resting on the ground sphere
            kind, v = kind_of(count)
            m = "l%d" % v if kind == "lambertian" else "m%d" % v if kind == "metal" else "g"
            lines.append(',\n{"center":[%.5f,%.5f,%.5f],"radius":%s,"material":"%s"}' % (x, y, z, rtext, m))
            count += 1
            if len(lines) >= 65536:
                f.write("".join(lines))
                lines = []
        f.write("".join(lines))
        f.write("\n  ]\n}\n")
    if count != n:
        raise RuntimeError("wrote %d spheres, meant %d" % (count, n))
    return count, r


def count_spheres(path):
    """(spheres, kinds): counted by reading the scene file back (json for small
    files, a line count of the sphere records for large ones)."""
    kinds, total = {}, 0
    if os.path.getsize(path) < 50 << 20:
        with open(path) as f:
            scene = json.load(f)
        materials = {m["name"]: m["type"] for m in scene["materials"]}
        for s in scene["spheres"]:
            t = "ground" if s["material"] == "ground" else materials[s["material"]]
            kinds[t] = kinds.get(t, 0) + 1
        return len(scene["spheres"]), kinds
    with open(path) as f:
        for line in f:
            if '"center"' in line:
                total += 1
                m = line.rsplit('"material":', 1)[1].strip().strip('}{,"\n ')
                m = m if m == "ground" else {"l": "lambertian", "m": "metal", "g": "dielectric"}[m[0]]
                kinds[m] = kinds.get(m, 0) + 1
    return total, kinds


# ---------------------------------------------------------------- triangles

def quad_grid(n):
    """(a, b): a x b quads, 2ab = n, a / b nearest WIDTH / DEPTH in log."""
    if n < 2 or n % 2:
        raise ValueError("a triangle count must be even and at least 2 (got %d)" % n)
    half = n // 2
    want = WIDTH / DEPTH
    best = None
    d = 1
    while d * d <= half:
        if half % d == 0:
            for a in (d, half // d):
                b = half // a
                score = abs(math.log((a / b) / want))
                if best is None or score < best[0]:
                    best = (score, a, b)
        d += 1
    return best[1], best[2]


def height_terms():
    """The height field h(x, z) = H0 + sum of A * f(x) * g(z): each term's
    column and row functions."""
    return [(1.2, lambda x: math.sin(0.45 * x + 0.3), lambda z: math.sin(0.5 * z + 1.1)),
            (0.7, lambda x: math.sin(0.23 * x - 0.9), lambda z: math.cos(0.31 * z + 0.4)),
            (0.25, lambda x: math.cos(1.3 * x + 2.0), lambda z: math.sin(1.1 * z - 0.5))]


H0 = 2.15


def bounds(count, parts):
    """The index ranges [lo, hi) of `parts` near-equal runs of `count` cells
    (empty runs dropped)."""
    cuts = sorted(set(round(k * count / parts) for k in range(parts + 1)))
    return list(zip(cuts[:-1], cuts[1:]))


def triangle_materials():
    mats = [meshfile.pbr_material("l%d" % i, c, metallic=0.0, roughness=1.0) for i, c in enumerate(LAMBERTIAN)]
    mats += [meshfile.pbr_material("m%d" % i, c, metallic=1.0, roughness=f) for i, (c, f) in enumerate(METAL)]
    mats.append(meshfile.pbr_material("coated", COATED, metallic=0.0, roughness=0.2))
    return mats


def write_triangles(glb_path, n):
    """Writes the height field of n triangles as one GLB (a primitive per
    material patch); returns (triangles, vertices, a, b)."""
    a, b = quad_grid(n)
    dx, dz = WIDTH / a, DEPTH / b
    xs = [X0 + i * dx for i in range(a + 1)]
    zs = [Z0 + j * dz for j in range(b + 1)]
    terms = height_terms()
    cols = [[amp * fx(x) for x in xs] for amp, fx, _ in terms]
    rows_g = [[gz(z) for z in zs] for _, _, gz in terms]
    mats = triangle_materials()
    index_of = {}
    for i, m in enumerate(mats):
        index_of[m["name"]] = i
    px, pz = round(WIDTH / PATCH), round(DEPTH / PATCH)
    parts = []
    triangles = vertices = 0
    for pj, (j0, j1) in enumerate(bounds(b, pz)):
        for pi, (i0, i1) in enumerate(bounds(a, px)):
            # The patch of the quads' centres: the patch grid is in world space, so
            # with few quads several patches are empty and a quad takes its centre's.
            ci = min(px - 1, int((i0 + i1) / 2 * dx / (WIDTH / px)))
            cj = min(pz - 1, int((j0 + j1) / 2 * dz / (DEPTH / pz)))
            kind, v = kind_of(cj * px + ci)
            name = "l%d" % v if kind == "lambertian" else "m%d" % v if kind == "metal" else "coated"
            w, h = i1 - i0, j1 - j0
            nv = w + 1
            pos = array.array("f", bytes(4 * 3 * nv * (h + 1)))
            xrow = xs[i0:i1 + 1]
            ccols = [c[i0:i1 + 1] for c in cols]
            pos[0::3] = array.array("f", xrow * (h + 1))
            ys, zcol = [], []
            for j in range(j0, j1 + 1):
                g = [rg[j] for rg in rows_g]
                if len(terms) == 3:
                    g0, g1, g2 = g
                    ys += [H0 + c0 * g0 + c1 * g1 + c2 * g2 for c0, c1, c2 in zip(*ccols)]
                else:
                    ys += [H0 + sum(c[i] * gg for c, gg in zip(ccols, g)) for i in range(nv)]
                zcol += [zs[j]] * nv
            pos[1::3] = array.array("f", ys)
            pos[2::3] = array.array("f", zcol)
            del ys, zcol
            # Quad (i, j) of the patch: corners q = j nv + i, q + 1, q + nv, q + nv + 1;
            # (q, q + nv, q + 1) and (q + 1, q + nv, q + nv + 1) face +y.
            ind = array.array("I", bytes(4 * 6 * w * h))
            for j in range(h):
                q = j * nv
                s = 6 * w * j
                e = s + 6 * w
                ind[s + 0:e:6] = array.array("I", range(q, q + w))
                ind[s + 1:e:6] = array.array("I", range(q + nv, q + nv + w))
                ind[s + 2:e:6] = array.array("I", range(q + 1, q + 1 + w))
                ind[s + 3:e:6] = array.array("I", range(q + 1, q + 1 + w))
                ind[s + 4:e:6] = array.array("I", range(q + nv, q + nv + w))
                ind[s + 5:e:6] = array.array("I", range(q + nv + 1, q + nv + 1 + w))
            parts.append(meshfile.Part(pos, None, None, ind, mats[index_of[name]]))
            triangles += 2 * w * h
            vertices += nv * (h + 1)
    written = meshfile.write_glb(glb_path, parts, "height-field")
    if written != n or triangles != n:
        raise RuntimeError("wrote %d triangles, meant %d" % (written, n))
    return triangles, vertices, a, b


def triangle_scene(glb_name):
    return {"camera": CAMERA, "sky": SKY, "render": RENDER,
            "materials": [{"name": "unused", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
            "meshes": [{"name": "field", "file": glb_name}],
            "instances": [{"mesh": "field"}]}


# ---------------------------------------------------------------- command line

def counts(text):
    out = []
    for t in text.split(","):
        t = t.strip()
        if t:
            out.append(int(float(t)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spheres", type=counts, default=DEFAULT_SPHERES,
                    help="sphere counts, comma-separated (default 10,...,1e6; add 1e7 for the largest)")
    ap.add_argument("--triangles", type=counts, default=DEFAULT_TRIANGLES,
                    help="triangle counts, comma-separated (default 10,...,1e7)")
    ap.add_argument("--out", default=DEFAULT_OUT, help="folder to write (default scenes/generated/scaling)")
    ap.add_argument("--check", action="store_true", help="re-read every file written and count what it holds")
    ap.add_argument("--force", action="store_true", help="rewrite files that are already there and current")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    manifest_path = os.path.join(args.out, "manifest.json")
    try:
        with open(manifest_path) as f:
            manifest = json.load(f)
    except (OSError, ValueError):
        manifest = {}
    # A file is current when the manifest says this version of the script wrote it
    # and it still has the size written: re-running scripts/scaling.sh costs nothing.
    with open(os.path.abspath(__file__), "rb") as f:
        version = hashlib.sha1(f.read()).hexdigest()
    files = manifest.get("scenes", {}) if manifest.get("generator_sha1") == version else {}

    def current(key, *paths):
        e = files.get(key)
        return (not args.force and e is not None and
                all(os.path.exists(p) and os.path.getsize(p) == e["bytes"][k] for k, p in enumerate(paths)))

    start_all = time.time()
    for n in args.spheres:
        key = "spheres-" + label(n)
        path = os.path.join(args.out, key + ".json")
        if not current(key, path):
            t = time.time()
            count, r = write_spheres(path, n)
            files[key] = {"series": "spheres", "n": n, "file": os.path.basename(path),
                          "unique_spheres": count + 1, "measured_spheres": count, "ground_spheres": 1,
                          "triangles": 0, "instanced_triangles": 0, "radius": float("%.6g" % r),
                          "grid": list(sphere_grid(n)[:2]), "bytes": [os.path.getsize(path)],
                          "seconds": round(time.time() - t, 2)}
        e = files[key]
        print("%s: %d spheres (+ the ground), radius %.4g, %.1f MB, %.1f s" %
              (os.path.relpath(path), e["measured_spheres"], e["radius"], e["bytes"][0] / 1e6, e["seconds"]))
    for n in args.triangles:
        key = "triangles-" + label(n)
        path = os.path.join(args.out, key + ".json")
        glb = os.path.join(args.out, key + ".glb")
        if not current(key, path, glb):
            t = time.time()
            tris, verts, a, b = write_triangles(glb, n)
            with open(path, "w") as f:
                f.write(scenefile.dumps_scene(triangle_scene(os.path.basename(glb))))
            files[key] = {"series": "triangles", "n": n, "file": os.path.basename(path),
                          "mesh": os.path.basename(glb), "unique_triangles": tris, "instanced_triangles": tris,
                          "instances": 1, "vertices": verts, "quads": [a, b], "spheres": 0,
                          "bytes": [os.path.getsize(path), os.path.getsize(glb)],
                          "seconds": round(time.time() - t, 2)}
        e = files[key]
        print("%s: %d triangles (%d x %d quads, %d vertices), %.1f MB, %.1f s" %
              (os.path.relpath(path), e["unique_triangles"], e["quads"][0], e["quads"][1], e["vertices"],
               sum(e["bytes"]) / 1e6, e["seconds"]))
    manifest = {"generator": "tools/make_scaling_scenes.py", "generator_sha1": version,
                "patch": {"x": [X0, X1], "z": [Z0, Z1]}, "camera": CAMERA,
                "note": "spheres-N: N unique spheres + 1 ground sphere; triangles-N: one mesh of N unique "
                        "triangles placed once (no instancing)",
                "scenes": files}
    tmp = manifest_path + ".tmp.%d" % os.getpid()
    with open(tmp, "w") as f:
        json.dump(manifest, f, indent=1, sort_keys=True)
    os.replace(tmp, manifest_path)
    print("scaling scenes in %s: %.1f s" % (os.path.relpath(args.out), time.time() - start_all))

    if args.check:
        bad = 0
        for key, e in sorted(files.items(), key=lambda kv: (kv[1]["series"], kv[1]["n"])):
            if e["series"] == "spheres" and e["n"] in args.spheres:
                got, kinds = count_spheres(os.path.join(args.out, e["file"]))
                ok = got == e["n"] + 1
            elif e["series"] == "triangles" and e["n"] in args.triangles:
                got, verts = meshfile.check_glb(os.path.join(args.out, e["mesh"]))
                kinds = "%d vertices" % verts
                ok = got == e["n"]
            else:
                continue
            bad += not ok
            print("check %s: %d %s read back%s (%s)" % (key, got, e["series"], "" if ok else " WRONG", kinds))
        if bad:
            sys.exit("make_scaling_scenes: %d files hold other counts than meant" % bad)


if __name__ == "__main__":
    main()
