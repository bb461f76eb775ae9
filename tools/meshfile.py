"""What the mesh-writing scene generators in tools/ share: a pure-Python GLB
writer and checker, a tiny OBJ writer, PLY and Mitsuba serialized writers
(and readers that check them), deterministic noise and procedural shapes
(icosphere, rock, tree).

The generators (make_terrain.py, make_instances.py, make_model_scenes.py)
import this module as a sibling, as they do scenefile.py. Plain python3 only:
no numpy. Bulk data is built in array('f') / array('I') and written with
tobytes(), never one struct.pack per number, so a million triangles take
seconds.

Run directly, it checks GLB, PLY and serialized files, or checks its own
PLY and serialized writers against its readers:

    python3 tools/meshfile.py check scenes/generated/*.glb
    python3 tools/meshfile.py self-test

Conventions of every mesh written here: counter-clockwise winding seen from
the side the surface faces (the geometric normal (b - a) x (c - a) points
out of a closed shape, and up out of a ground), shading normals of unit
length at every vertex, glTF UVs with v = 0 at the image's top row (PLY and
serialized UVs too: Mitsuba 3 reads both unflipped, v = 0 the top row).
"""

import array
import json
import math
import os
import struct
import sys
import zlib

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


def _file_and_complaint(path):
    """A file's bytes, and a function that raises ValueError naming the file."""
    with open(path, "rb") as f:
        data = f.read()

    def bad(msg):
        raise ValueError("%s: %s" % (path, msg))
    return data, bad


def check_glb(path):
    """Re-reads a GLB and checks it: the header and its length, the two chunks,
    every buffer view inside the buffer, every accessor's byte length equal to
    its view's, POSITION min/max equal to the data's, every index inside the
    vertex range, unit normals. Returns (triangles, vertices); raises
    ValueError naming what is wrong."""
    data, bad = _file_and_complaint(path)

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


# ---------------------------------------------------------------- PLY and Mitsuba's serialized

SERIALIZED_FORMAT = 0x041C
SER_NORMALS, SER_UVS, SER_COLOURS, SER_FACE_NORMALS = 0x0001, 0x0002, 0x0008, 0x0010
SER_SINGLE, SER_DOUBLE = 0x1000, 0x2000


def _flat(values, width, typecode, what):
    """VALUES (a flat array / list of numbers, or a sequence of WIDTH-tuples) as
    one flat array of TYPECODE; raises ValueError if its length is not a
    multiple of WIDTH."""
    if isinstance(values, array.array):
        out = values if values.typecode == typecode else array.array(typecode, values)
    else:
        values = list(values)
        if values and isinstance(values[0], (tuple, list)):
            if any(len(v) != width for v in values):
                raise ValueError("%s: every item must have %d numbers" % (what, width))
            out = array.array(typecode, (x for v in values for x in v))
        else:
            out = array.array(typecode, values)
    if len(out) % width:
        raise ValueError("%s: %d numbers, not a multiple of %d" % (what, len(out), width))
    return out


def _mesh_arrays(what, positions, triangles, normals, uvs, typecode="f"):
    """The flat arrays of a mesh to write, checked: normals and UVs one per
    position where given, every index within the positions."""
    p = _flat(positions, 3, typecode, what + ": positions")
    t = _flat(triangles, 3, "I", what + ": triangles")
    n = len(p) // 3
    if t and max(t) >= n:
        raise ValueError("%s: index %d out of range (%d vertices)" % (what, max(t), n))
    nn = None if normals is None else _flat(normals, 3, typecode, what + ": normals")
    uu = None if uvs is None else _flat(uvs, 2, typecode, what + ": uvs")
    if nn is not None and len(nn) != 3 * n:
        raise ValueError("%s: %d normals for %d positions" % (what, len(nn) // 3, n))
    if uu is not None and len(uu) != 2 * n:
        raise ValueError("%s: %d UVs for %d positions" % (what, len(uu) // 2, n))
    return p, t, nn, uu


def write_ply(path, positions, triangles, normals=None, uvs=None, binary=True):
    """A PLY mesh: POSITIONS, TRIANGLES (index triples, 0-based), NORMALS and
    UVS (or None), each a sequence of tuples or a flat array. Binary little
    endian, or ASCII with float32's shortest round-tripping text (%.9g). The
    properties are x y z, nx ny nz, u v (float) and vertex_indices (uchar
    count, uint indices). UVs are written as given: v = 0 the image's top row,
    as Mitsuba 3 reads a PLY's v (no flip) and as glTF has it."""
    p, t, n, u = _mesh_arrays(path, positions, triangles, normals, uvs)
    nv, nt = len(p) // 3, len(t) // 3
    props = ["x", "y", "z"] + (["nx", "ny", "nz"] if n is not None else []) + (["u", "v"] if u is not None else [])
    header = ["ply", "format %s 1.0" % ("binary_little_endian" if binary else "ascii"),
              "comment wavetrace tools/meshfile.py", "element vertex %d" % nv]
    header += ["property float " + name for name in props]
    header += ["element face %d" % nt, "property list uchar uint vertex_indices", "end_header"]
    k = len(props)
    # The vertex records interleaved: property j of vertex i at k * i + j.
    record = array.array("f", bytes(4 * k * nv))
    record[0::k], record[1::k], record[2::k] = p[0::3], p[1::3], p[2::3]
    if n is not None:
        record[3::k], record[4::k], record[5::k] = n[0::3], n[1::3], n[2::3]
    if u is not None:
        record[k - 2::k], record[k - 1::k] = u[0::2], u[1::2]
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode("ascii"))
        if binary:
            f.write(_le_bytes(record))
            # Each face: the count 3 (one byte), then its three indices (12 bytes).
            faces = bytearray(13 * nt)
            faces[0::13] = b"\x03" * nt
            index_bytes = _le_bytes(t)
            for b in range(12):
                faces[1 + b::13] = index_bytes[b::12]
            f.write(bytes(faces))
        else:
            fmt = " ".join(["%.9g"] * k) + "\n"
            f.write("".join(fmt % tuple(record[k * i:k * i + k]) for i in range(nv)).encode("ascii"))
            f.write("".join("3 %d %d %d\n" % tuple(t[3 * i:3 * i + 3]) for i in range(nt)).encode("ascii"))


def write_serialized(path, shapes):
    """A Mitsuba serialized mesh file (version 4): SHAPES a list of dicts
    {name, positions, triangles, normals, uvs, double}, normals and uvs None
    where absent (as write_ply takes them), double True for float64 numbers.
    Each shape is its header (0x041C, 4) and one zlib stream; the file ends
    with the table of the shapes' offsets (u64) and their count (u32). UVs are
    written as given (Mitsuba reads them unflipped: v = 0 the top row)."""
    out, offsets = [], []
    size = 0
    for i, s in enumerate(shapes):
        what = "%s: shape %d" % (path, i)
        code = "d" if s.get("double") else "f"
        p, t, n, u = _mesh_arrays(what, s["positions"], s["triangles"], s.get("normals"), s.get("uvs"), code)
        name = s.get("name", "").encode("utf-8")
        if b"\0" in name:
            raise ValueError("%s: a name may not hold NUL" % what)
        flags = (SER_DOUBLE if code == "d" else SER_SINGLE) | (SER_NORMALS if n is not None else 0) | \
            (SER_UVS if u is not None else 0)
        parts = [struct.pack("<I", flags), name + b"\0", struct.pack("<QQ", len(p) // 3, len(t) // 3), _le_bytes(p)]
        parts += [_le_bytes(a) for a in (n, u) if a is not None] + [_le_bytes(t)]
        blob = struct.pack("<HH", SERIALIZED_FORMAT, 4) + zlib.compress(b"".join(parts))
        offsets.append(size)
        out.append(blob)
        size += len(blob)
    with open(path, "wb") as f:
        for blob in out:
            f.write(blob)
        f.write(struct.pack("<%dQI" % len(offsets), *(offsets + [len(offsets)])))


def _from_le(typecode, data):
    out = array.array(typecode)
    out.frombytes(data)
    if sys.byteorder != "little":
        out.byteswap()
    return out


def read_ply(path):
    """Re-reads a PLY as write_ply writes it (float vertex properties, a face
    list of uchar count and int/uint indices; ASCII or binary little endian).
    Returns {positions, normals, uvs, triangles} as flat arrays (None where
    absent); raises ValueError naming what is wrong, as check_glb does."""
    data, bad = _file_and_complaint(path)

    end = data.find(b"end_header\n")
    if not data.startswith(b"ply\n") or end < 0:
        bad("not a PLY written by write_ply (no 'ply' line or no end_header)")
    lines = data[:end].decode("ascii").splitlines()
    body = data[end + len(b"end_header\n"):]
    fmt, elements = None, []
    for line in lines[1:]:
        w = line.split()
        if w[0] == "format":
            fmt = w[1]
        elif w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w[0] == "property":
            elements[-1][2].append(w[1:])
    if fmt not in ("ascii", "binary_little_endian") or [e[0] for e in elements] != ["vertex", "face"]:
        bad("format %s, elements %r: not what write_ply writes" % (fmt, [e[0] for e in elements]))
    (_, nv, vprops), (_, nt, fprops) = elements
    names = [p[1] for p in vprops]
    if any(p[0] != "float" for p in vprops) or fprops != [["list", "uchar", "uint", "vertex_indices"]] and \
            fprops != [["list", "uchar", "int", "vertex_indices"]]:
        bad("properties not as write_ply writes them")
    k = len(names)
    if fmt == "ascii":
        words = body.split()
        if len(words) != k * nv + 4 * nt:
            bad("%d numbers after the header, expected %d" % (len(words), k * nv + 4 * nt))
        record = array.array("f", (float(x) for x in words[:k * nv]))
        faces = [int(x) for x in words[k * nv:]]
        if any(faces[4 * i] != 3 for i in range(nt)):
            bad("a face that is not a triangle")
        tri = array.array("I", (faces[4 * i + 1 + c] for i in range(nt) for c in range(3)))
    else:
        if len(body) != 4 * k * nv + 13 * nt:
            bad("%d bytes after the header, expected %d" % (len(body), 4 * k * nv + 13 * nt))
        record = _from_le("f", body[:4 * k * nv])
        faces = body[4 * k * nv:]
        if faces[0::13] != b"\x03" * nt:
            bad("a face that is not a triangle")
        index_bytes = bytearray(12 * nt)
        for b in range(12):
            index_bytes[b::12] = faces[1 + b::13]
        tri = _from_le("I", bytes(index_bytes))

    def columns(*cols):
        if not all(c in names for c in cols):
            return None
        out = array.array("f", bytes(4 * len(cols) * nv))
        for j, c in enumerate(cols):
            out[j::len(cols)] = record[names.index(c)::k]
        return out

    mesh = {"positions": columns("x", "y", "z"), "normals": columns("nx", "ny", "nz"), "uvs": columns("u", "v"),
            "triangles": tri}
    if mesh["positions"] is None:
        bad("no x, y, z")
    if tri and max(tri) >= nv:
        bad("an index out of range (%d vertices)" % nv)
    return mesh


def read_serialized(path):
    """Re-reads a Mitsuba serialized file (versions 3 and 4) through its table:
    a list of {name, positions, normals, uvs, triangles, double} (flat arrays,
    None where absent); raises ValueError naming what is wrong: a count that
    disagrees with the inflated size, an index out of range, a bad table."""
    data, bad = _file_and_complaint(path)

    if len(data) < 8:
        bad("too short")
    fmt, version = struct.unpack_from("<HH", data, 0)
    if fmt != SERIALIZED_FORMAT or version not in (3, 4):
        bad("format 0x%04X version %d: not a serialized mesh of version 3 or 4" % (fmt, version))
    count, = struct.unpack_from("<I", data, len(data) - 4)
    entry = 8 if version == 4 else 4
    table = len(data) - 4 - entry * count
    if table < 4:
        bad("a table of %d shapes does not fit" % count)
    offsets = struct.unpack_from("<%d%s" % (count, "Q" if version == 4 else "I"), data, table)
    shapes = []
    for i, start in enumerate(offsets):
        stop = offsets[i + 1] if i + 1 < count else table
        if not start + 4 <= stop <= table or struct.unpack_from("<HH", data, start) != (fmt, version):
            bad("shape %d: offset %d is not a shape's header" % (i, start))
        try:
            raw = zlib.decompress(data[start + 4:stop])
        except zlib.error as e:
            bad("shape %d: %s" % (i, e))
        flags, = struct.unpack_from("<I", raw, 0)
        at, name = 4, ""
        if version == 4:
            nul = raw.index(b"\0", 4)
            name, at = raw[4:nul].decode("utf-8"), nul + 1
        nv, nt = struct.unpack_from("<QQ", raw, at)
        at += 16
        code = "d" if flags & SER_DOUBLE else "f"
        size = 8 if code == "d" else 4
        arrays = {}
        for key, flag, width in (("positions", None, 3), ("normals", SER_NORMALS, 3), ("uvs", SER_UVS, 2),
                                 ("colours", SER_COLOURS, 3)):
            if flag is None or flags & flag:
                arrays[key] = _from_le(code, raw[at:at + size * width * nv])
                at += size * width * nv
            else:
                arrays[key] = None
        if len(raw) != at + 12 * nt:
            bad("shape %d: %d vertices and %d triangles need %d bytes, the stream holds %d"
                % (i, nv, nt, at + 12 * nt, len(raw)))
        tri = _from_le("I", raw[at:])
        if tri and max(tri) >= nv:
            bad("shape %d: an index out of range (%d vertices)" % (i, nv))
        shapes.append({"name": name, "positions": arrays["positions"], "normals": arrays["normals"],
                       "uvs": arrays["uvs"], "triangles": tri, "double": code == "d"})
    return shapes


def _check_unit_normals(path, normals):
    for k in range(0, len(normals or ()), 3 * 97):  # a sample: unit length
        if abs(normals[k] ** 2 + normals[k + 1] ** 2 + normals[k + 2] ** 2 - 1) > 1e-4:
            raise ValueError("%s: normal %d not of unit length" % (path, k // 3))


def check_mesh_file(path):
    """Checks a .glb, .ply or .serialized file (check_glb, read_ply,
    read_serialized; unit normals). Returns (triangles, vertices)."""
    ext = os.path.splitext(path)[1].lower()
    if ext == ".ply":
        meshes = [read_ply(path)]
    elif ext == ".serialized":
        meshes = read_serialized(path)
    else:
        return check_glb(path)
    for m in meshes:
        _check_unit_normals(path, m["normals"])
    return sum(len(m["triangles"]) // 3 for m in meshes), sum(len(m["positions"]) // 3 for m in meshes)


def self_test():
    """Writes PLY (binary and ASCII) and serialized files of known contents into a
    temporary folder and reads them back: every number as written (as float32,
    or float64 for a double shape)."""
    import tempfile
    positions = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0.1)]
    triangles = [(0, 1, 2), (0, 2, 3)]
    normals = [(0, 0, 1)] * 4
    uvs = [(0, 0), (1, 0), (1, 0.75), (0, 0.75)]
    f32 = lambda seq: array.array("f", (x for v in seq for x in v))  # noqa: E731
    with tempfile.TemporaryDirectory() as folder:
        for binary in (True, False):
            path = os.path.join(folder, "quad%d.ply" % binary)
            write_ply(path, positions, triangles, normals, uvs, binary=binary)
            m = read_ply(path)
            assert m["positions"] == f32(positions) and m["normals"] == f32(normals), m
            assert m["uvs"] == f32(uvs) and list(m["triangles"]) == [0, 1, 2, 0, 2, 3], m
            assert check_mesh_file(path) == (2, 4)
            write_ply(path, f32(positions), array.array("I", [0, 1, 2]), binary=binary)
            m = read_ply(path)
            assert m["normals"] is None and m["uvs"] is None and len(m["triangles"]) == 3, m
        path = os.path.join(folder, "two.serialized")
        write_serialized(path, [
            {"name": "quad", "positions": positions, "triangles": triangles, "normals": normals, "uvs": uvs,
             "double": False},
            {"name": "tri", "positions": positions[:3], "triangles": triangles[:1], "normals": None, "uvs": None,
             "double": True}])
        a, b = read_serialized(path)
        assert a["name"] == "quad" and not a["double"] and a["positions"] == f32(positions), a
        assert a["normals"] == f32(normals) and a["uvs"] == f32(uvs) and list(a["triangles"]) == [0, 1, 2, 0, 2, 3]
        assert b["name"] == "tri" and b["double"] and list(b["positions"]) == [x for v in positions[:3] for x in v]
        assert b["normals"] is None and b["uvs"] is None and list(b["triangles"]) == [0, 1, 2], b
        assert check_mesh_file(path) == (3, 7)
        for wrong in ([(0, 1, 4)], [(0, 1)]):
            try:
                write_ply(os.path.join(folder, "wrong.ply"), positions, wrong)
                raise AssertionError("write_ply took triangles %r" % wrong)
            except ValueError:
                pass
    print("meshfile self-test: ok")
    return 0


def _main(argv):
    if argv == ["self-test"]:
        sys.exit(self_test())
    if len(argv) < 2 or argv[0] != "check":
        sys.exit("usage: python3 tools/meshfile.py check FILE.glb|FILE.ply|FILE.serialized...\n"
                 "       python3 tools/meshfile.py self-test")
    failed = False
    for path in argv[1:]:
        try:
            t, v = check_mesh_file(path)
            print("%s: ok, %d triangles, %d vertices" % (path, t, v))
        except (ValueError, KeyError, IndexError, struct.error) as e:
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
