"""What the mesh-writing scene generators in tools/ share: a pure-Python GLB
writer and checker, a tiny OBJ writer, deterministic noise and procedural
shapes (icosphere, rock, tree).

The generators (make_terrain.py, make_instances.py, make_model_scenes.py)
import this module as a sibling, as they do scenefile.py. Plain python3 only:
no numpy. Bulk data is built in array('f') / array('I') and written with
tobytes(), never one struct.pack per number, so a million triangles take
seconds.

Run directly, it checks GLB files:

    python3 tools/meshfile.py check scenes/generated/*.glb

Conventions of every mesh written here: counter-clockwise winding seen from
the side the surface faces (the geometric normal (b - a) x (c - a) points
out of a closed shape, and up out of a ground), shading normals of unit
length at every vertex, glTF UVs with v = 0 at the image's top row.
"""

import array
import json
import math
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

# glTF constants.
FLOAT = 5126
UNSIGNED_INT = 5125
ARRAY_BUFFER = 34962
ELEMENT_ARRAY_BUFFER = 34963
TRIANGLES = 4
GLB_MAGIC = 0x46546C67  # "glTF"
CHUNK_JSON = 0x4E4F534A
CHUNK_BIN = 0x004E4942
COMPONENT_SIZE = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
TYPE_COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def generated_path(name):
    """scenes/generated/NAME, wherever the script runs from; the folder is made."""
    folder = os.path.normpath(os.path.join(HERE, "..", "scenes", "generated"))
    os.makedirs(folder, exist_ok=True)
    return os.path.join(folder, name)


def _le_bytes(arr):
    """The array's bytes in little endian, as glTF wants them."""
    if sys.byteorder != "little":
        arr = array.array(arr.typecode, arr)
        arr.byteswap()
    return arr.tobytes()


class Part:
    """One glTF primitive: positions (array 'f', xyz), normals (array 'f',
    xyz, unit length), uvs (array 'f', uv; or None), indices (array 'I',
    three per triangle) and a material dict (glTF material object)."""

    def __init__(self, positions, normals, uvs, indices, material):
        if array.array("I").itemsize != 4:
            raise RuntimeError("array('I') is not 32 bits on this machine")
        self.positions, self.normals, self.uvs = positions, normals, uvs
        self.indices, self.material = indices, material

    @property
    def vertex_count(self):
        return len(self.positions) // 3

    @property
    def triangle_count(self):
        return len(self.indices) // 3


def pbr_material(name, base_color, metallic=0.0, roughness=1.0, emissive=None):
    """A glTF pbrMetallicRoughness material. The wavetrace loader maps it
    (docs/scene-format.md, "Meshes"): metallic >= 0.5 -> metal, roughness < 0.5
    -> coated, else lambertian; an emissiveFactor not all 0 -> emissive."""
    m = {"name": name,
         "pbrMetallicRoughness": {"baseColorFactor": [base_color[0], base_color[1], base_color[2], 1.0],
                                  "metallicFactor": metallic, "roughnessFactor": roughness}}
    if emissive:
        m["emissiveFactor"] = list(emissive)
    return m


def write_glb(path, parts, mesh_name="mesh"):
    """Writes PARTS (a list of Part) as one binary glTF: one buffer, one mesh
    with a primitive per part, one node, one scene. Returns the triangle count."""
    views, accessors, chunks, materials, primitives = [], [], [], [], []
    offset = 0

    def add(data, target, component, kind, count, extra=None):
        nonlocal offset
        blob = _le_bytes(data)
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob), "target": target})
        chunks.append(blob)
        offset += len(blob)
        pad = (-offset) % 4
        if pad:
            chunks.append(b"\0" * pad)
            offset += pad
        acc = {"bufferView": len(views) - 1, "componentType": component, "count": count, "type": kind}
        if extra:
            acc.update(extra)
        accessors.append(acc)
        return len(accessors) - 1

    for part in parts:
        p = part.positions
        n = part.vertex_count
        xs, ys, zs = p[0::3], p[1::3], p[2::3]
        # min/max as float32 values, as the data holds them.
        bounds = {"min": [min(xs), min(ys), min(zs)], "max": [max(xs), max(ys), max(zs)]}
        attrs = {"POSITION": add(p, ARRAY_BUFFER, FLOAT, "VEC3", n, bounds)}
        if part.normals is not None:
            attrs["NORMAL"] = add(part.normals, ARRAY_BUFFER, FLOAT, "VEC3", n)
        if part.uvs is not None:
            attrs["TEXCOORD_0"] = add(part.uvs, ARRAY_BUFFER, FLOAT, "VEC2", n)
        ind = add(part.indices, ELEMENT_ARRAY_BUFFER, UNSIGNED_INT, "SCALAR", len(part.indices))
        materials.append(part.material)
        primitives.append({"attributes": attrs, "indices": ind, "material": len(materials) - 1,
                           "mode": TRIANGLES})

    gltf = {
        "asset": {"version": "2.0", "generator": "wavetrace tools/meshfile.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": mesh_name}],
        "meshes": [{"name": mesh_name, "primitives": primitives}],
        "materials": materials,
        "buffers": [{"byteLength": offset}],
        "bufferViews": views,
        "accessors": accessors,
    }
    js = json.dumps(gltf, separators=(",", ":")).encode("utf-8")
    js += b" " * ((-len(js)) % 4)
    total = 12 + 8 + len(js) + 8 + offset
    with open(path, "wb") as f:
        f.write(struct.pack("<III", GLB_MAGIC, 2, total))
        f.write(struct.pack("<II", len(js), CHUNK_JSON))
        f.write(js)
        f.write(struct.pack("<II", offset, CHUNK_BIN))
        for c in chunks:
            f.write(c)
    return sum(p.triangle_count for p in parts)


def check_glb(path):
    """Re-reads a GLB and checks it: the header and its length, the two chunks,
    every buffer view inside the buffer, every accessor's byte length equal to
    its view's, POSITION min/max equal to the data's, every index inside the
    vertex range, unit normals. Returns (triangles, vertices); raises
    ValueError naming what is wrong."""
    with open(path, "rb") as f:
        data = f.read()

    def bad(msg):
        raise ValueError("%s: %s" % (path, msg))

    if len(data) < 20:
        bad("too short")
    magic, version, length = struct.unpack_from("<III", data, 0)
    if magic != GLB_MAGIC or version != 2:
        bad("not a glTF 2 binary")
    if length != len(data):
        bad("header length %d, file %d" % (length, len(data)))
    jlen, jtype = struct.unpack_from("<II", data, 12)
    if jtype != CHUNK_JSON or jlen % 4 or 20 + jlen > len(data):
        bad("bad JSON chunk")
    gltf = json.loads(data[20:20 + jlen].decode("utf-8"))
    pos = 20 + jlen
    blen, btype = struct.unpack_from("<II", data, pos)
    if btype != CHUNK_BIN or pos + 8 + blen != len(data):
        bad("bad BIN chunk (or bytes after it)")
    binary = data[pos + 8:pos + 8 + blen]
    if gltf.get("asset", {}).get("version") != "2.0":
        bad("asset.version is not 2.0")
    if len(gltf["buffers"]) != 1 or gltf["buffers"][0]["byteLength"] > blen:
        bad("buffer length")
    for i, v in enumerate(gltf["bufferViews"]):
        if v["byteOffset"] % 4 or v["byteOffset"] + v["byteLength"] > gltf["buffers"][0]["byteLength"]:
            bad("bufferView %d outside the buffer or unaligned" % i)

    def read(acc_index):
        a = gltf["accessors"][acc_index]
        v = gltf["bufferViews"][a["bufferView"]]
        size = COMPONENT_SIZE[a["componentType"]] * TYPE_COMPONENTS[a["type"]] * a["count"]
        if size != v["byteLength"]:
            bad("accessor %d: %d bytes, its view %d" % (acc_index, size, v["byteLength"]))
        code = {FLOAT: "f", UNSIGNED_INT: "I"}[a["componentType"]]
        out = array.array(code)
        out.frombytes(binary[v["byteOffset"]:v["byteOffset"] + size])
        if sys.byteorder != "little":
            out.byteswap()
        return a, out

    triangles = vertices = 0
    for mesh in gltf["meshes"]:
        for prim in mesh["primitives"]:
            if prim.get("mode", TRIANGLES) != TRIANGLES:
                bad("a primitive that is not TRIANGLES")
            a, p = read(prim["attributes"]["POSITION"])
            n = a["count"]
            got = [[min(p[k::3]) for k in range(3)], [max(p[k::3]) for k in range(3)]]
            if got != [a["min"], a["max"]]:
                bad("POSITION min/max %r, data %r" % ([a["min"], a["max"]], got))
            if not all(math.isfinite(x) for x in got[0] + got[1]):
                bad("non-finite position")
            if "NORMAL" in prim["attributes"]:
                an, nn = read(prim["attributes"]["NORMAL"])
                if an["count"] != n:
                    bad("NORMAL count")
                for k in range(0, len(nn), 3 * 97):  # a sample: unit length
                    if abs(nn[k] ** 2 + nn[k + 1] ** 2 + nn[k + 2] ** 2 - 1) > 1e-4:
                        bad("normal %d not of unit length" % (k // 3))
            if "TEXCOORD_0" in prim["attributes"]:
                at, _ = read(prim["attributes"]["TEXCOORD_0"])
                if at["count"] != n:
                    bad("TEXCOORD_0 count")
            ai, ind = read(prim["indices"])
            if ai["count"] % 3 or (ind and max(ind) >= n):
                bad("indices: count not a multiple of 3 or index out of range")
            triangles += ai["count"] // 3
            vertices += n
    return triangles, vertices


def write_obj(path, positions, faces, mtllib=None, groups=None, header=None, uvs=None):
    """A small OBJ: POSITIONS a list of (x, y, z); FACES a list of index
    triples (0-based), or GROUPS a list of (group name, material name or None,
    faces). UVS: None, or a (u, v) per position (OBJ's v: 0 at the image's
    bottom row), which the faces index as they index the positions. Numbers
    are written with %g (at most 6 significant digits)."""
    lines = []
    if header:
        lines += ["# " + h for h in header.splitlines()]
    if mtllib:
        lines.append("mtllib " + mtllib)
    lines += ["v %g %g %g" % tuple(p) for p in positions]
    if uvs is not None:
        if len(uvs) != len(positions):
            raise ValueError("write_obj: %d UVs for %d positions" % (len(uvs), len(positions)))
        lines += ["vt %g %g" % tuple(t) for t in uvs]
    corner = "%d/%d" if uvs is not None else "%d"
    if groups is None:
        groups = [(None, None, faces)]
    for name, material, fs in groups:
        if name:
            lines.append("o " + name)
        if material:
            lines.append("usemtl " + material)
        lines += ["f " + " ".join(corner % ((i + 1,) * corner.count("%")) for i in f) for f in fs]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def write_ground_obj(path):
    """A unit ground quad, x and z in [-1, 1] at y = 0, facing up (+y), no
    material (the loader's white lambertian 'default'; scenes override it)."""
    write_obj(path, [(-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1)], [(0, 1, 2), (0, 2, 3)],
              header="ground quad: x, z in [-1, 1], y = 0, facing +y; tools/meshfile.py")


# ---------------------------------------------------------------- noise

def _hash3(x, y, z, seed):
    """A deterministic integer hash of a lattice point, in [0, 1)."""
    h = (x * 374761393 + y * 668265263 + z * 2147483647 + seed * 1442695041) & 0xFFFFFFFF
    h = ((h ^ (h >> 13)) * 1274126177) & 0xFFFFFFFF
    h ^= h >> 16
    return h / 4294967296.0


def value_noise3(x, y, z, seed=0):
    """Value noise in 3D, in [-1, 1], quintic fade between lattice values."""
    xi, yi, zi = math.floor(x), math.floor(y), math.floor(z)
    fx, fy, fz = x - xi, y - yi, z - zi
    u = fx * fx * fx * (fx * (fx * 6 - 15) + 10)
    v = fy * fy * fy * (fy * (fy * 6 - 15) + 10)
    w = fz * fz * fz * (fz * (fz * 6 - 15) + 10)

    def c(dx, dy, dz):
        return _hash3(xi + dx, yi + dy, zi + dz, seed)

    x00 = c(0, 0, 0) + (c(1, 0, 0) - c(0, 0, 0)) * u
    x10 = c(0, 1, 0) + (c(1, 1, 0) - c(0, 1, 0)) * u
    x01 = c(0, 0, 1) + (c(1, 0, 1) - c(0, 0, 1)) * u
    x11 = c(0, 1, 1) + (c(1, 1, 1) - c(0, 1, 1)) * u
    y0 = x00 + (x10 - x00) * v
    y1 = x01 + (x11 - x01) * v
    return 2 * (y0 + (y1 - y0) * w) - 1


def fbm3(x, y, z, octaves=4, seed=0, lacunarity=2.0, gain=0.5):
    """Fractal sum of value_noise3 octaves, roughly in [-1, 1]."""
    total, amp, freq, norm = 0.0, 1.0, 1.0, 0.0
    for o in range(octaves):
        total += amp * value_noise3(x * freq, y * freq, z * freq, seed + 101 * o)
        norm += amp
        amp *= gain
        freq *= lacunarity
    return total / norm


# ---------------------------------------------------------------- shapes

def icosphere(subdivisions):
    """A unit icosphere: (vertices as a list of [x, y, z], faces as a list of
    index triples), counter-clockwise seen from outside; 20 * 4^s faces."""
    t = (1 + 5 ** 0.5) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
             (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [[c / math.sqrt(x * x + y * y + z * z) for c in (x, y, z)] for x, y, z in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache = {}

        def mid(a, b):
            key = (a, b) if a < b else (b, a)
            if key not in cache:
                p = [(verts[a][k] + verts[b][k]) / 2 for k in range(3)]
                r = math.sqrt(p[0] ** 2 + p[1] ** 2 + p[2] ** 2)
                verts.append([c / r for c in p])
                cache[key] = len(verts) - 1
            return cache[key]

        nf = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = nf
    return verts, faces


def vertex_normals(verts, faces):
    """Smooth normals: the area-weighted face normals summed at each vertex."""
    acc = [[0.0, 0.0, 0.0] for _ in verts]
    for a, b, c in faces:
        pa, pb, pc = verts[a], verts[b], verts[c]
        e1 = (pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2])
        e2 = (pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2])
        n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
        for i in (a, b, c):
            s = acc[i]
            s[0] += n[0]
            s[1] += n[1]
            s[2] += n[2]
    out = []
    for x, y, z in acc:
        r = math.sqrt(x * x + y * y + z * z)
        out.append((x / r, y / r, z / r) if r > 0 else (0.0, 1.0, 0.0))
    return out


def spherical_uvs(verts, center=(0, 0, 0)):
    """Longitude/latitude UVs about CENTER (glTF: v = 0 at the top)."""
    uvs = []
    for x, y, z in verts:
        dx, dy, dz = x - center[0], y - center[1], z - center[2]
        r = math.sqrt(dx * dx + dy * dy + dz * dz) or 1.0
        uvs.append((0.5 + math.atan2(dz, dx) / (2 * math.pi), 0.5 - math.asin(max(-1.0, min(1.0, dy / r))) / math.pi))
    return uvs


def make_part(verts, faces, material, uvs=None):
    """A Part from python lists: smooth normals computed here."""
    normals = vertex_normals(verts, faces)
    p = array.array("f", [c for v in verts for c in v])
    n = array.array("f", [c for v in normals for c in v])
    uv = array.array("f", [c for t in uvs for c in t]) if uvs is not None else None
    ind = array.array("I", [i for f in faces for i in f])
    return Part(p, n, uv, ind, material)


def displaced_sphere(subdivisions, seed, amount, frequency, squash=(1, 1, 1), center=(0, 0, 0), radius=1.0):
    """An icosphere pushed in and out along its normals by fbm noise:
    radius * (1 + amount * fbm(frequency * p)), then scaled by SQUASH and
    moved to CENTER. Returns (verts, faces)."""
    verts, faces = icosphere(subdivisions)
    out = []
    for x, y, z in verts:
        r = radius * (1 + amount * fbm3(frequency * x + 17.3, frequency * y + 5.1, frequency * z + 9.7,
                                        octaves=4, seed=seed))
        out.append([center[0] + squash[0] * r * x, center[1] + squash[1] * r * y, center[2] + squash[2] * r * z])
    return out, faces


def rock_part(subdivisions=4, seed=7, material=None):
    """A procedural rock: a subdivided icosahedron (20 * 4^s triangles), a
    little flattened, with two scales of noise displacement; radius about 1,
    centred at the origin."""
    verts, faces = displaced_sphere(subdivisions, seed, amount=0.35, frequency=1.3, squash=(1.0, 0.75, 0.9))
    # Fine grain on top of the lumps.
    for v in verts:
        g = 1 + 0.04 * value_noise3(6 * v[0], 6 * v[1], 6 * v[2], seed + 9)
        v[0] *= g
        v[1] *= g
        v[2] *= g
    material = material or pbr_material("rock", (0.45, 0.42, 0.38))
    return make_part(verts, faces, material, spherical_uvs(verts))


def tree_parts(seed=3, blob_subdivisions=4, leaves=(0.16, 0.36, 0.10)):
    """A procedural tree, 1 unit = 1 m, base at the origin, about 6 m tall:
    a tapered trunk (a cylinder of 24 sides and 16 rings) and a crown of four
    displaced icospheres (20 * 4^s triangles each), LEAVES its colour.
    Returns [trunk, crown]: materials "bark" and "leaves", both lambertian."""
    sides, rings, height = 24, 16, 3.6
    verts, faces = [], []
    for r in range(rings + 1):
        t = r / rings
        rad = 0.28 * (1 - 0.55 * t) * (1 + 0.25 * (1 - t) ** 6)  # flared foot
        y = height * t
        lean = 0.15 * t * t
        for s in range(sides):
            a = 2 * math.pi * s / sides
            wob = 1 + 0.06 * value_noise3(3 * math.cos(a), 4 * t, 3 * math.sin(a), seed)
            verts.append([lean + rad * wob * math.cos(a), y, rad * wob * math.sin(a)])
    for r in range(rings):
        for s in range(sides):
            a, b = r * sides + s, r * sides + (s + 1) % sides
            c, d = a + sides, b + sides
            # Outward: going round in +angle (x to z) and up, (a, c, b) is counter-clockwise seen from outside.
            faces += [(a, c, b), (b, c, d)]
    uvs = [((i % sides) / sides, 1 - (i // sides) / rings) for i in range(len(verts))]
    trunk = make_part(verts, faces, pbr_material("bark", (0.30, 0.20, 0.12)), uvs)

    cverts, cfaces = [], []
    blobs = [((0.15, 4.3, 0.0), 1.7), ((-0.9, 3.7, 0.5), 1.2), ((0.9, 3.8, -0.4), 1.25), ((0.2, 5.4, 0.2), 1.15)]
    for k, (center, radius) in enumerate(blobs):
        v, f = displaced_sphere(blob_subdivisions, seed + 31 * k, amount=0.3, frequency=1.8,
                                squash=(1, 0.85, 1), center=center, radius=radius)
        base = len(cverts)
        cverts += v
        cfaces += [(a + base, b + base, c + base) for a, b, c in f]
    crown = make_part(cverts, cfaces, pbr_material("leaves", leaves),
                      spherical_uvs(cverts, (0.15, 4.3, 0.0)))
    return [trunk, crown]


def obj_stats(path):
    """An OBJ's bounding box over its `v` lines, and counts:
    ((min x, y, z), (max x, y, z), vertices, triangles), a polygon of k corners
    counting as k - 2 triangles (the loader's fan triangulation)."""
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    vertices = triangles = 0
    with open(path) as f:
        for line in f:
            if line.startswith("v ") or line.startswith("v\t"):
                p = line.split()
                x, y, z = float(p[1]), float(p[2]), float(p[3])
                vertices += 1
                if x < lo[0]: lo[0] = x
                if x > hi[0]: hi[0] = x
                if y < lo[1]: lo[1] = y
                if y > hi[1]: hi[1] = y
                if z < lo[2]: lo[2] = z
                if z > hi[2]: hi[2] = z
            elif line.startswith("f ") or line.startswith("f\t"):
                triangles += max(0, len(line.split()) - 3)
    if not vertices:
        raise ValueError("%s: no vertices" % path)
    return lo, hi, vertices, triangles


def _main(argv):
    if len(argv) < 2 or argv[0] != "check":
        sys.exit("usage: python3 tools/meshfile.py check FILE.glb...")
    failed = False
    for path in argv[1:]:
        try:
            t, v = check_glb(path)
            print("%s: ok, %d triangles, %d vertices" % (path, t, v))
        except (ValueError, KeyError, struct.error) as e:
            print("%s: FAILED: %s" % (path, e))
            failed = True
    sys.exit(1 if failed else 0)


def scene_command(doc, default_name):
    """The command line of a generator that writes a scene and the meshes it names:
    [-o OUTPUT]. Returns (OUTPUT, the folder generated/ beside it, made if absent),
    where the meshes go and where the scene's "generated/..." paths point."""
    import argparse
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("-o", "--output", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                                             "scenes", default_name), help="scene file to write")
    output = ap.parse_args().output
    folder = os.path.join(os.path.dirname(os.path.abspath(output)), "generated")
    os.makedirs(folder, exist_ok=True)
    return output, folder


if __name__ == "__main__":
    _main(sys.argv[1:])


# ---------------------------------------------------------------- transforms

def trs_matrix(translate, rotate_deg, scale):
    """The 4 x 4 matrix, row-major, of the scene format's instance transform:
    translate * rotate * scale, the rotation about x, then y, then z (degrees),
    i.e. R = Rz * Ry * Rx. Returns 16 numbers."""
    ax, ay, az = (math.radians(a) for a in rotate_deg)
    cx, sx, cy, sy, cz, sz = math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay), math.cos(az), math.sin(az)
    rx = [[1, 0, 0], [0, cx, -sx], [0, sx, cx]]
    ry = [[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]]
    rz = [[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]

    def mul(a, b):
        return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]

    r = mul(rz, mul(ry, rx))
    s = scale if isinstance(scale, (list, tuple)) else (scale, scale, scale)
    m = []
    for i in range(3):
        m += [r[i][0] * s[0], r[i][1] * s[1], r[i][2] * s[2], translate[i]]
    return m + [0, 0, 0, 1]
