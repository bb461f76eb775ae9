#!/usr/bin/env python3
"""Mitsuba 3 as a peer in the benchmark: wavetrace's scenes converted to Mitsuba
scene dicts, and rendered with Mitsuba's path tracer, timed as wavetrace's
renders are (one warm-up render, then the median of 3).

    python3 bench/mitsuba_peer.py convert SCENE.json [--width W ...]   # the dict and the notes
    python3 bench/mitsuba_peer.py xml SCENE.json -o SCENE.xml [...]    # the same as Mitsuba XML
    python3 bench/mitsuba_peer.py render SCENE.xml [-D name=value] [--spp N] ...  # a Mitsuba scene as it is
    python3 bench/mitsuba_peer.py regions SCENE.json --width W --height H -o REGIONS.json
            # each placed glTF mesh's pixel boxes, for bench/peer_regions.py
    python3 bench/mitsuba_peer.py render SCENE.json --width W --height H --spp N --depth D
            [--roulette-depth R] [--seed S] [--mode symbolic|evaluated|both]
            [--variant cuda_ad_rgb] [-o OUT_PREFIX] [--json RESULTS.json]

The conversion (everything up to `load_scene`) is plain Python and never imports
Mitsuba: it builds a dict of plain values in which a transform is written
{"__transform__": 4x4 rows}; `load_scene` turns those into Mitsuba transforms,
registers the few Python plugins the dict names and calls mi.load_dict. Mesh
parts and procedural images that Mitsuba has to read from files (split OBJ files,
PLY files from glTF, PFM skies) are written to a cache folder
($WAVETRACE_PEER_CACHE, default $TMPDIR/wavetrace-mitsuba-peer).

What does not map exactly is collected as notes: printed by both commands and
stored with every record of `render`. The mapping and its approximations are
listed in bench/README.md ("Mitsuba 3 peer").
"""

import argparse
import array
import base64
import hashlib
import json
import math
import os
import platform
import re
import struct
import subprocess
import sys
import tempfile
import time

CONVERTER_VERSION = 2

# Every Mitsuba plugin type the converter can emit (scripts/peer-pack.sh keeps
# these, and what they load, in the trimmed package).
EMITTED_PLUGINS = (
    "scene", "path", "perspective", "thinlens", "hdrfilm", "box", "independent",
    "sphere", "obj", "ply", "shapegroup", "instance",
    "diffuse", "twosided", "conductor", "roughconductor", "dielectric", "plastic",
    "roughdielectric", "thindielectric", "roughplastic", "principled", "normalmap", "bumpmap", "blendbsdf",
    "area", "constant", "envmap", "bitmap", "rgb",
    "principledthin", "mask", "point", "spot", "directional", "volpath", "homogeneous", "constvolume",
)
# Python plugins registered by load_scene when a dict names them.
PYTHON_PLUGINS = ("wt_checker", "wt_scale", "wt_roughness", "wt_null", "wt_channel", "wt_normal_scale")

# Metal fuzz -> Beckmann roughness: equal mean-square slope of the half vector
# at normal incidence. wavetrace's fuzzy mirror turns the reflection r into
# normalize(r + fuzz s), s uniform on the unit sphere; for small fuzz the
# deviation angle has E[theta^2] = (2/3) fuzz^2, and the half vector deviates by
# theta / 2, so E[tan^2 theta_h] = fuzz^2 / 6, which is alpha^2 for Beckmann.
# (Measured by sampling: alpha_rms / fuzz = 0.408 at fuzz 0.1, 0.420 at 0.5,
# 0.477 at 1.)
FUZZ_TO_ALPHA = 1.0 / math.sqrt(6.0)

# Below this alpha (both alphas, where anisotropic) wavetrace's microfacet lobes are
# deltas: a mirror, a smooth interface (kSmoothAlpha, include/wavetrace/bsdfs/microfacet.hpp).
SMOOTH_ALPHA = 1e-4

# wavetrace's default Smith masking, "masking": "height-correlated" (include/wavetrace/
# bsdfs/microfacet.hpp), against Mitsuba's separable G1(wo) G1(wi), which is
# "separable". The numbers: a white GGX mirror's directional albedo (alpha =
# roughness^2), over 64 x 64 visible normals.
SMITH_NOTE = ("Smith masking: wavetrace's default height-correlated G2 makes a white GGX mirror reflect as much as "
              "Mitsuba's separable G1(wo) G1(wi) (\"masking\": \"separable\") at normal incidence, but Mitsuba's "
              "less by 0.3%, 2.4%, 9.2% at 60 degrees and 1.8%, 7.6%, 20% at 78 degrees for roughness 0.5, 0.75, 1 "
              "(under 0.1% at 0.25 and below)")
MASKINGS = ("height-correlated", "separable")

# What wavetrace's energy_compensation does (include/wavetrace/bsdfs/conductor.hpp, glass.hpp).
CONDUCTOR_COMPENSATION = "adds a Kulla-Conty multiple-scattering lobe to rough conductors"
GLASS_COMPENSATION = ("divides rough glass by its single-scattering albedo E(mu_o) (Turquin 2019), "
                      "so that it loses nothing")

# A gradient sky becomes a lat-long image of this size (rows sit at
# v = i / (rows - 1), where Mitsuba's envmap puts them; columns are all alike).
GRADIENT_SKY_ROWS = 129
GRADIENT_SKY_COLUMNS = 8
# Angular and mirror-ball environments are resampled to a lat-long image of
# this many rows (and twice as many columns) when the scene is loaded.
RESAMPLED_SKY_ROWS = 512

# wavetrace's wrap modes of an image texture where it names none (u, v).
IMAGE_WRAP = ["repeat", "clamp"]


class ConversionError(Exception):
    pass


# --------------------------------------------------------------------------
# Conductor presets: wavetrace's table (src/scene/conductor_presets.hpp)
# --------------------------------------------------------------------------

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CONDUCTOR_PRESETS_HEADER = os.path.join(ROOT, "src", "scene", "conductor_presets.hpp")
# One entry a line: {"gold", vec3(0.188f, 0.544f, 1.332f), vec3(3.403f, 2.231f, 1.869f)},
_PRESET_LINE = re.compile(r'^\s*\{"(\w+)", vec3\(%s\), vec3\(%s\)\},' % ((", ".join([r"([\d.]+)f"] * 3),) * 2), re.M)


def conductor_presets(path=None):
    """{name: (eta, k)} from the table of conductor_presets.hpp (default:
    CONDUCTOR_PRESETS_HEADER)."""
    path = path or CONDUCTOR_PRESETS_HEADER
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise ConversionError("conductor presets: cannot read %s (%s)" % (path, e.strerror))
    return {m.group(1): (tuple(map(float, m.group(2, 3, 4))), tuple(map(float, m.group(5, 6, 7))))
            for m in _PRESET_LINE.finditer(text)}


# --------------------------------------------------------------------------
# 4x4 matrices as lists of rows (pure Python)
# --------------------------------------------------------------------------

def mat_identity():
    return [[1.0 if r == c else 0.0 for c in range(4)] for r in range(4)]


def mat_mul(a, b):
    return [[sum(a[r][k] * b[k][c] for k in range(4)) for c in range(4)] for r in range(4)]


def mat_translate(t):
    m = mat_identity()
    for i in range(3):
        m[i][3] = float(t[i])
    return m


def mat_scale(s):
    if isinstance(s, (int, float)):
        s = (s, s, s)
    m = mat_identity()
    for i in range(3):
        m[i][i] = float(s[i])
    return m


def mat_rotate(axis, degrees):
    """Right-handed rotation about a coordinate axis ('x', 'y' or 'z'), as glm::rotate."""
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    m = mat_identity()
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    m[i][i], m[i][j], m[j][i], m[j][j] = c, -s, s, c
    return m


def mat_det3(m):
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def mat_inverse_affine(m):
    d = mat_det3(m)
    if d == 0 or not math.isfinite(d):
        raise ConversionError("singular transform")
    inv = [[0.0] * 4 for _ in range(4)]
    for r in range(3):
        for c in range(3):
            r1, r2 = [k for k in range(3) if k != c]
            c1, c2 = [k for k in range(3) if k != r]
            minor = m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1]
            inv[r][c] = (-1) ** (r + c) * minor / d
    for r in range(3):
        inv[r][3] = -sum(inv[r][k] * m[k][3] for k in range(3))
    inv[3][3] = 1.0
    return inv


def mat_point(m, p):
    return [m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3] for r in range(3)]


def is_identity(m):
    return all(abs(m[r][c] - (1.0 if r == c else 0.0)) == 0.0 for r in range(4) for c in range(4))


def transform(m):
    """A transform in the dict, turned into mi.ScalarTransform4f by load_scene."""
    return {"__transform__": [list(map(float, row)) for row in m]}


def instance_matrix(inst):
    """wavetrace's placement: 'matrix' (rows), or translate x Rz x Ry x Rx x scale."""
    if "matrix" in inst:
        v = inst["matrix"]
        return [[float(v[4 * r + c]) for c in range(4)] for r in range(4)]
    m = mat_identity()
    if "translate" in inst:
        m = mat_mul(m, mat_translate(inst["translate"]))
    if "rotate" in inst:
        rx, ry, rz = inst["rotate"]
        m = mat_mul(m, mat_rotate("z", rz))
        m = mat_mul(m, mat_rotate("y", ry))
        m = mat_mul(m, mat_rotate("x", rx))
    if "scale" in inst:
        m = mat_mul(m, mat_scale(inst["scale"]))
    return m


def look_at_matrix(origin, target, up):
    """Camera-to-world as Mitsuba's look_at builds it: columns (left, up, forward, origin)."""
    def sub(a, b):
        return [a[i] - b[i] for i in range(3)]

    def cross(a, b):
        return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]

    def norm(a):
        n = math.sqrt(sum(x * x for x in a))
        return [x / n for x in a]

    d = norm(sub(target, origin))
    left = norm(cross(norm(up), d))
    new_up = cross(d, left)
    return [[left[i], new_up[i], d[i], float(origin[i])] for i in range(3)] + [[0.0, 0.0, 0.0, 1.0]]


# Mitsuba's sphere maps u = atan2(l.y, l.x) / 2 pi, v = acos(l.z) / pi in its own
# frame l; wavetrace's spheres map u = 0.5 + atan2(n.z, n.x) / 2 pi,
# v = acos(n.y) / pi. With l = (-n.x, n.z, n.y) (a rotation: this matrix) Mitsuba's
# v is wavetrace's and Mitsuba's u is 1 - wavetrace's u, which image textures on
# spheres undo with to_uv (SPHERE_TO_UV).
SPHERE_FRAME = [[-1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
SPHERE_TO_UV = [[-1.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]


# --------------------------------------------------------------------------
# Notes
# --------------------------------------------------------------------------

class Notes:
    """The list of 'could not map' notes, each once, with how often it applied."""

    def __init__(self):
        self._counts = {}

    def add(self, text):
        self._counts[text] = self._counts.get(text, 0) + 1

    def list(self):
        return [t if n == 1 else "%s (%d times)" % (t, n) for t, n in self._counts.items()]

    def __contains__(self, fragment):
        return any(fragment in t for t in self._counts)

    def __len__(self):
        return len(self._counts)


# --------------------------------------------------------------------------
# Files the conversion writes (mesh parts, skies)
# --------------------------------------------------------------------------

def cache_dir():
    d = os.environ.get("WAVETRACE_PEER_CACHE") or os.path.join(tempfile.gettempdir(), "wavetrace-mitsuba-peer")
    os.makedirs(d, exist_ok=True)
    return d


def _source_key(path, *extra):
    st = os.stat(path)
    h = hashlib.sha1()
    h.update(repr((os.path.abspath(path), st.st_size, st.st_mtime_ns, CONVERTER_VERSION) + extra).encode())
    return h.hexdigest()[:16]


def _write_atomic(path, data):
    tmp = "%s.%d.tmp" % (path, os.getpid())
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def _le(arr):
    if sys.byteorder != "little":
        arr = array.array(arr.typecode, arr)
        arr.byteswap()
    return arr.tobytes()


def write_pfm(path, width, height, rgb_rows):
    """rgb_rows: `height` rows, top first, each `width` * 3 floats. PFM stores the
    bottom row first."""
    body = array.array("f")
    for row in reversed(rgb_rows):
        body.extend(row)
    _write_atomic(path, b"PF\n%d %d\n-1\n" % (width, height) + _le(body))


def write_ply(path, positions, normals, uvs, indices):
    """Binary PLY: float x y z [nx ny nz] [u v] per vertex, triangles as lists with
    a uint count. positions/normals/uvs/indices: flat arrays ('f', 'f', 'f', 'I')."""
    n = len(positions) // 3
    t = len(indices) // 3
    stride = 3 + (3 if normals is not None else 0) + (2 if uvs is not None else 0)
    verts = array.array("f", bytes(4 * stride * n))
    for k in range(3):
        verts[k::stride] = positions[k::3]
    o = 3
    if normals is not None:
        for k in range(3):
            verts[o + k::stride] = normals[k::3]
        o += 3
    if uvs is not None:
        for k in range(2):
            verts[o + k::stride] = uvs[k::2]
    faces = array.array("I", bytes(16 * t))
    faces[0::4] = array.array("I", [3]) * t
    for k in range(3):
        faces[1 + k::4] = indices[k::3]
    head = ["ply", "format binary_little_endian 1.0", "element vertex %d" % n,
            "property float x", "property float y", "property float z"]
    if normals is not None:
        head += ["property float nx", "property float ny", "property float nz"]
    if uvs is not None:
        head += ["property float u", "property float v"]
    head += ["element face %d" % t, "property list uint uint vertex_indices", "end_header", ""]
    _write_atomic(path, "\n".join(head).encode("ascii") + _le(verts) + _le(faces))


# --------------------------------------------------------------------------
# Mesh files: OBJ (+ MTL) and glTF, read as wavetrace reads them
# --------------------------------------------------------------------------

class MeshPart:
    """Triangles of one material of a mesh file. kind 'obj': `file` can be given
    to Mitsuba's obj plugin; 'ply': written by the converter. `material` is the
    file's material as a wavetrace material dict (named '<mesh>/<name>')."""

    def __init__(self, kind, file, material, has_normals, bounds, area_of=None):
        self.kind, self.file, self.material = kind, file, material
        self.has_normals = has_normals
        self.bounds = bounds          # (lo, hi) in the file's coordinates
        self.area_of = area_of        # function(matrix) -> world area (for emitters)


def _triangle_area(a, b, c):
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    x = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    return 0.5 * math.sqrt(sum(k * k for k in x))


def _area_function(positions, indices):
    """World area of the triangles under a transform (only for emitters: small)."""
    def area(m):
        total = 0.0
        for t in range(0, len(indices), 3):
            pts = [mat_point(m, positions[3 * indices[t + k]:3 * indices[t + k] + 3]) for k in range(3)]
            total += _triangle_area(*pts)
        return total
    return area


def _bounds(positions):
    if not positions:
        return ([0.0] * 3, [0.0] * 3)
    return ([min(positions[k::3]) for k in range(3)], [max(positions[k::3]) for k in range(3)])


def read_mtl(path, mesh_name, materials, notes):
    """Adds the file's materials, mapped to wavetrace kinds (docs/scene-format.md)."""
    folder = os.path.dirname(path)
    cur = None
    raw = {}
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            tok = line.split("#", 1)[0].split()
            if not tok:
                continue
            if tok[0] == "newmtl":
                cur = " ".join(tok[1:])
                raw[cur] = {}
            elif cur is not None and tok[0] in ("Kd", "Ks", "Ke"):
                raw[cur][tok[0]] = [float(x) for x in tok[1:4]]
            elif cur is not None and tok[0] in ("Ns", "Ni", "d"):
                raw[cur][tok[0]] = float(tok[1])
            elif cur is not None and tok[0] == "map_Kd":
                raw[cur]["map_Kd"] = os.path.join(folder, tok[-1])
    for name, r in raw.items():
        kd, ks, ke = r.get("Kd", [0, 0, 0]), r.get("Ks", [0, 0, 0]), r.get("Ke", [0, 0, 0])
        ni = r.get("Ni", 1.0)
        ior = ni if ni > 1.0 else 1.5
        full = "%s/%s" % (mesh_name, name)
        if any(ke):
            m = {"type": "emissive", "emission": ke}
        elif r.get("d", 1.0) < 1.0:
            m = {"type": "dielectric", "ior": ior}
        elif any(ks) and not any(kd):
            m = {"type": "metal", "albedo": ks, "fuzz": min(1.0, math.sqrt(2.0 / (r.get("Ns", 0.0) + 2.0)))}
        elif any(ks):
            m = {"type": "coated", "albedo": kd, "ior": ior}
        else:
            m = {"type": "lambertian", "albedo": kd}
        if "map_Kd" in r and m["type"] in ("lambertian", "metal", "coated"):
            m["__image__"] = {"file": r["map_Kd"], "colorspace": "srgb"}
        m["name"] = full
        materials[name] = m


def read_obj(path, mesh_name, notes):
    """Returns the mesh's parts, one per material. A file of one material is
    handed to Mitsuba as it is; otherwise each material's faces go to an OBJ
    file of their own in the cache folder."""
    folder = os.path.dirname(path)
    v, vt, vn = [], [], []
    groups = {}       # material -> list of faces (lists of (vi, ti, ni), 0-based, -1: none)
    order = []
    materials = {}
    current = None
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            tok = line.split("#", 1)[0].split()
            if not tok:
                continue
            key = tok[0]
            if key == "v":
                v.append(tok[1:4])
            elif key == "vt":
                vt.append(tok[1:3])
            elif key == "vn":
                vn.append(tok[1:4])
            elif key == "f":
                face = []
                for c in tok[1:]:
                    parts = c.split("/")
                    idx = []
                    for i, count in zip(range(3), (len(v), len(vt), len(vn))):
                        if i < len(parts) and parts[i]:
                            k = int(parts[i])
                            idx.append(k - 1 if k > 0 else count + k)
                        else:
                            idx.append(-1)
                    face.append(tuple(idx))
                if current not in groups:
                    groups[current] = []
                    order.append(current)
                groups[current].append(face)
            elif key == "usemtl":
                current = " ".join(tok[1:])
            elif key == "mtllib":
                mtl = os.path.join(folder, " ".join(tok[1:]))
                if not os.path.exists(mtl):
                    raise ConversionError("%s: MTL file %s not found" % (path, mtl))
                read_mtl(mtl, mesh_name, materials, notes)
    if not groups:
        raise ConversionError("%s: no faces" % path)
    positions_all = [float(x) for p in v for x in p]
    every_normal = all(all(i[2] >= 0 for i in face) for faces in groups.values() for face in faces)
    parts = []
    single = len(order) == 1
    for name in order:
        faces = groups[name]
        if name is None:
            material = {"type": "lambertian", "albedo": [1, 1, 1], "name": "%s/default" % mesh_name}
        elif name in materials:
            material = materials[name]
        else:
            raise ConversionError("%s: usemtl %s names no material of its MTL file" % (path, name))
        used = sorted({i[0] for face in faces for i in face})
        pos = [float(x) for i in used for x in v[i]]
        tris = []
        remap = {o: k for k, o in enumerate(used)}
        for face in faces:
            for k in range(1, len(face) - 1):
                tris += [remap[face[0][0]], remap[face[k][0]], remap[face[k + 1][0]]]
        area_of = _area_function(pos, tris) if material["type"] == "emissive" else None
        if single:
            parts.append(MeshPart("obj", path, material, every_normal, _bounds(positions_all), area_of))
            continue
        out = os.path.join(cache_dir(), "%s-%s.obj" % (os.path.splitext(os.path.basename(path))[0],
                                                       _source_key(path, name)))
        if not os.path.exists(out):
            vmap, tmap, nmap = {}, {}, {}
            lines = ["# %s, material %s: written by bench/mitsuba_peer.py" % (os.path.basename(path), name)]
            body = []
            for face in faces:
                refs = []
                for (a, b, c) in face:
                    if a not in vmap:
                        vmap[a] = len(vmap) + 1
                        lines.append("v " + " ".join(v[a]))
                    r = str(vmap[a])
                    if b >= 0:
                        if b not in tmap:
                            tmap[b] = len(tmap) + 1
                            lines.append("vt " + " ".join(vt[b]))
                        r += "/" + str(tmap[b])
                    if c >= 0 and every_normal:
                        if c not in nmap:
                            nmap[c] = len(nmap) + 1
                            lines.append("vn " + " ".join(vn[c]))
                        r += ("/" if b >= 0 else "//") + str(nmap[c])
                    refs.append(r)
                body.append("f " + " ".join(refs))
            _write_atomic(out, ("\n".join(lines + body) + "\n").encode())
        parts.append(MeshPart("obj", out, material, every_normal, _bounds(pos), area_of))
    return parts


GLTF_COMPONENTS = {5120: ("b", 1), 5121: ("B", 1), 5122: ("h", 2), 5123: ("H", 2), 5125: ("I", 4), 5126: ("f", 4)}
GLTF_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def _gltf_load(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"glTF":
        _, _, length = struct.unpack_from("<III", data, 0)
        jlen, _ = struct.unpack_from("<II", data, 12)
        doc = json.loads(data[20:20 + jlen].decode("utf-8"))
        pos = 20 + jlen
        glb_bin = None
        if pos + 8 <= len(data):
            blen, _ = struct.unpack_from("<II", data, pos)
            glb_bin = data[pos + 8:pos + 8 + blen]
    else:
        doc = json.loads(data.decode("utf-8"))
        glb_bin = None
    buffers = []
    for i, b in enumerate(doc.get("buffers", [])):
        uri = b.get("uri")
        if uri is None:
            buffers.append(glb_bin)
        elif uri.startswith("data:"):
            buffers.append(base64.b64decode(uri.split(",", 1)[1]))
        else:
            with open(os.path.join(os.path.dirname(path), uri), "rb") as f:
                buffers.append(f.read())
    return doc, buffers


def _gltf_accessor(doc, buffers, index):
    a = doc["accessors"][index]
    code, size = GLTF_COMPONENTS[a["componentType"]]
    width = GLTF_WIDTH[a["type"]]
    count = a["count"]
    out = array.array(code)
    if "bufferView" not in a:
        return array.array("f", bytes(4 * width * count)) if code == "f" else array.array(code, [0] * (width * count))
    view = doc["bufferViews"][a["bufferView"]]
    buf = buffers[view["buffer"]]
    start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
    stride = view.get("byteStride", 0) or width * size
    if stride == width * size:
        out.frombytes(buf[start:start + count * stride])
    else:
        for k in range(count):
            out.frombytes(buf[start + k * stride:start + k * stride + width * size])
    if sys.byteorder != "little":
        out.byteswap()
    if a.get("normalized") and code != "f":
        scale = {"b": 127.0, "B": 255.0, "h": 32767.0, "H": 65535.0}[code]
        out = array.array("f", [max(x / scale, -1.0) for x in out])
    return out


def _quat_matrix(q):
    x, y, z, w = q
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), 0],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), 0],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), 0],
            [0, 0, 0, 1]]


def _node_matrix(node):
    if "matrix" in node:
        v = node["matrix"]  # column-major
        return [[float(v[4 * c + r]) for c in range(4)] for r in range(4)]
    m = mat_identity()
    if "translation" in node:
        m = mat_mul(m, mat_translate(node["translation"]))
    if "rotation" in node:
        m = mat_mul(m, _quat_matrix(node["rotation"]))
    if "scale" in node:
        m = mat_mul(m, mat_scale(node["scale"]))
    return m


# glTF sampler codes (wrapS / wrapT, magFilter / minFilter) as wavetrace reads them.
GLTF_WRAP = {10497: "repeat", 33071: "clamp", 33648: "mirror"}
GLTF_NEAREST = 9728
GLTF_LINEAR = 9729

# Embedded images by MIME type: the file extension Mitsuba's bitmap reader needs.
IMAGE_EXTENSIONS = {"image/png": ".png", "image/jpeg": ".jpg", "image/bmp": ".bmp", "image/gif": ".gif"}


class MeshParts(list):
    """A mesh file's parts, and its KHR_lights_punctual lights (dicts: kind,
    matrix (the node's, in the file's coordinates), intensity, range, cone
    angles)."""

    def __init__(self, parts=(), lights=()):
        super().__init__(parts)
        self.lights = list(lights)


def _uri_decode(uri):
    return re.sub(r"%([0-9a-fA-F]{2})", lambda m: chr(int(m.group(1), 16)), uri)


def _sniff_extension(data):
    if data[:8] == b"\x89PNG\r\n\x1a\n":
        return ".png"
    if data[:3] == b"\xff\xd8\xff":
        return ".jpg"
    if data[:2] == b"BM":
        return ".bmp"
    return None


def gltf_image_file(doc, buffers, path, index):
    """The file of glTF image INDEX: beside the mesh file (a uri), or its bytes (a
    GLB buffer view, a data URI) written once to the cache folder, named by
    their hash (Mitsuba's bitmap reads files only)."""
    image = doc["images"][index]
    uri = image.get("uri")
    if uri is not None and not uri.startswith("data:"):
        return os.path.normpath(os.path.join(os.path.dirname(path), _uri_decode(uri)))
    if uri is not None:
        head, _, body = uri.partition(",")
        mime = head[5:].split(";")[0]
        data = base64.b64decode(body) if ";base64" in head else _uri_decode(body).encode("latin-1")
    elif "bufferView" in image:
        view = doc["bufferViews"][image["bufferView"]]
        start = view.get("byteOffset", 0)
        data = bytes(buffers[view["buffer"]][start:start + view["byteLength"]])
        mime = image.get("mimeType", "")
    else:
        raise ConversionError("%s: image %d has neither a uri nor a buffer view" % (path, index))
    if not data:
        raise ConversionError("%s: image %d is empty" % (path, index))
    ext = IMAGE_EXTENSIONS.get(mime) or _sniff_extension(data)
    if ext is None:
        raise ConversionError("%s: image %d: type '%s' is not one Mitsuba's bitmap reads" % (path, index, mime))
    out = os.path.join(cache_dir(), "embedded-%s%s" % (hashlib.sha1(data).hexdigest()[:20], ext))
    if not os.path.exists(out):
        _write_atomic(out, data)
    return out


def _gltf_texture(doc, buffers, path, info, colorspace, name):
    """A material's textureInfo as an inline wavetrace image texture (what the
    scene file's `textures` hold), with the glTF sampler's wrap and filters and
    KHR_texture_transform's uv_offset / uv_scale / uv_rotation; and the
    TEXCOORD set it reads."""
    tex = doc["textures"][info["index"]]
    if "source" not in tex:
        raise ConversionError("%s: %s: the texture has no source image (only an extension's)" % (path, name))
    t = {"name": name, "type": "image", "file": gltf_image_file(doc, buffers, path, tex["source"]),
         "colorspace": colorspace, "wrap": ["repeat", "repeat"], "filter": "trilinear", "magnify": "bilinear"}
    if "sampler" in tex:
        s = doc["samplers"][tex["sampler"]]
        t["wrap"] = [GLTF_WRAP.get(s.get("wrapS", 10497), "repeat"), GLTF_WRAP.get(s.get("wrapT", 10497), "repeat")]
        t["magnify"] = "nearest" if s.get("magFilter") == GLTF_NEAREST else "bilinear"
        t["filter"] = {GLTF_NEAREST: "nearest", GLTF_LINEAR: "bilinear"}.get(s.get("minFilter"), "trilinear")
    uv_set = info.get("texCoord", 0)
    x = info.get("extensions", {}).get("KHR_texture_transform")
    if x is not None:
        t["uv_offset"] = list(x.get("offset", [0, 0]))
        t["uv_scale"] = list(x.get("scale", [1, 1]))
        t["uv_rotation"] = float(x.get("rotation", 0.0))
        uv_set = x.get("texCoord", uv_set)
    return t, uv_set


def _gltf_material(doc, buffers, index, mesh_name, path, notes):
    """glTF material INDEX as wavetrace maps it (src/scene/mesh_load.cpp, map_gltf):
    a `principled` material dict of the scene file's keys, its textures inline;
    an `emissive` one where the material emits and nothing else reflects. Also
    the TEXCOORD set its textures read (the first texture's, as wavetrace's)."""
    if index is None:
        # The specification's default material: every property at its default.
        g = {"name": "default"}
    else:
        g = doc["materials"][index]
    name = "%s/%s" % (mesh_name, g.get("name", "material %d" % index))
    pbr = g.get("pbrMetallicRoughness", {})
    ext = g.get("extensions", {})
    factor = list(pbr.get("baseColorFactor", [1, 1, 1, 1]))
    base = factor[:3]
    strength = ext.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
    emission = [float(e) * float(strength) for e in g.get("emissiveFactor", [0, 0, 0])]
    transmission = float(ext.get("KHR_materials_transmission", {}).get("transmissionFactor", 0.0))
    coat = ext.get("KHR_materials_clearcoat", {})
    clearcoat = float(coat.get("clearcoatFactor", 0.0))
    sets = []

    def texture(info, colorspace, slot):
        t, s = _gltf_texture(doc, buffers, path, info, colorspace, "%s %s" % (name, slot))
        sets.append(s)
        return t

    alpha_mode = g.get("alphaMode", "OPAQUE")
    alpha = None
    if alpha_mode in ("MASK", "BLEND"):
        textured = "baseColorTexture" in pbr
        cutoff = float(g.get("alphaCutoff", 0.5)) if alpha_mode == "MASK" else None
        a = float(factor[3])
        if textured or (a < cutoff if cutoff is not None else a < 1.0):
            alpha = {"mode": alpha_mode.lower(), "factor": a, "cutoff": cutoff}
    reflects = any(base) or "baseColorTexture" in pbr or transmission != 0 or clearcoat != 0
    if any(emission) and not reflects:
        # An emitter alone (its 4% specular layer left out, as wavetrace does).
        m = {"type": "emissive", "emission": emission, "name": name}
        if "emissiveTexture" in g:
            m["emission_texture"] = texture(g["emissiveTexture"], "srgb", "emissive texture")
    else:
        ior = float(ext.get("KHR_materials_ior", {}).get("ior", 1.5))
        m = {"type": "principled", "name": name, "albedo": base,
             "metallic": float(pbr.get("metallicFactor", 1.0)), "roughness": float(pbr.get("roughnessFactor", 1.0)),
             "ior": 1e4 if ior == 0 else ior,     # ior 0: f0 = 1, wavetrace's stand-in index
             "specular": float(ext.get("KHR_materials_specular", {}).get("specularFactor", 1.0)),
             "double_sided": bool(g.get("doubleSided", False))}
        spec = ext.get("KHR_materials_specular", {})
        for field in ("specularTexture", "specularColorFactor", "specularColorTexture"):
            if field in spec:
                notes.add("material '%s': KHR_materials_specular %s is not read (by wavetrace either)" % (name, field))
        if any(emission):
            m["emission"] = emission
            if "emissiveTexture" in g:
                m["emission_texture"] = texture(g["emissiveTexture"], "srgb", "emissive texture")
        if clearcoat:
            m["clearcoat"] = clearcoat
            m["clearcoat_roughness"] = float(coat.get("clearcoatRoughnessFactor", 0.0))
            for field, key in (("clearcoatTexture", "clearcoat_texture"),
                               ("clearcoatRoughnessTexture", "clearcoat_roughness_texture"),
                               ("clearcoatNormalTexture", "clearcoat_normal_texture")):
                if field in coat:
                    m[key] = texture(coat[field], "linear", field)
        if transmission:
            m["transmission"] = transmission
            tt = ext.get("KHR_materials_transmission", {}).get("transmissionTexture")
            if tt is not None:
                m["transmission_texture"] = texture(tt, "linear", "transmission texture")
        volume = ext.get("KHR_materials_volume", {})
        if float(volume.get("thicknessFactor", 0.0)) > 0:
            m["thin"] = False
            if "attenuationDistance" in volume:
                m["attenuation_distance"] = float(volume["attenuationDistance"])
                m["attenuation_color"] = list(volume.get("attenuationColor", [1, 1, 1]))
        if "baseColorTexture" in pbr:
            m["texture"] = texture(pbr["baseColorTexture"], "srgb", "base colour texture")
        if "metallicRoughnessTexture" in pbr:
            t = texture(pbr["metallicRoughnessTexture"], "linear", "metallic-roughness texture")
            m["roughness_texture"] = m["metallic_texture"] = t
        if "normalTexture" in g:
            m["normal_texture"] = texture(g["normalTexture"], "linear", "normal texture")
            m["normal_strength"] = float(g["normalTexture"].get("scale", 1.0))
        if "occlusionTexture" in g:
            notes.add("glTF occlusionTexture: read and not applied, by wavetrace and the peer alike (paths find the "
                      "occlusion)")
    if alpha is not None:
        if "baseColorTexture" in pbr:
            alpha["texture"] = texture(pbr["baseColorTexture"], "linear", "base colour texture's alpha")
        m["__alpha__"] = alpha
    return m, (sets[0] if sets else 0)


def _spot_cones(light):
    spot = light.get("spot", {})
    return float(spot.get("innerConeAngle", 0.0)), float(spot.get("outerConeAngle", math.pi / 4))


def read_gltf(path, mesh_name, notes):
    """glTF / GLB: Mitsuba 3 reads neither, so each primitive (with the node
    transforms applied, as wavetrace applies them) is written to a binary PLY.
    The nodes' KHR_lights_punctual lights come back with the parts."""
    notes.add("glTF/GLB meshes: Mitsuba 3 has no glTF loader; each primitive was written to a PLY file "
              "(node transforms applied, as wavetrace does)")
    doc, buffers = _gltf_load(path)
    scenes = doc.get("scenes")
    if scenes:
        roots = scenes[doc.get("scene", 0)].get("nodes", [])
        todo = [(r, mat_identity()) for r in roots]
    else:
        todo = None
    placed = []   # (mesh index, matrix)
    lights = []
    if todo is None:
        placed = [(i, mat_identity()) for i in range(len(doc.get("meshes", [])))]
    else:
        while todo:
            # Depth first in the file's order, as wavetrace walks the nodes.
            i, parent = todo.pop(0)
            node = doc["nodes"][i]
            m = mat_mul(parent, _node_matrix(node))
            if "mesh" in node:
                placed.append((node["mesh"], m))
            punctual = node.get("extensions", {}).get("KHR_lights_punctual")
            if punctual is not None:
                g = doc["extensions"]["KHR_lights_punctual"]["lights"][punctual["light"]]
                colour = g.get("color", [1, 1, 1])
                light = {"kind": g["type"], "matrix": m, "name": g.get("name", ""),
                         "intensity": [float(c) * float(g.get("intensity", 1.0)) for c in colour],
                         "range": float(g.get("range", 0.0)) if g["type"] != "directional" else 0.0}
                if g["type"] == "spot":
                    light["inner"], light["outer"] = _spot_cones(g)
                elif g["type"] not in ("point", "directional"):
                    raise ConversionError("%s: light type '%s' is not point, spot or directional" % (path, g["type"]))
                lights.append(light)
            todo = [(c, m) for c in node.get("children", [])] + todo
    materials = {}
    prims = [(mi_, m, p) for mi_, m in placed for p in doc["meshes"][mi_]["primitives"]]
    every_normal = all("NORMAL" in p["attributes"] for _, _, p in prims)
    parts = MeshParts(lights=lights)
    for k, (mesh_index, m, prim) in enumerate(prims):
        if prim.get("mode", 4) != 4:
            raise ConversionError("%s: a primitive that is not TRIANGLES" % path)
        key = prim.get("material")
        if key not in materials:
            materials[key] = _gltf_material(doc, buffers, key, mesh_name, path, notes)
        material, uv_set = materials[key]
        uv_name = "TEXCOORD_%d" % uv_set
        out = os.path.join(cache_dir(), "%s-%s.ply" % (os.path.splitext(os.path.basename(path))[0],
                                                       _source_key(path, k, uv_set)))
        pos = _gltf_accessor(doc, buffers, prim["attributes"]["POSITION"])
        if "indices" in prim:
            ind = array.array("I", _gltf_accessor(doc, buffers, prim["indices"]))
        else:
            ind = array.array("I", range(len(pos) // 3))
        if not is_identity(m):
            p2 = array.array("f", bytes(len(pos) * 4))
            for i in range(0, len(pos), 3):
                p2[i:i + 3] = array.array("f", mat_point(m, pos[i:i + 3]))
            pos = p2
        emits = material["type"] == "emissive" or any(material.get("emission", [0]))
        area_of = _area_function(pos, ind) if emits else None
        if not os.path.exists(out):
            nrm = uv = None
            if every_normal:
                nrm = _gltf_accessor(doc, buffers, prim["attributes"]["NORMAL"])
                if not is_identity(m):
                    nm = mat_inverse_affine(m)   # normals: the inverse transpose
                    n2 = array.array("f", bytes(len(nrm) * 4))
                    for i in range(0, len(nrm), 3):
                        x, y, z = nrm[i:i + 3]
                        w = [nm[0][r] * x + nm[1][r] * y + nm[2][r] * z for r in range(3)]
                        ln = math.sqrt(sum(c * c for c in w)) or 1.0
                        n2[i:i + 3] = array.array("f", [c / ln for c in w])
                    nrm = n2
            if uv_name in prim["attributes"]:
                # glTF's v = 0 is the image's top row, where Mitsuba's bitmap and
                # wavetrace's mesh UVs have v = 0 as well: written as it is. (OBJ
                # files go to Mitsuba as they are; its reader and wavetrace's both
                # read OBJ's v as 1 - v.) The set is the one the material's
                # textures read: a PLY holds one.
                uv = _gltf_accessor(doc, buffers, prim["attributes"][uv_name])
            write_ply(out, pos, nrm, uv, ind)
        parts.append(MeshPart("ply", out, material, every_normal, _bounds(pos), area_of))
    if not parts:
        raise ConversionError("%s: no triangles" % path)
    return parts


def read_mesh(path, mesh_name, notes):
    ext = os.path.splitext(path)[1].lower()
    if not os.path.exists(path):
        raise ConversionError("mesh file %s not found" % path)
    if ext == ".obj":
        return read_obj(path, mesh_name, notes)
    if ext in (".gltf", ".glb"):
        return read_gltf(path, mesh_name, notes)
    raise ConversionError("%s: unknown mesh extension" % path)


# --------------------------------------------------------------------------
# The scene
# --------------------------------------------------------------------------

def _rgb(c):
    return {"type": "rgb", "value": [float(x) for x in c]}


def fresnel_dielectric(cos_i, eta):
    """Unpolarized reflectance at incidence cosine cos_i of an interface of
    relative index eta (transmitted over incident)."""
    sin2_t = (1.0 - cos_i * cos_i) / (eta * eta)
    if sin2_t >= 1.0:
        return 1.0
    cos_t = math.sqrt(1.0 - sin2_t)
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs * rs + rp * rp)


def diffuse_fresnel(eta, steps=4096):
    """2 int_0^1 F(mu, eta) mu dmu: the reflectance for diffuse light (wavetrace's
    plastic_internal_reflectance of a smooth coat, eta = 1 / ior)."""
    return 2.0 * sum(fresnel_dielectric((i + 0.5) / steps, eta) * (i + 0.5) / steps for i in range(steps)) / steps


def mitsuba_diffuse_fresnel(eta):
    """Mitsuba 3's fresnel_diffuse_reflectance (include/mitsuba/render/fresnel.h):
    Egan and Hilgeman's fit for eta < 1, d'Eon and Irving's otherwise."""
    inv = 1.0 / eta
    if eta < 1.0:
        return 0.0636 * inv + eta * (eta * -1.4399 + 0.7099) + 0.6681
    return sum(c * inv ** i for i, c in enumerate((0.919317, -3.4793, 6.75335, -7.80989, 4.98554, -1.36881)))


def _is_white(c):
    return all(float(x) == 1.0 for x in c)


def _mean3(c):
    return (float(c[0]) + float(c[1]) + float(c[2])) / 3.0


class Converter:
    """Builds the Mitsuba dict of one wavetrace scene file."""

    def __init__(self, scene_path, width=None, height=None, spp=None, depth=None, roulette_depth=None,
                 seed=None, nee=None, instancing=False, sky_sampling="auto", python_plugins=True, doc=None):
        self.path = scene_path
        self.folder = os.path.dirname(os.path.abspath(scene_path))
        if doc is None:
            with open(scene_path, encoding="utf-8") as f:
                doc = json.load(f)
        self.doc = doc
        r = doc.get("render", {})

        def pick(value, key, default):
            return value if value is not None else r.get(key, default)

        self.width = int(pick(width, "width", 640))
        self.height = int(pick(height, "height", 360))
        self.spp = int(pick(spp, "spp", 16))        # wavetrace's defaults (RenderDefaults)
        self.depth = int(pick(depth, "depth", 10))
        self.roulette_depth = int(pick(roulette_depth, "roulette_depth", 5))
        self.seed = int(pick(seed, "seed", 1))
        self.nee = int(pick(nee, "nee", 1))
        self.instancing = instancing
        self.allow_python = python_plugins
        if sky_sampling not in ("auto", "always"):
            raise ConversionError("sky_sampling must be auto or always")
        self.sky_sampling = sky_sampling
        self.notes = Notes()
        self.out = {"type": "scene"}
        self.textures = {t["name"]: t for t in doc.get("textures", [])}
        self.materials = {m["name"]: m for m in doc.get("materials", [])}
        self.python_plugins = set()
        self.emitters = []      # (dict, wavetrace samples it, power)
        self.bounds = None      # scene bounding box (lo, hi)
        self.punctuals = []     # (dict, power or None for directional, mean intensity)
        self.needs_volpath = False
        self._bsdf_ids = {}
        self._counter = 0

    # -- helpers ---------------------------------------------------------
    def file(self, rel):
        return os.path.normpath(os.path.join(self.folder, rel))

    def _name(self, prefix):
        self._counter += 1
        return "%s_%05d" % (prefix, self._counter)

    def _grow(self, lo, hi):
        if self.bounds is None:
            self.bounds = (list(lo), list(hi))
        else:
            self.bounds = ([min(a, b) for a, b in zip(self.bounds[0], lo)],
                           [max(a, b) for a, b in zip(self.bounds[1], hi)])

    # -- camera, film, sampler, integrator -----------------------------------
    def camera(self):
        cam = self.doc["camera"]
        look_from = [float(x) for x in cam["look_from"]]
        look_at = [float(x) for x in cam["look_at"]]
        up = [float(x) for x in cam.get("up", [0, 1, 0])]
        vfov = float(cam.get("vfov", 40))
        aperture = float(cam.get("aperture", 0))
        focus = cam.get("focus_distance")
        if focus is None or float(focus) <= 0:
            focus = math.sqrt(sum((a - b) ** 2 for a, b in zip(look_from, look_at)))
        sensor = {
            "type": "perspective",
            "fov": vfov,
            "fov_axis": "y",
            "near_clip": 1e-4 * float(focus),
            "far_clip": 1e7,
            "to_world": transform(look_at_matrix(look_from, look_at, up)),
            "film": {
                "type": "hdrfilm",
                "width": self.width,
                "height": self.height,
                "pixel_format": "rgb",
                "component_format": "float32",
                "rfilter": {"type": "box"},
            },
            "sampler": {"type": "independent", "sample_count": self.spp, "seed": self.seed},
        }
        if aperture > 0:
            sensor["type"] = "thinlens"
            sensor["aperture_radius"] = 0.5 * aperture
            sensor["focus_distance"] = float(focus)
        return sensor

    def integrator(self):
        # Both count the camera ray: wavetrace traces at most `depth` rays a path,
        # Mitsuba's max_depth is "the longest path depth" (1: only directly visible
        # emitters, 2: direct lighting). Roulette: wavetrace plays it after the
        # scatter at hit number roulette_depth (1-based) and on; Mitsuba's path
        # tracer when its depth counter (hits so far) >= rr_depth.
        return {"type": "path", "max_depth": self.depth, "rr_depth": self.roulette_depth, "hide_emitters": False}

    # -- textures and materials ---------------------------------------------
    def texture(self, name, albedo, on_sphere, to_object):
        """The reflectance: albedo times the named texture. to_object: the
        shape's world -> object matrix (for checker)."""
        t = name if isinstance(name, dict) else self.textures.get(name)
        if t is None:
            raise ConversionError("unknown texture %s" % name)
        return self._texture(t, albedo, on_sphere, to_object)

    def _texture(self, t, albedo, on_sphere, to_object):
        kind = t["type"]
        if kind == "checker":
            size = float(t["size"])
            even = [float(a) * float(b) for a, b in zip(albedo, t["even"])]
            odd = [float(a) * float(b) for a, b in zip(albedo, t["odd"])]
            if not self.allow_python:
                mean = [0.5 * (a + b) for a, b in zip(even, odd)]
                self.notes.add("checker texture '%s': without Python plugins, its mean colour %s"
                               % (t["name"], [round(x, 4) for x in mean]))
                return _rgb(mean)
            # Mitsuba's checkerboard is a function of the surface's UVs (a sphere's
            # are its angles), wavetrace's of the object-space x and z: a texture
            # written in Python evaluates wavetrace's pattern exactly.
            self.python_plugins.add("wt_checker")
            # The object-space point's x and z (rows 0 and 2 of to_object) are all it reads.
            d = {"type": "wt_checker", "size": size}
            for row, label in ((0, "x"), (2, "z")):
                for k in range(4):
                    d["o%s%d" % (label, k)] = float(to_object[row][k])
            for label, c in (("even", even), ("odd", odd)):
                for ch, x in zip("rgb", c):
                    d["%s_%s" % (label, ch)] = x
            return d
        if kind == "noise":
            hi, lo = t["high"], t["low"]
            mean = [float(a) * 0.5 * (float(h) + float(l)) for a, h, l in zip(albedo, hi, lo)]
            self.notes.add("noise texture '%s': no Mitsuba counterpart; its mean colour "
                           "(high + low) / 2 x albedo = %s is used" % (t["name"], [round(x, 4) for x in mean]))
            return _rgb(mean)
        if kind == "image":
            return self._image(self.file(t["file"]), t.get("colorspace", "srgb"), albedo, on_sphere, t)
        raise ConversionError("unknown texture type %s" % kind)

    def _image(self, path, colorspace, albedo, on_sphere, t=None):
        """A bitmap; t: the scene's image texture (its wrap modes and UV
        transform), None for a mesh file's own texture (which repeats both ways
        in wavetrace, as glTF's default sampler)."""
        wrap = t.get("wrap", IMAGE_WRAP) if t is not None else ["repeat", "repeat"]
        wrap = [wrap, wrap] if isinstance(wrap, str) else list(wrap)
        d = {"type": "bitmap", "filename": path, "raw": colorspace == "linear",
             "filter_type": "bilinear", "wrap_mode": wrap[0] if wrap[0] == wrap[1] else "repeat"}
        if wrap[0] != wrap[1]:
            # Mitsuba's bitmap has one wrap mode for both axes.
            self.notes.add("image textures: Mitsuba's bitmap wraps u and v alike (repeat), wavetrace %s u and %s "
                           "v: differs within half a texel of the %s" % (
                               wrap[0], wrap[1], "top and bottom rows" if wrap[0] == "repeat" else "edges"))
        to_uv = SPHERE_TO_UV if on_sphere else mat_identity()
        if t is not None and any(k in t and t[k] != v for k, v in (("uv_scale", [1, 1]), ("uv_offset", [0, 0]),
                                                                    ("uv_rotation", 0))):
            # wavetrace's (and KHR_texture_transform's) uv' = offset + R (scale uv),
            # R = [cos sin; -sin cos] (include/wavetrace/texture.hpp): the 2D
            # affine map Mitsuba's bitmap applies through to_uv (its x, y and
            # translation column), after the sphere's own turn where there is one.
            sx, sy = (float(x) for x in t.get("uv_scale", [1, 1]))
            ox, oy = (float(x) for x in t.get("uv_offset", [0, 0]))
            c, s = math.cos(float(t.get("uv_rotation", 0))), math.sin(float(t.get("uv_rotation", 0)))
            tr = [[c * sx, s * sy, 0.0, ox], [-s * sx, c * sy, 0.0, oy], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
            to_uv = mat_mul(tr, to_uv)
        if t is not None and t.get("filter", "trilinear") == "trilinear":
            self.notes.add("image texture '%s': wavetrace filters it trilinearly between mip levels where it is "
                           "minified, Mitsuba's bitmap bilinearly at full size (\"filter\": \"bilinear\" "
                           "compares like with like)" % t["name"])
        if t is not None and (t.get("magnify") == "nearest" or t.get("filter") == "nearest"):
            # Mitsuba's bitmap has one filter for both ways.
            d["filter_type"] = "nearest"
            if t.get("magnify") != t.get("filter"):
                self.notes.add("image texture '%s': nearest texels where wavetrace %s it and %s where it %s it; "
                               "Mitsuba's bitmap filters one way, nearest, both ways" % (
                                   t["name"], "magnifies" if t.get("magnify") == "nearest" else "minifies",
                                   t.get("filter") if t.get("magnify") == "nearest" else t.get("magnify"),
                                   "minifies" if t.get("magnify") == "nearest" else "magnifies"))
        if not is_identity(to_uv):
            d["to_uv"] = transform(to_uv)
        if not _is_white(albedo) and not self.allow_python:
            self.notes.add("image texture %s: without Python plugins, the albedo %s it is multiplied by "
                           "is dropped" % (os.path.basename(path), list(albedo)))
        elif not _is_white(albedo):
            self.python_plugins.add("wt_scale")
            return {"type": "wt_scale", "texture": d, "r": float(albedo[0]), "g": float(albedo[1]),
                    "b": float(albedo[2])}
        return d

    def reflectance(self, m, on_sphere, to_object):
        albedo = m.get("albedo", [1, 1, 1])
        if "texture" in m:
            return self.texture(m["texture"], albedo, on_sphere, to_object)
        if "__image__" in m:
            return self._image(m["__image__"]["file"], m["__image__"]["colorspace"], albedo, on_sphere, None)
        return _rgb(albedo)

    def object_space(self, m):
        """Whether one of the material's textures (its albedo's, its roughness's)
        is a function of the object-space point."""
        for key in ("texture", "roughness_texture", "metallic_texture"):
            ref = m.get(key, "")
            t = ref if isinstance(ref, dict) else self.textures.get(ref)
            if t is not None and t["type"] == "checker":
                return True
        return False

    def texture_of(self, m, key):
        """The texture the material's KEY names (None where it names none)."""
        name = m.get(key)
        if name is None:
            return None
        if isinstance(name, dict):
            return name     # a mesh file's own texture
        t = self.textures.get(name)
        if t is None:
            raise ConversionError("material '%s': unknown texture %s" % (m["name"], name))
        return t

    @staticmethod
    def roughness_of(m):
        """A microfacet material's roughness: 1 by default where a roughness
        texture scales it, 0 otherwise (as wavetrace reads it)."""
        return float(m.get("roughness", 1.0 if "roughness_texture" in m else 0.0))

    def textured(self, m, value, power, on_sphere, to_object, takes_texture=True):
        """VALUE (an alpha, power 2, or a roughness, power 1) times the green
        channel of the material's roughness_texture to the power POWER, as
        wavetrace scales alpha at each hit: a wt_roughness texture (Python) where
        the Mitsuba parameter takes a texture and the pattern converts; else one
        number, from the texture's mean green (noted). VALUE where the material
        has no roughness texture."""
        t = self.texture_of(m, "roughness_texture")
        if t is None:
            return value
        name = t["name"]
        if takes_texture and self.allow_python and t["type"] in ("checker", "image"):
            self.python_plugins.add("wt_roughness")
            return {"type": "wt_roughness", "texture": self._texture(t, [1, 1, 1], on_sphere, to_object),
                    "scale": float(value), "power": float(power)}
        if not takes_texture:
            why = "Mitsuba's roughplastic takes one alpha (its tables are computed for it)"
        elif not self.allow_python:
            why = "without Python plugins Mitsuba cannot square a texture (alpha = (roughness x green)^2)"
        else:
            why = "a noise texture has no Mitsuba counterpart"

        def clamp(x):
            return min(max(float(x), 0.0), 1.0)

        if t["type"] == "image":
            out = {"__green_mean__": {"file": self.file(t["file"]), "srgb": t.get("colorspace", "srgb") == "srgb",
                                      "scale": float(value), "power": float(power)}}
            mean, value_text = "its mean green over the texels (computed when the scene is loaded)", ""
        else:
            a, b = (t["even"], t["odd"]) if t["type"] == "checker" else (t["high"], t["low"])
            g = 0.5 * (clamp(a[1]) + clamp(b[1]))
            out = float(value) * g ** power
            mean = "its mean green %s = %g" % ("(even + odd) / 2" if t["type"] == "checker" else "(high + low) / 2", g)
            value_text = " = %.6g" % out
        self.notes.add("roughness_texture '%s' of '%s': the textured roughness does not map exactly: %s; %s "
                       "gives one %s over the whole surface, (roughness x mean)%s%s (wavetrace: (roughness x "
                       "green)%s at each hit)" % (name, m["name"], why, mean, "roughness" if power == 1 else "alpha",
                                                  "" if power == 1 else "^2", value_text, "" if power == 1 else "^2"))
        return out

    def normal_map(self, m, b, on_sphere):
        """B wrapped in Mitsuba's normalmap where the material has a normal_texture
        that converts (an image): the map perturbs the shading frame of the BSDF
        inside, twosided included, so that a surface's back sees the map turned
        with it, as in wavetrace."""
        t = self.texture_of(m, "normal_texture")
        if t is None:
            return b
        name = t["name"]
        strength = float(m.get("normal_strength", 1.0))
        if strength == 0:
            return b   # the unperturbed normal, in wavetrace too
        if t["type"] != "image":
            self.notes.add("normal_texture '%s' of '%s': a %s texture used as a normal map does not map (Mitsuba's "
                           "normalmap reads a texture's colour in its shading frame, and the procedural pattern is "
                           "not converted to one): converted without its normal map" % (name, m["name"], t["type"]))
            return b
        if t.get("colorspace", "srgb") != "linear":
            raise ConversionError("material '%s': normal_texture '%s' is read as sRGB; a normal map needs "
                                  "\"colorspace\": \"linear\" (wavetrace refuses it too)" % (m["name"], name))
        if strength != 1 and not self.allow_python:
            self.notes.add("normal_strength %g of '%s': Mitsuba's normalmap has no strength, and without Python "
                           "plugins the map is used as it is (strength 1)" % (strength, m["name"]))
        if on_sphere:
            self.notes.add("normal maps on spheres: both tangent frames run along the azimuth and up the image "
                           "(towards the +y pole), but Mitsuba's dp/du points the other way round (SPHERE_FRAME "
                           "turns its u against wavetrace's; to_uv turns the texture back): the map's x (red) tilts "
                           "the normal the mirrored way in Mitsuba, its y (green) the same way")
        else:
            self.notes.add("normal maps on meshes: Mitsuba's normalmap works in its shading frame, s = dp/du (of the "
                           "UVs) made orthogonal to the shading normal n, t = cross(n, s); wavetrace's tangent is the "
                           "same, its bitangent cross(n, dp/du) times the UV handedness (so +y is up the image on "
                           "every triangle): the frames agree where a triangle's UVs are not mirrored (seen from the "
                           "front, the image is not flipped), the map's y (green) tilts the other way on mirrored "
                           "ones, and on a mesh without UVs the tangents differ (wavetrace: the triangle's first "
                           "edge; Mitsuba: an arbitrary frame about n)")
        self.notes.add("normal maps: where the viewer is below the mapped normal, wavetrace turns the normal towards "
                       "it (to a cosine of 0.01) and Mitsuba's normalmap mirrors the normal's tilt "
                       "(flip_invalid_normals); Mitsuba drops directions on different sides of the mapped and the "
                       "unmapped shading normal, where wavetrace absorbs reflections that cross the geometric "
                       "surface; Mitsuba's shadow-terminator term is off (use_shadowing_function false: wavetrace "
                       "has none)")
        bitmap = self._image(self.file(t["file"]), "linear", [1, 1, 1], on_sphere, t)
        if strength != 1 and self.allow_python:
            # wavetrace (and glTF's normalTexture scale) scales the map's x and y
            # by the strength before normalising; Mitsuba's normalmap reads
            # 2 c - 1 and normalises: a texture of (strength (2 c - 1) + 1) / 2
            # in x and y does it.
            self.python_plugins.add("wt_normal_scale")
            bitmap = {"type": "wt_normal_scale", "texture": bitmap, "strength": strength}
        return {"type": "normalmap", "normalmap": bitmap, "flip_invalid_normals": True,
                "use_shadowing_function": False, "bsdf": b}

    def bump_map(self, m, b, on_sphere):
        """B wrapped in Mitsuba's bumpmap where the material has a bump_texture: the
        same displacement, bump_scale times the image's luminance in world units
        along the normal, outside the twosided adapter as a normal map is."""
        t = self.texture_of(m, "bump_texture")
        if t is None:
            return b
        scale = float(m.get("bump_scale", 1.0))
        if scale == 0:
            return b
        self.notes.add("bump maps: both displace by bump_scale x the image's luminance along the normal; Mitsuba's "
                       "bumpmap differentiates its bilinear lookup at the hit (a slope constant across each texel, "
                       "at full resolution) with the exact dp/du and dp/dv, wavetrace central differences taken at "
                       "load, filtered (and mip-mapped) as any image, with the triangle's UV density as the rate "
                       "(exact on a UV map that neither shears nor stretches one axis against the other)")
        bitmap = self._image(self.file(t["file"]), "linear", [1, 1, 1], on_sphere, t)
        return {"type": "bumpmap", "arbitrary": bitmap, "scale": scale, "bsdf": b}

    def bsdf(self, m, on_sphere, to_object):
        """The BSDF dict of a wavetrace material (no id)."""
        kind = m["type"]
        if kind == "lambertian":
            b = {"type": "diffuse", "reflectance": self.reflectance(m, on_sphere, to_object)}
        elif kind == "metal":
            fuzz = float(m.get("fuzz", 0))
            refl = self.reflectance(m, on_sphere, to_object)
            if fuzz == 0:
                b = {"type": "conductor", "material": "none", "specular_reflectance": refl}
            else:
                b = {"type": "roughconductor", "material": "none", "distribution": "beckmann",
                     "alpha": fuzz * FUZZ_TO_ALPHA, "specular_reflectance": refl}
                self.notes.add("metal fuzz -> roughconductor (Beckmann) alpha = fuzz / sqrt(6) (equal mean-square "
                               "half-vector slope at normal incidence); the lobe shapes differ, and Mitsuba "
                               "adds Smith masking (wavetrace absorbs only what the fuzz sends below the surface)")
        elif kind == "dielectric":
            b = {"type": "dielectric", "int_ior": float(m["ior"]), "ext_ior": 1.0}
            tint = m.get("albedo", [1, 1, 1])
            if not _is_white(tint):
                b["specular_reflectance"] = _rgb(tint)
                b["specular_transmittance"] = _rgb(tint)
            self.notes.add("dielectric: Mitsuba uses the exact Fresnel equations (wavetrace: Schlick's "
                           "approximation) and scales radiance by 1/eta^2 on refraction (cancels on leaving)")
        elif kind == "coated":
            b = {"type": "plastic", "diffuse_reflectance": self.reflectance(m, on_sphere, to_object),
                 "int_ior": float(m["ior"]), "ext_ior": 1.0, "nonlinear": False}
            self.notes.add("coated -> plastic: Mitsuba's coat has exact Fresnel and internal reflections "
                           "between coat and base (wavetrace: a Schlick-weighted choice of mirror or Lambertian)")
        elif kind == "emissive":
            # The path ends at an emitter in wavetrace: a black mirror ends it
            # here too (zero throughput, and no light sample at a delta BSDF).
            b = {"type": "conductor", "material": "none", "specular_reflectance": _rgb([0, 0, 0])}
        elif kind == "conductor":
            b = self.conductor(m, on_sphere, to_object)
        elif kind == "glass":
            b = self.glass(m, on_sphere, to_object)
        elif kind == "plastic":
            b = self.plastic(m, on_sphere, to_object)
        elif kind == "principled":
            b = self.principled(m, on_sphere, to_object)
        elif kind == "blend":
            # Mitsuba's blendbsdf is the same mixture (its weight clamped to [0, 1],
            # a texture's read by its luminance); it evaluates both BSDFs at a hit
            # where wavetrace shades with one picked by the weight.
            w = float(m.get("weight", 0.5))
            weight = (self.texture(m["weight_texture"], [w, w, w], on_sphere, to_object)
                      if "weight_texture" in m else w)
            b = {"type": "blendbsdf", "weight": weight}
            for i, name in enumerate(m["materials"]):
                b["bsdf_%d" % i] = self.bsdf(self.materials[name], on_sphere, to_object)
            return b
        else:
            raise ConversionError("unknown material type %s" % kind)
        if kind in ("conductor", "plastic") or (not on_sphere and kind in ("lambertian", "metal", "coated")):
            # wavetrace shades either side of a triangle (it turns the normal to the
            # ray), and its conductors and plastics either side of any surface;
            # Mitsuba's BSDFs are one-sided unless wrapped.
            b = {"type": "twosided", "bsdf": b}
        return self.alpha(m, self.bump_map(m, self.normal_map(m, b, on_sphere), on_sphere), on_sphere)

    def channel(self, t, channel, scale, on_sphere, to_object, what, cutoff=None):
        """SCALE times channel CHANNEL (0 red, 1 green, 2 blue) of texture T,
        clamped to [0, 1] (and thresholded at CUTOFF where given): a wt_channel
        texture; without Python plugins, SCALE alone (noted)."""
        if not self.allow_python:
            self.notes.add("%s: without Python plugins Mitsuba cannot read one channel of a texture; the factor %g "
                           "alone is used" % (what, scale))
            return float(scale)
        self.python_plugins.add("wt_channel")
        d = {"type": "wt_channel", "texture": self._texture(t, [1, 1, 1], on_sphere, to_object),
             "channel": int(channel), "scale": float(scale)}
        if cutoff is not None:
            d["cutoff"] = float(cutoff)
        return d

    def principled(self, m, on_sphere, to_object):
        """wavetrace's principled (glTF's metallic-roughness model,
        include/wavetrace/bsdfs/principled.hpp) on Mitsuba's principled (Disney
        2015), or principledthin where it passes light through a thin wall. What
        the models do not share is noted, one line each."""
        name = m["name"]
        roughness = self.roughness_of(m)
        anisotropy = float(m.get("anisotropy", 0.0))
        metallic = float(m.get("metallic", 1.0 if "metallic_texture" in m else 0.0))
        ior = float(m.get("ior", 1.5))
        specular = float(m.get("specular", 1.0))
        transmission = float(m.get("transmission", 1.0 if "transmission_texture" in m else 0.0))
        thin = bool(m.get("thin", True))
        clearcoat = float(m.get("clearcoat", 1.0 if "clearcoat_texture" in m else 0.0))
        f0 = ((ior - 1.0) / (ior + 1.0)) ** 2
        b = {"base_color": self.reflectance(m, on_sphere, to_object),
             # Principled squares its roughness itself (alpha = roughness^2, over and
             # times sqrt(1 - 0.9 anisotropic) along and across the tangent, as
             # wavetrace's ggx_from_roughness): a roughness texture scales it linearly.
             "roughness": self.textured(m, roughness, 1, on_sphere, to_object)}
        if anisotropy > 0:
            b["anisotropic"] = anisotropy
        self._masking_note(m)
        if roughness * roughness * math.sqrt(1.0 - 0.9 * anisotropy) < 0.001:
            self.notes.add("principled below roughness 0.032: Mitsuba's principled keeps each alpha >= 0.001, where "
                           "wavetrace's lobes are smaller, and mirrors (deltas) below alpha 1e-4")
        self.notes.add("principled -> Mitsuba's principled: the metal is the same (Schlick from f0 = base colour on "
                       "GGX); the dielectric's specular layer uses the exact Fresnel of the index where wavetrace's "
                       "uses Schlick's, and its diffuse is Disney's (Schlick-weighted, with retro-reflection that "
                       "grows with roughness), where wavetrace's is a Lambertian weighed by what the layer lets "
                       "through, (1 - E_s(mu_o)) (1 - E_s(mu_i)) / (1 - E_s,avg)")
        if m.get("energy_compensation", True):
            self.notes.add("energy_compensation (the default, glTF materials' too): wavetrace gives principled's "
                           "rough glossy lobes a Kulla-Conty lobe for what single scattering loses; Mitsuba's "
                           "principled has none (the rougher, the darker the metal)")
        tex = self.texture_of(m, "metallic_texture")
        if tex is not None and metallic > 0:
            metallic_value = self.channel(tex, 2, metallic, on_sphere, to_object,
                                          "metallic_texture of '%s'" % name)
        else:
            metallic_value = metallic
        tex = self.texture_of(m, "transmission_texture")
        trans_value = transmission
        if tex is not None and transmission > 0:
            trans_value = self.channel(tex, 0, transmission, on_sphere, to_object,
                                       "transmission_texture of '%s'" % name)
        if transmission > 0 and thin:
            # principledthin: Disney's thin surface, its specular transmission the
            # layer's lobe passed straight through (roughness scaled by the index),
            # tinted by the base colour, as wavetrace's thin wall is.
            b.update({"type": "principledthin", "spec_trans": trans_value, "eta": ior})
            self.notes.add("principled '%s', a thin wall that transmits: Mitsuba's principledthin (Disney's thin "
                           "surface: the transmitted lobe's roughness scaled by (0.65 eta - 0.35), Fresnel exact, "
                           "a Disney diffuse with no layer weighting); wavetrace mirrors the layer's own GGX lobe to "
                           "the far side, weighed by 1 - s F_d, and loses nothing. principledthin has no metal and "
                           "no clear coat%s" % (name, "" if not (metallic or clearcoat) else
                                                ": metallic %g and clearcoat %g are dropped" % (metallic, clearcoat)))
            if specular != 1:
                self.notes.add("principled '%s': specular %g is not converted on a transmitting wall (eta = ior "
                               "sets Mitsuba's layer)" % (name, specular))
            return b
        b["type"] = "principled"
        if metallic_value != 0:
            b["metallic"] = metallic_value
        if transmission > 0:
            # A volume: the share t refracts at the index (the exact Fresnel, as
            # wavetrace's glass share), so eta is the index itself.
            b["spec_trans"] = trans_value
            b["eta"] = ior
            self.notes.add("principled transmission into a volume -> principled spec_trans: Mitsuba tints each "
                           "crossing by sqrt(base colour) (twice through a closed shape: the base colour), wavetrace "
                           "each crossing by the base colour; both take the share t from the diffuse base and "
                           "refract with the exact Fresnel of the index")
            if specular != 1:
                self.notes.add("principled '%s': specular %g is not converted where the material refracts (eta = "
                               "ior sets Mitsuba's layer and the refraction alike)" % (name, specular))
        else:
            # Mitsuba's eta sets its layer's reflectance, f0 = ((eta - 1) / (eta +
            # 1))^2 at normal incidence, as wavetrace's index sets F_d's f0. The
            # layer's strength s (KHR_materials_specular) has no counterpart:
            # the index whose f0 is s f0 gives the layer's normal-incidence
            # reflectance (Mitsuba's still reaches 1 at grazing, wavetrace's s).
            r = math.sqrt(max(specular, 0.0) * f0)
            b["eta"] = max((1.0 + r) / (1.0 - r) if r < 1.0 else 1e4, 1.0 + 1e-4)
            if specular != 1:
                self.notes.add("principled '%s': specular %g -> eta %.5g, the index whose f0 is %g x %.4g (the "
                               "layer's reflectance at normal incidence; Mitsuba's exact Fresnel still reaches 1 at "
                               "grazing angles, wavetrace's s F_d reaches s)" % (name, specular, b["eta"], specular, f0))
        if clearcoat > 0:
            cr = float(m.get("clearcoat_roughness", 1.0 if "clearcoat_roughness_texture" in m else 0.0))
            # Mitsuba's coat: clearcoat x 0.25 x Schlick(0.04) x GTR1(alpha = 0.1 -
            # 0.099 gloss) x Smith G(alpha 0.25) / (4 mu_o): 4 c makes it a microfacet
            # lobe of weight c, as wavetrace's coat is.
            tex = self.texture_of(m, "clearcoat_texture")
            b["clearcoat"] = (self.channel(tex, 0, 4.0 * clearcoat, on_sphere, to_object,
                                           "clearcoat_texture of '%s'" % name) if tex is not None else 4.0 * clearcoat)
            b["clearcoat_gloss"] = min(max((0.1 - cr * cr) / 0.099, 0.0), 1.0)
            self.notes.add("clear coat -> principled clearcoat = 4 c (Mitsuba scales its coat by 0.25: 4 c makes it a "
                           "lobe of weight c, f0 0.04, as wavetrace's), clearcoat_gloss = (0.1 - r^2) / 0.099 so that "
                           "its GTR1 alpha is wavetrace's r^2 (clamped to [0.001, 0.1]); but GTR1's long tail is not "
                           "GGX, its masking has a fixed alpha of 0.25, and Mitsuba adds the coat on top of the base "
                           "where wavetrace weighs the base by min(1 - c E_c(mu_o), 1 - c E_c(mu_i))")
            if cr * cr > 0.1:
                self.notes.add("principled '%s': clearcoat_roughness %g (alpha %.3g) is rougher than Mitsuba's "
                               "coat can be (alpha 0.1)" % (name, cr, cr * cr))
            for key in ("clearcoat_roughness_texture", "clearcoat_normal_texture"):
                if key in m:
                    self.notes.add("principled '%s': its %s is not converted (Mitsuba's coat has one gloss and "
                                   "follows the base's normal)" % (name, key))
        if not m.get("double_sided", True):
            # One-sided: wavetrace's back face reflects nothing, and so does Mitsuba's
            # principled without spec_trans (its back-side Fresnel is spec_trans x the
            # dielectric's, and its diffuse and coat are front-only): left bare.
            return b
        if transmission > 0:
            # Mitsuba's twosided refuses transmitting BSDFs; principled with
            # spec_trans is seen from both sides already, as wavetrace's is.
            return b
        return {"type": "twosided", "bsdf": b}

    def alpha(self, m, b, on_sphere):
        """B inside Mitsuba's mask where the material has glTF's alpha (MASK, BLEND):
        the opacity the base colour's alpha times its factor, thresholded at the
        cutoff for MASK (a wt_channel texture of the alpha channel, extracted from
        the image when the scene is loaded: Mitsuba's bitmap drops alpha)."""
        a = m.get("__alpha__")
        if a is None:
            return b
        self.needs_volpath = True
        if "texture" not in a:
            # A constant alpha: MASK below its cutoff (wholly cut away), or BLEND.
            opacity = 0.0 if a["mode"] == "mask" else a["factor"]
        else:
            t = dict(a["texture"])
            bitmap = self._image(t["file"], "linear", [1, 1, 1], on_sphere, t)
            bitmap["filename"] = {"__alpha_image__": {"file": t["file"]}}
            if self.allow_python:
                self.python_plugins.add("wt_channel")
                opacity = {"type": "wt_channel", "texture": bitmap, "channel": 0, "scale": float(a["factor"])}
                if a["mode"] == "mask":
                    opacity["cutoff"] = float(a["cutoff"])
            else:
                opacity = bitmap
                self.notes.add("alpha of '%s': without Python plugins the alpha is used as an opacity as it is (no "
                               "factor%s)" % (m["name"], ", no cutoff" if a["mode"] == "mask" else ""))
        self.notes.add("glTF alpha (MASK, BLEND) -> Mitsuba's mask (opacity = alpha x factor, 0 or 1 at the MASK "
                       "cutoff; BLEND is a stochastic opacity in both); the integrator is volpath, whose shadow rays "
                       "pass through masks as wavetrace's do (path's do not)")
        return {"type": "mask", "opacity": opacity, "bsdf": b}

    def medium_for(self, m):
        """The interior medium of a principled volume that absorbs: Beer-Lambert's
        sigma = -ln(colour) / distance per channel (KHR_materials_volume), a
        homogeneous medium that only absorbs (albedo 0) in volpath."""
        if m["type"] != "principled" or m.get("thin", True) or "attenuation_distance" not in m:
            return None
        if not float(m.get("transmission", 1.0 if "transmission_texture" in m else 0.0)) > 0:
            return None
        d = float(m["attenuation_distance"])
        sigma = [-math.log(max(float(c), 1e-30)) / d for c in m.get("attenuation_color", [1, 1, 1])]
        if not any(sigma):
            return None
        self.needs_volpath = True
        self.notes.add("principled volume absorption -> a homogeneous medium inside the shape (sigma_t = -ln(colour) "
                       "/ distance, albedo 0) under volpath: Beer-Lambert in both; Mitsuba samples the distance and "
                       "ends absorbed paths (noisier), wavetrace multiplies by exp(-sigma t)")
        return {"type": "homogeneous", "albedo": 0.0,
                "sigma_t": {"type": "constvolume", "value": _rgb(sigma)}}

    def _compensation_note(self, m, how, mitsuba):
        """A note where wavetrace compensates the multiple scattering that the
        single-scattering Mitsuba BSDF of a rough material loses."""
        if m.get("energy_compensation", True):
            self.notes.add("energy_compensation (the default): wavetrace %s; Mitsuba's %s has none and loses "
                           "the light that scatters more than once among the microfacets (the rougher, the "
                           "darker; \"energy_compensation\": false compares single scattering with single "
                           "scattering)" % (how, mitsuba))

    def _masking_note(self, m):
        """SMITH_NOTE where a rough material masks with wavetrace's height-correlated
        Smith term (its default); "separable" is Mitsuba's."""
        masking = m.get("masking", MASKINGS[0])
        if masking not in MASKINGS:
            raise ConversionError("material '%s': masking '%s' is none of %s" % (m["name"], masking, ", ".join(MASKINGS)))
        if masking == MASKINGS[0]:
            self.notes.add(SMITH_NOTE)

    def conductor(self, m, on_sphere=True, to_object=None):
        """wavetrace's conductor: GGX with alpha = roughness^2, stretched by
        anisotropy along the tangent (a sphere's direction of increasing u, the
        azimuth, which Mitsuba's sphere frame also takes for its s axis:
        SPHERE_FRAME turns u the other way round, and GGX is even in it)."""
        to_object = to_object if to_object is not None else mat_identity()
        roughness = self.roughness_of(m)
        anisotropy = float(m.get("anisotropy", 0))
        alpha = roughness * roughness
        aspect = math.sqrt(1.0 - 0.9 * anisotropy)
        alpha_x, alpha_y = alpha / aspect, alpha * aspect
        smooth = alpha_x < SMOOTH_ALPHA and alpha_y < SMOOTH_ALPHA
        if not smooth:
            self._masking_note(m)
        if not smooth and anisotropy > 0 and not on_sphere:
            self.notes.add("anisotropic conductor '%s' on a mesh: the tangent alpha_x runs along is dp/du of the "
                           "mesh's UVs in both renderers, but without UVs wavetrace takes the triangle's first "
                           "edge and Mitsuba a frame of its own" % m["name"])
        if "f0" in m:
            # Schlick's Fresnel with F0 = f0 at the microfacet normal is the
            # metallic lobe of Mitsuba's principled BSDF (metallic 1: no diffuse,
            # sheen, clearcoat or transmission; spec_tint unset), with GGX, Smith
            # masking and the same roughness / anisotropy mapping (Disney's).
            # Principled squares its roughness itself: a roughness texture scales
            # it linearly (power 1).
            b = {"type": "principled", "base_color": _rgb(m["f0"]), "metallic": 1.0,
                 "roughness": self.textured(m, roughness, 1, on_sphere, to_object)}
            if anisotropy > 0:
                b["anisotropic"] = anisotropy
            self.notes.add("conductor with f0 -> principled, metallic 1, base_color = f0: Schlick's Fresnel at "
                           "the microfacet normal, GGX, alpha = roughness^2 over and times sqrt(1 - 0.9 anisotropy) "
                           "along and across the tangent, as in wavetrace")
            if min(alpha_x, alpha_y) < 0.001:
                self.notes.add("conductor '%s' (f0, roughness %g): principled keeps each alpha >= 0.001, where "
                               "wavetrace's is %s" % (m["name"], roughness, "a perfect mirror" if smooth
                                                      else "smaller"))
            if not smooth:
                self._compensation_note(m, CONDUCTOR_COMPENSATION, "principled")
            return b
        if "metal" in m:
            presets = conductor_presets()
            if m["metal"] not in presets:
                raise ConversionError("conductor '%s': metal preset '%s' is not in %s (found: %s)"
                                      % (m["name"], m["metal"], CONDUCTOR_PRESETS_HEADER,
                                         ", ".join(presets) or "none"))
            eta, k = presets[m["metal"]]
        elif "eta" in m and "k" in m:
            eta, k = m["eta"], m["k"]
        else:
            raise ConversionError("conductor '%s' has none of metal, eta + k, f0" % m["name"])
        b = {"eta": _rgb(eta), "k": _rgb(k)}
        if smooth:
            b["type"] = "conductor"
            return b
        b.update({"type": "roughconductor", "distribution": "ggx", "sample_visible": True})
        if anisotropy > 0:
            b["alpha_u"] = self.textured(m, alpha_x, 2, on_sphere, to_object)
            b["alpha_v"] = self.textured(m, alpha_y, 2, on_sphere, to_object)
        else:
            b["alpha"] = self.textured(m, alpha, 2, on_sphere, to_object)
        self._compensation_note(m, CONDUCTOR_COMPENSATION, "roughconductor")
        return b

    def glass(self, m, on_sphere=True, to_object=None):
        """wavetrace's glass: exact dielectric Fresnel, GGX (alpha = roughness^2)
        where rough, 1/eta^2 on refraction (Mitsuba's radiance mode), the tint
        on transmission only."""
        to_object = to_object if to_object is not None else mat_identity()
        ior = float(m.get("ior", 1.5))
        roughness = self.roughness_of(m)
        alpha = roughness * roughness
        if m.get("thin", False):
            if roughness > 0:
                raise ConversionError("glass '%s': thin glass has roughness 0 only" % m["name"])
            b = {"type": "thindielectric", "int_ior": ior, "ext_ior": 1.0}
        elif alpha < SMOOTH_ALPHA or ior == 1.0:
            # An interface of index 1 neither reflects nor bends, rough or not
            # (and roughdielectric refuses equal indices).
            b = {"type": "dielectric", "int_ior": ior, "ext_ior": 1.0}
        else:
            b = {"type": "roughdielectric", "distribution": "ggx", "sample_visible": True,
                 "alpha": self.textured(m, alpha, 2, on_sphere, to_object),
                 "int_ior": ior, "ext_ior": 1.0}
            self._masking_note(m)
            self._compensation_note(m, GLASS_COMPENSATION, "roughdielectric")
        tint = m.get("tint", [1, 1, 1])
        if not _is_white(tint):
            b["specular_transmittance"] = _rgb(tint)
        return b

    def plastic(self, m, on_sphere, to_object):
        """wavetrace's plastic: Mitsuba's plastic / roughplastic, nonlinear."""
        ior = float(m.get("ior", 1.5))
        roughness = self.roughness_of(m)
        alpha = roughness * roughness
        b = {"diffuse_reflectance": self.reflectance(m, on_sphere, to_object), "int_ior": ior, "ext_ior": 1.0,
             "nonlinear": True}
        if alpha < SMOOTH_ALPHA or ior == 1.0:
            # Index 1: no coat to reflect, rough or not; the plastic is its diffuse
            # base (and roughplastic refuses equal indices).
            b["type"] = "plastic"
            if ior != 1.0:
                exact, fit = diffuse_fresnel(1.0 / ior), mitsuba_diffuse_fresnel(1.0 / ior)
                self.notes.add("smooth plastic, ior %g: the coat's reflectance for the diffuse light under it "
                               "(R_int) is a fitted formula in Mitsuba, %.4f, the integral in wavetrace, %.4f "
                               "(%+.2f%%)" % (ior, fit, exact, 100.0 * (fit / exact - 1.0)))
        else:
            b.update({"type": "roughplastic", "distribution": "ggx", "sample_visible": True,
                      "alpha": self.textured(m, alpha, 2, on_sphere, to_object, takes_texture=False)})
            self._masking_note(m)
        metallic = float(m.get("metallic", 1.0 if "metallic_texture" in m else 0.0))
        if metallic > 0.0:
            # The metal: a conductor reflecting the albedo at every angle, where
            # wavetrace's is Schlick's from f0 = albedo (a brighter rim).
            metal = {"type": "conductor", "material": "none",
                     "specular_reflectance": self.reflectance(m, on_sphere, to_object)}
            if alpha >= SMOOTH_ALPHA:
                metal = dict(metal, type="roughconductor", distribution="ggx", sample_visible=True, alpha=alpha)
            b = {"type": "blendbsdf", "weight": metallic, "bsdf_0": b, "bsdf_1": metal}
            self.notes.add("plastic '%s', metallic %g: a blendbsdf of the plastic and a conductor of reflectance "
                           "albedo (wavetrace's metal: Schlick's Fresnel from f0 = albedo, energy-compensated)%s" % (
                               m["name"], metallic,
                               "; its metallic_texture is not converted" if "metallic_texture" in m else ""))
        return b

    def bsdf_ref(self, m, on_sphere, to_object):
        """A shared BSDF where one can be shared, else an inline one."""
        if self.object_space(m):
            return self.bsdf(m, on_sphere, to_object)
        key = (m["name"], on_sphere)
        if key not in self._bsdf_ids:
            ident = self._name("bsdf")
            d = self.bsdf(m, on_sphere, to_object)
            self.out[ident] = d
            self._bsdf_ids[key] = ident
        return {"type": "ref", "id": self._bsdf_ids[key]}

    @staticmethod
    def emits(m):
        """Whether the material emits: an emitter, or a principled material with an
        emission (which reflects and emits)."""
        if m["type"] == "emissive":
            return any(float(x) for x in m["emission"])
        return m["type"] == "principled" and any(float(x) for x in m.get("emission", [0, 0, 0]))

    def emitter_for(self, m, area, on_sphere=False, to_object=None):
        """The area emitter of a material that emits (None for others): its
        emission, times its emission_texture where it has one (an emitter is
        picked by its untextured emission x area in both)."""
        if not self.emits(m):
            return None
        e = [float(x) for x in m["emission"]]
        radiance = _rgb(e)
        if "emission_texture" in m:
            radiance = self.texture(m["emission_texture"], e, on_sphere,
                                    to_object if to_object is not None else mat_identity())
        d = {"type": "area", "radiance": radiance}
        self.emitters.append((d, True, _mean3(e) * area))
        return d

    # -- shapes ---------------------------------------------------------------
    def spheres(self):
        for s in self.doc.get("spheres", []):
            m = self.materials[s["material"]]
            c = [float(x) for x in s["center"]]
            r = float(s["radius"])
            to_world = mat_mul(mat_mul(mat_translate(c), SPHERE_FRAME), mat_scale(r))
            shape = {"type": "sphere", "to_world": transform(to_world),
                     "bsdf": self.bsdf_ref(m, True, mat_translate([-x for x in c]))}
            em = self.emitter_for(m, 4.0 * math.pi * r * r, True, mat_translate([-x for x in c]))
            if em is not None:
                shape["emitter"] = em
            medium = self.medium_for(m)
            if medium is not None:
                shape["interior"] = medium
            self.out[self._name("sphere")] = shape
            self._grow([x - r for x in c], [x + r for x in c])

    @staticmethod
    def _part_shape(part, to_world):
        shape = {"type": part.kind, "filename": part.file}
        if not part.has_normals:
            # wavetrace shades with the geometric normal where the mesh has no
            # vertex normals; Mitsuba would compute smooth ones.
            shape["face_normals"] = True
        if to_world is not None:
            shape["to_world"] = transform(to_world)
        return shape

    def meshes(self):
        meshes = {}
        for mesh in self.doc.get("meshes", []):
            parts = read_mesh(self.file(mesh["file"]), mesh["name"], self.notes)
            meshes[mesh["name"]] = (mesh, parts)
        placements = []
        for inst in self.doc.get("instances", []):
            mesh, parts = meshes[inst["mesh"]]
            matrix = instance_matrix(inst)
            override = inst.get("material", mesh.get("material"))
            mats = [self.materials[override] if override is not None else p.material for p in parts]
            placements.append((inst, mesh, parts, matrix, mats))
            for p in parts:
                lo, hi = p.bounds
                corners = [[(lo, hi)[(k >> i) & 1][i] for i in range(3)] for k in range(8)]
                world = [mat_point(matrix, c) for c in corners]
                self._grow([min(w[i] for w in world) for i in range(3)], [max(w[i] for w in world) for i in range(3)])
        if any(self.emits(m) for *_, mats in placements for m in mats):
            self.notes.add("emissive triangles emit on their front side only in Mitsuba (wavetrace: both sides)")
        for inst, mesh, parts, matrix, mats in placements:
            for light in getattr(parts, "lights", []):
                self.punctual(light, matrix, mesh["name"])
        # Placements that can share one Mitsuba shapegroup: same mesh, same
        # materials, nothing that depends on the placement (object-space
        # textures, emitters: Mitsuba instances cannot carry area emitters).
        counts = {}
        for inst in self.doc.get("instances", []):
            counts[inst["mesh"]] = counts.get(inst["mesh"], 0) + 1
        if not self.instancing and any(n > 1 for n in counts.values()):
            self.notes.add("meshes placed more than once: each placement is a Mitsuba shape of its own, holding "
                           "its own transformed copy of the triangles (wavetrace stores each mesh once). "
                           "Mitsuba 3.7.1's shapegroup instancing (--instancing) costs host time on every render "
                           "that grows faster than the instance count (terrain, 400 instances: about 100 s a render "
                           "on the LLVM backend, against 0.1 s flattened)")
        groups = {}
        for k, (inst, mesh, parts, matrix, mats) in enumerate(placements):
            shareable = self.instancing and not any(self.object_space(m) or self.emits(m) or
                                                    self.medium_for(m) is not None for m in mats)
            key = (mesh["name"], tuple(m["name"] for m in mats)) if shareable else ("#", k)
            groups.setdefault(key, []).append(k)
        for key, members in groups.items():
            if len(members) > 1:
                _, mesh, parts, _, mats = placements[members[0]]
                gid = self._name("group")
                group = {"type": "shapegroup"}
                for p, m in zip(parts, mats):
                    shape = self._part_shape(p, None)
                    shape["bsdf"] = self.bsdf_ref(m, False, mat_identity())
                    group[self._name("part")] = shape
                self.out[gid] = group
                for k in members:
                    self.out[self._name("instance")] = {"type": "instance", "shapegroup": {"type": "ref", "id": gid},
                                                        "to_world": transform(placements[k][3])}
                continue
            inst, mesh, parts, matrix, mats = placements[members[0]]
            for p, m in zip(parts, mats):
                shape = self._part_shape(p, None if is_identity(matrix) else matrix)
                shape["bsdf"] = self.bsdf_ref(m, False, mat_inverse_affine(matrix))
                if self.emits(m):
                    em = self.emitter_for(m, p.area_of(matrix) if p.area_of else 0.0, False,
                                          mat_inverse_affine(matrix))
                    if em is not None:
                        shape["emitter"] = em
                medium = self.medium_for(m)
                if medium is not None:
                    shape["interior"] = medium
                self.out[self._name("mesh")] = shape

    def punctual(self, light, placement, mesh_name):
        """A mesh file's KHR_lights_punctual light, placed by the node's matrix and
        the instance's: Mitsuba's point (intensity, W/sr), spot (intensity, cones)
        or directional (irradiance, W/m^2), as wavetrace's PunctualLight."""
        m = mat_mul(placement, light["matrix"])
        pos = mat_point(m, [0.0, 0.0, 0.0])
        tip = mat_point(m, [0.0, 0.0, -1.0])
        d = [tip[i] - pos[i] for i in range(3)]
        ln = math.sqrt(sum(x * x for x in d))
        if ln == 0:
            raise ConversionError("%s: a light's node transform collapses its direction" % mesh_name)
        d = [x / ln for x in d]
        intensity = [float(x) for x in light["intensity"]]
        mean = _mean3(intensity)
        what = "%s light '%s' of %s" % (light["kind"], light["name"], mesh_name)
        if light["kind"] == "directional":
            e = {"type": "directional", "direction": d, "irradiance": _rgb(intensity)}
            power = None            # set by emitter_weights, from the scene's radius
        elif light["kind"] == "point":
            e = {"type": "point", "position": pos, "intensity": _rgb(intensity)}
            power = 4.0 * mean
        else:
            inner, outer = light["inner"], light["outer"]
            # Mitsuba's spot shines down its +z: a frame looking along d.
            up = [0.0, 1.0, 0.0] if abs(d[1]) < 0.9 else [1.0, 0.0, 0.0]
            e = {"type": "spot", "intensity": _rgb(intensity), "cutoff_angle": math.degrees(outer),
                 "beam_width": math.degrees(inner),
                 "to_world": transform(look_at_matrix(pos, [pos[i] + d[i] for i in range(3)], up))}
            power = 2.0 * (1.0 - math.cos(outer)) * mean
            self.notes.add("spot lights: Mitsuba's spot is full inside beam_width (glTF's innerConeAngle) and falls "
                           "to 0 at cutoff_angle (outerConeAngle) linearly in the angle; wavetrace (the extension) "
                           "by clamp((cos - cos_outer) / (cos_inner - cos_outer))^2, smaller in between")
        if light["range"] > 0:
            self.notes.add("%s: its range %g (a fade to 0 at that distance, (1 - (d / range)^4) in wavetrace) is "
                           "not converted: Mitsuba's lights have none" % (what, light["range"]))
        self.out[self._name("light")] = e
        self.punctuals.append((e, power, mean))
        self.emitters.append((e, "always", power))

    # -- sky ----------------------------------------------------------------
    def sky(self):
        sky = self.doc.get("sky", {"type": "gradient"})
        kind = sky.get("type", "gradient")
        lo, hi = self.bounds if self.bounds else ([0.0] * 3, [0.0] * 3)
        radius = 0.5 * math.sqrt(sum((b - a) ** 2 for a, b in zip(lo, hi)))
        sphere_area = 4.0 * math.pi * radius * radius
        if kind == "uniform":
            rad = [float(x) for x in sky["radiance"]]
            if not any(rad):
                return  # black: no emitter in either renderer
            d = {"type": "constant", "radiance": _rgb(rad)}
            self.emitters.append((d, True, _mean3(rad) * sphere_area))
        elif kind == "gradient":
            horizon = [float(x) for x in sky.get("horizon", [1, 1, 1])]
            zenith = [float(x) for x in sky.get("zenith", [0.5, 0.7, 1.0])]
            rows = []
            for i in range(GRADIENT_SKY_ROWS):
                theta = math.pi * i / (GRADIENT_SKY_ROWS - 1)
                t = 0.5 * (math.cos(theta) + 1.0)
                c = [(1 - t) * h + t * z for h, z in zip(horizon, zenith)]
                rows.append(c * GRADIENT_SKY_COLUMNS)
            key = hashlib.sha1(repr((horizon, zenith, GRADIENT_SKY_ROWS, GRADIENT_SKY_COLUMNS)).encode()).hexdigest()[:16]
            path = os.path.join(cache_dir(), "gradient-sky-%s.pfm" % key)
            if not os.path.exists(path):
                write_pfm(path, GRADIENT_SKY_COLUMNS, GRADIENT_SKY_ROWS, rows)
            d = {"type": "envmap", "filename": path}
            # Interpolating t = (cos theta + 1) / 2 linearly between rows h apart
            # errs by at most h^2 / 8 x max |t''| = h^2 / 16.
            self.notes.add("gradient sky -> envmap of a %dx%d lat-long image, linear in theta between rows "
                           "(wavetrace: linear in dir.y; at most %.1e of the colour difference apart)"
                           % (GRADIENT_SKY_COLUMNS, GRADIENT_SKY_ROWS, (math.pi / (GRADIENT_SKY_ROWS - 1)) ** 2 / 16))
            samples = self.sky_sampling == "always"
            if not samples and (self.allow_python or any(s for _, s, _ in self.emitters)):
                self.notes.add("gradient sky: not sampled as a light, as in wavetrace (envmap sampling_weight 0)")
            self.emitters.append((d, samples, _mean3([(a + b) / 2 for a, b in zip(horizon, zenith)]) * sphere_area))
        elif kind == "environment":
            path = self.file(sky["file"])
            mapping = sky.get("mapping", "latlong")
            intensity = float(sky.get("intensity", 1.0))
            rotation = float(sky.get("rotation", 0.0))
            ext = os.path.splitext(path)[1].lower()
            d = {"type": "envmap", "scale": intensity}
            if mapping == "latlong" and ext in (".hdr", ".exr"):
                d["filename"] = path
            else:
                # Read and (for angular / mirror ball) resampled into a lat-long
                # image by load_scene, which has Mitsuba's image readers.
                d["__envmap_image__"] = {"file": path, "mapping": mapping,
                                         "srgb": ext not in (".hdr", ".exr") and sky.get("colorspace", "srgb") == "srgb"}
                if mapping != "latlong":
                    self.notes.add("environment mapping '%s': resampled to a %dx%d lat-long image when loaded "
                                   "(bilinear, as wavetrace samples it)" % (mapping, 2 * RESAMPLED_SKY_ROWS,
                                                                             RESAMPLED_SKY_ROWS))
            # wavetrace turns the environment about +y by `rotation` (x toward -z)
            # and looks up u = atan2(e.x, -e.z) / 2 pi, v = acos(e.y) / pi, the
            # mapping of Mitsuba's envmap in its own frame: to_world is the same turn.
            if rotation != 0:
                d["to_world"] = transform(mat_rotate("y", rotation))
            self.notes.add("environment image: Mitsuba's envmap puts row centres at v = i / (rows - 1) "
                           "(wavetrace: (i + 0.5) / rows): up to half a texel apart toward the poles, none at "
                           "the horizon")
            # wavetrace's power: the mean radiance over the sphere (sin-weighted
            # rows) x the bounding sphere's area; not known without reading the
            # image, so the emitter keeps Mitsuba's default weight where others
            # are sampled too (a pick probability; the estimate stays unbiased).
            self.emitters.append((d, True, None))
        else:
            raise ConversionError("unknown sky type %s" % kind)

    def emitter_weights(self):
        """Which emitters light sampling picks, and how often: as wavetrace,
        by power (mean emission x area); none where wavetrace samples none.
        Punctual lights ("always") are reached by light sampling alone, nee or
        not, a directional one weighed by its irradiance over the scene's
        bounding disc, as wavetrace's PunctualLight::power."""
        lo, hi = self.bounds if self.bounds else ([0.0] * 3, [0.0] * 3)
        radius = 0.5 * math.sqrt(sum((b - a) ** 2 for a, b in zip(lo, hi)))
        self.emitters = [(d, s, (_mean3(d["irradiance"]["value"]) * radius * radius
                                 if p is None and d["type"] == "directional" else p)) for d, s, p in self.emitters]

        def samples(s):
            return s == "always" or (s and self.nee)

        sampled = [(d, p) for d, s, p in self.emitters if samples(s)]
        if len(self.emitters) > 1 or any(not s for _, s, _ in self.emitters) or not self.nee:
            known = [p for _, p in sampled if p is not None]
            default = (sum(known) / len(known)) if known else 1.0
            for d, s, p in self.emitters:
                d["sampling_weight"] = float((p if p is not None else default) if samples(s) else 0.0)
            if len(self.emitters) > 1 and any(p is None for _, p in sampled):
                self.notes.add("environment sky's light-picking weight is the mean of the other emitters' "
                               "(wavetrace weighs it by its power)")
        if self.emitters and not sampled and not self.allow_python:
            for d, _, _ in self.emitters:
                d.pop("sampling_weight", None)
            self.notes.add("without Python plugins every emitter is sampled as a light (Mitsuba's default), where "
                           "wavetrace samples none: a light sample and shadow ray at every diffuse hit")
        elif self.emitters and not sampled:
            # Mitsuba 3.7 refuses a scene whose emitters all have weight 0: a
            # null emitter takes every light sample and returns none.
            self.python_plugins.add("wt_null")
            self.out["null_emitter"] = {"type": "wt_null", "sampling_weight": 1.0}
            if not self.nee:
                self.notes.add("nee 0: every emitter has sampling_weight 0 (pure path tracing, as wavetrace --no-nee)")

    # -- all ----------------------------------------------------------------
    def convert(self):
        self.out["integrator"] = self.integrator()
        self.out["sensor"] = self.camera()
        self.spheres()
        self.meshes()
        self.sky()
        for d, _, _ in self.emitters:
            if d["type"] in ("constant", "envmap"):
                self.out["sky"] = d
        self.emitter_weights()
        if self.needs_volpath:
            # Shadow rays that pass through masks, and media inside volumes: volpath
            # is path's integrator with both (the same depth and roulette).
            self.out["integrator"]["type"] = "volpath"
            self.notes.add("integrator: volpath (masks or absorbing volumes), which is path plus null surfaces in "
                           "shadow rays and media")
        if "spheres" not in self.doc and "instances" not in self.doc:
            raise ConversionError("the scene has no spheres and no instances")
        return self.out


class Conversion:
    def __init__(self, scene, notes, settings, python_plugins):
        self.scene, self.notes, self.settings = scene, notes, settings
        self.python_plugins = sorted(python_plugins)

    def plugins(self):
        """Every plugin type the dict names."""
        found = set()

        def walk(d):
            if isinstance(d, dict):
                if "type" in d and isinstance(d["type"], str) and d["type"] != "ref":
                    found.add(d["type"])
                for v in d.values():
                    walk(v)
        walk(self.scene)
        return sorted(found)


def convert(scene_path, **kw):
    c = Converter(scene_path, **kw)
    scene = c.convert()
    settings = {"width": c.width, "height": c.height, "spp": c.spp, "depth": c.depth,
                "roulette_depth": c.roulette_depth, "seed": c.seed, "nee": c.nee}
    return Conversion(scene, c.notes.list(), settings, c.python_plugins)


# --------------------------------------------------------------------------
# Tile regions: where each placed glTF mesh lands in the image
# --------------------------------------------------------------------------

class Pinhole:
    """wavetrace's pinhole camera (include/wavetrace/camera.hpp): look_from,
    look_at, up, vertical field of view; pixel (x, y) continuous, row 0 at the
    top of the image."""

    def __init__(self, cam, width, height):
        def unit(a):
            n = math.sqrt(sum(x * x for x in a))
            return [x / n for x in a]

        def cross(a, b):
            return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]

        self.origin = [float(x) for x in cam["look_from"]]
        self.w = unit([float(a) - float(b) for a, b in zip(cam["look_from"], cam["look_at"])])
        self.u = unit(cross([float(x) for x in cam.get("up", [0, 1, 0])], self.w))
        self.v = cross(self.w, self.u)
        self.half_h = math.tan(math.radians(float(cam.get("vfov", 40))) / 2)
        self.half_w = self.half_h * width / height
        self.width, self.height = width, height

    def pixel(self, p):
        """(x, y) of world point p, and its depth along the view (> 0: in front)."""
        d = [p[i] - self.origin[i] for i in range(3)]
        x = sum(d[i] * self.u[i] for i in range(3))
        y = sum(d[i] * self.v[i] for i in range(3))
        z = -sum(d[i] * self.w[i] for i in range(3))
        return (0.5 + x / z / (2 * self.half_w)) * self.width, (0.5 - y / z / (2 * self.half_h)) * self.height, z


# Every tile of tools/make_gltf_tiles.cpp fits this box before its placement.
TILE_BOX = ([-0.5, 0.0, -0.5], [0.5, 1.0, 0.5])


def tile_regions(scene_path, width, height, shrink=0.5):
    """Each placed glTF mesh of the scene (a tile): its geometry's bounds (within
    TILE_BOX) placed by the instance and projected through the scene's camera:
    `bbox`, the pixels its box's corners span, and `inner`, that box shrunk
    about the projected centre of the bounds to SHRINK of its width and height,
    so that the ground between tiles weighs little in a tile's mean. The format
    bench/peer_regions.py reads (--regions)."""
    with open(scene_path, encoding="utf-8") as f:
        doc = json.load(f)
    folder = os.path.dirname(os.path.abspath(scene_path))
    cam = Pinhole(doc["camera"], width, height)
    meshes = {m["name"]: m for m in doc.get("meshes", [])}
    notes = Notes()
    bounds = {}
    tiles = []
    for inst in doc.get("instances", []):
        mesh = meshes[inst["mesh"]]
        if os.path.splitext(mesh["file"])[1].lower() not in (".glb", ".gltf"):
            continue
        if mesh["name"] not in bounds:
            parts = read_mesh(os.path.normpath(os.path.join(folder, mesh["file"])), mesh["name"], notes)
            lo = [max(min(p.bounds[0][i] for p in parts), TILE_BOX[0][i]) for i in range(3)]
            hi = [min(max(p.bounds[1][i] for p in parts), TILE_BOX[1][i]) for i in range(3)]
            bounds[mesh["name"]] = (lo, hi)
        lo, hi = bounds[mesh["name"]]
        m = instance_matrix(inst)
        corners = [mat_point(m, [(lo, hi)[(k >> i) & 1][i] for i in range(3)]) for k in range(8)]
        px = [cam.pixel(c) for c in corners]
        if any(z <= 0 for _, _, z in px):
            continue   # behind the camera, at least in part
        cx, cy, _ = cam.pixel(mat_point(m, [0.5 * (a + b) for a, b in zip(lo, hi)]))
        x0, x1 = min(p[0] for p in px), max(p[0] for p in px)
        y0, y1 = min(p[1] for p in px), max(p[1] for p in px)
        hx, hy = 0.5 * shrink * (x1 - x0), 0.5 * shrink * (y1 - y0)

        def clip(v, hi_):
            return int(min(max(v, 0), hi_))

        bbox = [clip(math.floor(x0), width), clip(math.floor(y0), height),
                clip(math.ceil(x1), width), clip(math.ceil(y1), height)]
        inner = [clip(round(cx - hx), width), clip(round(cy - hy), height),
                 clip(round(cx + hx), width), clip(round(cy + hy), height)]
        if inner[2] <= inner[0] or inner[3] <= inner[1]:
            continue   # outside the image
        tiles.append({"name": mesh["name"], "file": mesh["file"], "center_px": [round(cx, 3), round(cy, 3)],
                      "bbox": bbox, "inner": inner})
    return {"scene": os.path.relpath(os.path.abspath(scene_path)), "width": width, "height": height,
            "shrink": shrink, "tiles": tiles}


def cmd_regions(args):
    with open(args.scene, encoding="utf-8") as f:
        r = json.load(f).get("render", {})
    width, height = args.width or int(r.get("width", 640)), args.height or int(r.get("height", 360))
    regions = tile_regions(args.scene, width, height, args.shrink)
    text = json.dumps(regions, indent=1) + "\n"
    if args.output in (None, "-"):
        sys.stdout.write(text)
    else:
        with open(args.output, "w", encoding="utf-8") as f:
            f.write(text)
        print("%s: %d tiles at %d x %d" % (args.output, len(regions["tiles"]), width, height), file=sys.stderr)
    return 0


# --------------------------------------------------------------------------
# Mitsuba: plugins written in Python, loading
# --------------------------------------------------------------------------

def register_python_plugins(mi, dr, names):
    """Registers the Python plugins the dict names (they are traced into the
    kernels like Mitsuba's own: no per-sample Python)."""
    if "wt_checker" in names:
        class Checker(mi.Texture):
            """wavetrace's checker: squares of `size` in x and z of the object-space point."""

            def __init__(self, props):
                mi.Texture.__init__(self, props)
                self.size = props.get("size")
                self.ox = [props.get("ox%d" % k) for k in range(4)]
                self.oz = [props.get("oz%d" % k) for k in range(4)]
                self.even = mi.ScalarColor3f(props.get("even_r"), props.get("even_g"), props.get("even_b"))
                self.odd = mi.ScalarColor3f(props.get("odd_r"), props.get("odd_g"), props.get("odd_b"))

            def eval(self, si, active=True):
                p = si.p
                x = self.ox[0] * p.x + self.ox[1] * p.y + self.ox[2] * p.z + self.ox[3]
                z = self.oz[0] * p.x + self.oz[1] * p.y + self.oz[2] * p.z + self.oz[3]
                parity = mi.Int32(dr.floor(x / self.size)) + mi.Int32(dr.floor(z / self.size))
                return dr.select((parity & 1) != 0, mi.Color3f(self.odd), mi.Color3f(self.even))

            def eval_1(self, si, active=True):
                return dr.mean(self.eval(si, active))

            def mean(self):
                return 0.5 * (sum(self.even) + sum(self.odd)) / 3.0

            def traverse(self, callback):
                pass

            def to_string(self):
                return "WavetraceChecker[size=%g]" % self.size

        mi.register_texture("wt_checker", lambda props: Checker(props))

    if "wt_scale" in names:
        class Scale(mi.Texture):
            """A texture times a constant colour (wavetrace's albedo x texture)."""

            def __init__(self, props):
                mi.Texture.__init__(self, props)
                self.nested = props.get("texture")
                self.factor = mi.ScalarColor3f(props.get("r"), props.get("g"), props.get("b"))

            def eval(self, si, active=True):
                return self.nested.eval(si, active) * mi.Color3f(self.factor)

            def eval_1(self, si, active=True):
                return dr.mean(self.eval(si, active))

            def mean(self):
                return self.nested.mean() * sum(self.factor) / 3.0

            def traverse(self, callback):
                pass

            def to_string(self):
                return "WavetraceScale"

        mi.register_texture("wt_scale", lambda props: Scale(props))

    if "wt_roughness" in names:
        class Roughness(mi.Texture):
            """A roughness texture's effect on alpha (power 2) or on a roughness
            (power 1): scale x clamp(green, 0, 1)^power, at each lookup."""

            def __init__(self, props):
                mi.Texture.__init__(self, props)
                self.nested = props.get("texture")
                self.scale = props.get("scale")
                self.square = props.get("power") == 2.0

            def eval_1(self, si, active=True):
                g = dr.clip(self.nested.eval(si, active)[1], 0.0, 1.0)
                return self.scale * (g * g if self.square else g)

            def eval(self, si, active=True):
                return mi.Color3f(self.eval_1(si, active))

            def mean(self):
                g = min(max(self.nested.mean(), 0.0), 1.0)
                return self.scale * (g * g if self.square else g)

            def traverse(self, callback):
                pass

            def to_string(self):
                return "WavetraceRoughness[scale=%g, power=%d]" % (self.scale, 2 if self.square else 1)

        mi.register_texture("wt_roughness", lambda props: Roughness(props))

    if "wt_channel" in names:
        class Channel(mi.Texture):
            """scale x clamp(one channel of a texture, 0, 1), and where a cutoff is
            given 1 where that is >= cutoff, else 0 (glTF's metallic in blue,
            transmission and clear coat in red, an alpha and its MASK cutoff)."""

            def __init__(self, props):
                mi.Texture.__init__(self, props)
                self.nested = props.get("texture")
                self.channel = int(props.get("channel"))
                self.scale = props.get("scale")
                self.cutoff = props.get("cutoff", -1.0)

            def eval_1(self, si, active=True):
                v = self.scale * dr.clip(self.nested.eval(si, active)[self.channel], 0.0, 1.0)
                if self.cutoff >= 0.0:
                    v = dr.select(v >= self.cutoff, 1.0, 0.0)
                return mi.Float(v)

            def eval(self, si, active=True):
                return mi.Color3f(self.eval_1(si, active))

            def mean(self):
                return self.scale * min(max(self.nested.mean(), 0.0), 1.0)

            def traverse(self, callback):
                pass

            def to_string(self):
                return "WavetraceChannel[channel=%d, scale=%g, cutoff=%g]" % (self.channel, self.scale, self.cutoff)

        mi.register_texture("wt_channel", lambda props: Channel(props))

    if "wt_normal_scale" in names:
        class NormalScale(mi.Texture):
            """A normal map with its x and y scaled by a strength (glTF's
            normalTexture scale), still encoded as c = (n + 1) / 2 for Mitsuba's
            normalmap, which normalises 2 c - 1."""

            def __init__(self, props):
                mi.Texture.__init__(self, props)
                self.nested = props.get("texture")
                self.strength = props.get("strength")

            def eval(self, si, active=True):
                c = self.nested.eval(si, active)
                k = self.strength
                return mi.Color3f(0.5 + k * (c[0] - 0.5), 0.5 + k * (c[1] - 0.5), c[2])

            def eval_3(self, si, active=True):
                # What Mitsuba's normalmap asks of its texture.
                c = self.eval(si, active)
                return mi.Vector3f(c[0], c[1], c[2])

            def eval_1(self, si, active=True):
                return dr.mean(self.eval(si, active))

            def mean(self):
                return self.nested.mean()

            def traverse(self, callback):
                pass

            def to_string(self):
                return "WavetraceNormalScale[strength=%g]" % self.strength

        mi.register_texture("wt_normal_scale", lambda props: NormalScale(props))

    if "wt_null" in names:
        def zeros(cls):
            try:
                return dr.zeros(cls)
            except RuntimeError:  # scalar variants: Mitsuba's records construct as zeros
                return cls()

        class Null(mi.Emitter):
            """Takes the light samples of a scene whose emitters wavetrace does not
            sample, and returns none (Mitsuba 3.7 needs a non-zero total weight)."""

            def __init__(self, props):
                mi.Emitter.__init__(self, props)
                self.m_flags = mi.EmitterFlags.DeltaPosition

            def sample_direction(self, it, sample, active=True):
                return zeros(mi.DirectionSample3f), zeros(mi.Color3f)

            def pdf_direction(self, it, ds, active=True):
                return zeros(mi.Float)

            def eval_direction(self, it, ds, active=True):
                return zeros(mi.Color3f)

            def eval(self, si, active=True):
                return zeros(mi.Color3f)

            def sample_ray(self, time, sample1, sample2, sample3, active=True):
                return zeros(mi.Ray3f), zeros(mi.Color3f)

            def sample_position(self, ref, ds, active=True):
                return zeros(mi.PositionSample3f), zeros(mi.Float)

            def bbox(self):
                return mi.ScalarBoundingBox3f()

            def traverse(self, callback):
                pass

            def to_string(self):
                return "WavetraceNullEmitter"

        mi.register_emitter("wt_null", lambda props: Null(props))


def _bitmap_rows(mi, path, srgb):
    """An image file as linear RGB rows (lists of floats), top first."""
    bmp = mi.Bitmap(path)
    if bmp.component_format() != mi.Struct.Type.Float32 or bmp.pixel_format() != mi.Bitmap.PixelFormat.RGB:
        if bmp.component_format() in (mi.Struct.Type.UInt8, mi.Struct.Type.UInt16):
            bmp.set_srgb_gamma(bool(srgb))
        bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False)
    import drjit as dr
    w, h = bmp.size()
    flat = array.array("f", dr.scalar.TensorXf(bmp).array)   # host memory, whatever the variant
    return w, h, [flat[3 * w * y:3 * w * (y + 1)] for y in range(h)]


def _sample_rows(w, h, rows, u, v):
    """wavetrace's bilinear lookup: u wraps, v clamps, texel centres at half-integers."""
    x = (u - math.floor(u)) * w - 0.5
    y = min(max(v, 0.0), 1.0) * h - 0.5
    fx, fy = math.floor(x), math.floor(y)
    ax, ay = x - fx, y - fy
    x0, y0 = int(fx), int(fy)
    x1, y1 = x0 + 1, y0 + 1
    x0 = x0 + w if x0 < 0 else x0
    x1 = x1 - w if x1 >= w else x1
    y0 = max(y0, 0)
    y1 = min(y1, h - 1)
    out = []
    for ch in range(3):
        top = (1 - ax) * rows[y0][3 * x0 + ch] + ax * rows[y0][3 * x1 + ch]
        bot = (1 - ax) * rows[y1][3 * x0 + ch] + ax * rows[y1][3 * x1 + ch]
        out.append((1 - ay) * top + ay * bot)
    return out


_GREEN_MEANS = {}


def green_mean(mi, path, srgb):
    """The mean over the texels of an image's green channel (linear, clamped to
    [0, 1], as wavetrace reads a roughness texture's)."""
    key = (os.path.abspath(path), bool(srgb))
    if key not in _GREEN_MEANS:
        w, h, rows = _bitmap_rows(mi, path, srgb)
        _GREEN_MEANS[key] = sum(min(max(g, 0.0), 1.0) for row in rows for g in row[1::3]) / (w * h)
    return _GREEN_MEANS[key]


def alpha_image(mi, path):
    """A PFM of an image's alpha channel (grey: the alpha in every channel), as
    stored (alpha is linear in PNG and glTF); 1 where the image has none.
    Mitsuba's bitmap texture keeps colour only, so an opacity reads this."""
    key = _source_key(path, "alpha")
    out = os.path.join(cache_dir(), "alpha-%s.pfm" % key)
    if os.path.exists(out):
        return out
    import drjit as dr
    bmp = mi.Bitmap(path)
    bmp.set_srgb_gamma(False)
    bmp = bmp.convert(mi.Bitmap.PixelFormat.RGBA, mi.Struct.Type.Float32, False)
    w, h = bmp.size()
    flat = array.array("f", dr.scalar.TensorXf(bmp).array)
    rows = []
    for y in range(h):
        a = flat[4 * w * y + 3:4 * w * (y + 1):4]
        row = array.array("f", bytes(12 * w))
        for k in range(3):
            row[k::3] = a
        rows.append(row)
    write_pfm(out, w, h, rows)
    return out


def environment_uv(mapping, e):
    """wavetrace's environment_uv (include/wavetrace/sky.hpp) for a unit direction."""
    x, y, z = e
    if mapping == "angular":
        side = math.sqrt(x * x + y * y)
        if side == 0:
            return (0.5, 0.5) if z <= 0 else (1.0, 0.5)
        r = math.acos(min(max(-z, -1.0), 1.0)) / math.pi / side
        return 0.5 + 0.5 * x * r, 0.5 - 0.5 * y * r
    if mapping == "mirror_ball":
        h = (x, y, z + 1.0)
        ln = math.sqrt(sum(c * c for c in h))
        if ln == 0:
            return 1.0, 0.5
        return 0.5 + 0.5 * h[0] / ln, 0.5 - 0.5 * h[1] / ln
    return (math.atan2(x, -z) / (2 * math.pi)) % 1.0, math.acos(min(max(y, -1.0), 1.0)) / math.pi


def environment_to_latlong(mi, spec):
    """A lat-long PFM (in Mitsuba's envmap row convention) of an environment image."""
    key = _source_key(spec["file"], spec["mapping"], spec["srgb"], RESAMPLED_SKY_ROWS)
    out = os.path.join(cache_dir(), "environment-%s.pfm" % key)
    if os.path.exists(out):
        return out
    w, h, rows = _bitmap_rows(mi, spec["file"], spec["srgb"])
    if spec["mapping"] == "latlong":
        write_pfm(out, w, h, rows)
        return out
    H = RESAMPLED_SKY_ROWS
    W = 2 * H
    result = []
    for i in range(H):
        theta = math.pi * i / (H - 1)
        row = array.array("f")
        for j in range(W):
            phi = 2 * math.pi * (j + 0.5) / W
            d = (math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))
            u, v = environment_uv(spec["mapping"], d)
            row.extend(_sample_rows(w, h, rows, u, v))
        result.append(row)
    write_pfm(out, W, H, result)
    return out


def realize(mi, d):
    """The plain dict with transforms made Mitsuba transforms."""
    if isinstance(d, dict):
        if "__transform__" in d:
            return mi.ScalarTransform4f(mi.ScalarMatrix4f(d["__transform__"]))
        if "__green_mean__" in d:
            spec = d["__green_mean__"]
            return spec["scale"] * green_mean(mi, spec["file"], spec["srgb"]) ** spec["power"]
        if "__alpha_image__" in d:
            return alpha_image(mi, d["__alpha_image__"]["file"])
        out = {}
        for k, v in d.items():
            if k == "__envmap_image__":
                out["filename"] = environment_to_latlong(mi, v)
            else:
                out[k] = realize(mi, v)
        return out
    if isinstance(d, list):
        return [realize(mi, v) for v in d]
    return d


def load_scene(conversion, variant):
    import mitsuba as mi
    import drjit as dr
    if mi.variant() != variant:
        mi.set_variant(variant)
    if isinstance(conversion, XmlScene):
        return mi.load_file(conversion.path, **conversion.defines)
    register_python_plugins(mi, dr, conversion.python_plugins)
    return mi.load_dict(realize(mi, conversion.scene))


# --------------------------------------------------------------------------
# The dict as a Mitsuba XML file (the `xml` command), which wavetrace reads back
# --------------------------------------------------------------------------

# The element each plugin type is written as.
PLUGIN_TAGS = {
    "integrator": ("path", "volpath", "direct"),
    "sensor": ("perspective", "thinlens"),
    "film": ("hdrfilm",),
    "rfilter": ("box", "gaussian"),
    "sampler": ("independent", "stratified", "multijitter"),
    "shape": ("sphere", "obj", "ply", "serialized", "rectangle", "cube", "disk", "cylinder", "shapegroup", "instance"),
    "emitter": ("area", "constant", "envmap", "point", "spot", "directional"),
    "texture": ("bitmap", "checkerboard"),
    "medium": ("homogeneous",),
}


class XmlError(Exception):
    pass


def _xml_number(x):
    return repr(float(x)) if isinstance(x, float) else str(x)


def _xml_attr(text):
    return (str(text).replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;").replace(">", "&gt;"))


def to_xml(scene, base_dir):
    """The converter's dict (Mitsuba's load_dict form) as an XML <scene>, the files it
    names relative to base_dir. Only what XML can say: no Python plugins, no values
    made at load time (XmlError names what is not)."""
    lines = ['<scene version="3.0.0">']

    def tag_of(plugin, key):
        if key == "bsdf" or key.startswith("bsdf"):
            return "bsdf"
        for tag, types in PLUGIN_TAGS.items():
            if plugin in types:
                return tag
        if plugin in ("diffuse", "twosided", "conductor", "roughconductor", "dielectric", "roughdielectric",
                      "thindielectric", "plastic", "roughplastic", "principled", "normalmap", "bumpmap", "mask"):
            return "bsdf"
        raise XmlError("plugin '%s' has no XML form wavetrace reads" % plugin)

    def value(name, v, pad):
        if isinstance(v, bool):
            lines.append('%s<boolean name="%s" value="%s"/>' % (pad, name, "true" if v else "false"))
        elif isinstance(v, int):
            lines.append('%s<integer name="%s" value="%d"/>' % (pad, name, v))
        elif isinstance(v, float):
            lines.append('%s<float name="%s" value="%s"/>' % (pad, name, _xml_number(v)))
        elif isinstance(v, str):
            if name == "filename":
                v = os.path.relpath(v, base_dir) if os.path.isabs(v) else v
            lines.append('%s<string name="%s" value="%s"/>' % (pad, name, _xml_attr(v)))
        elif isinstance(v, dict) and "__transform__" in v:
            rows = v["__transform__"]
            lines.append('%s<transform name="%s"><matrix value="%s"/></transform>'
                         % (pad, name, " ".join(_xml_number(float(x)) for r in rows for x in r)))
        elif isinstance(v, dict) and v.get("type") == "rgb":
            c = v["value"]
            lines.append('%s<rgb name="%s" value="%s"/>' % (pad, name, ", ".join(_xml_number(float(x)) for x in c)))
        elif isinstance(v, dict) and v.get("type") == "ref":
            lines.append('%s<ref id="%s" name="%s"/>' % (pad, _xml_attr(v["id"]), name))
        elif isinstance(v, dict) and "type" in v:
            plugin(name, v, pad)
        else:
            raise XmlError("'%s' (%s) has no XML form" % (name, json.dumps(v)[:80]))

    def plugin(key, d, pad, ident=None):
        t = d["type"]
        tag = tag_of(t, key)
        attrs = 'type="%s"' % t
        if ident:
            attrs += ' id="%s"' % _xml_attr(ident)
        elif tag not in ("bsdf", "shape", "emitter", "film", "sampler", "rfilter", "integrator", "sensor") or \
                (tag == "bsdf" and key != "bsdf"):
            attrs += ' name="%s"' % _xml_attr(key)
        lines.append("%s<%s %s>" % (pad, tag, attrs))
        for k, v in d.items():
            if k == "type" or k == "id":
                continue
            value(k, v, pad + "  ")
        lines.append("%s</%s>" % (pad, tag))

    for key, v in scene.items():
        if key == "type":
            continue
        if not isinstance(v, dict) or "type" not in v:
            raise XmlError("'%s' at the scene's top level is not a plugin" % key)
        tag = tag_of(v["type"], key)
        # Top-level BSDFs and textures are referenced by their key; the rest stand alone.
        plugin(key, v, "  ", ident=key if tag in ("bsdf", "texture", "shape") else None)
    lines.append("</scene>")
    return "\n".join(lines) + "\n"


def write_xml(conv, path, what):
    """The conversion as the Mitsuba XML file `path`, headed by a comment: `what` the
    scene was, and the notes of what does not map exactly. Raises XmlError."""
    text = to_xml(conv.scene, os.path.dirname(os.path.abspath(path)))
    notes = "".join("  - %s\n" % n.replace("--", "- -") for n in conv.notes)
    header = "<!-- %s.%s -->\n" % (what, ("\n  What does not map exactly:\n" + notes) if notes else "")
    _write_atomic(path, (header + text).encode("utf-8"))


def cmd_xml(args):
    conv = convert(args.scene, **convert_kwargs(args))
    if conv.python_plugins:
        print("%s: needs Python plugins (%s), which XML cannot name" % (args.scene, ", ".join(conv.python_plugins)),
              file=sys.stderr)
        return 2
    try:
        write_xml(conv, args.output, "%s as a Mitsuba 3 scene (bench/mitsuba_peer.py xml)" % os.path.basename(args.scene))
    except XmlError as e:
        print("%s: %s" % (args.scene, e), file=sys.stderr)
        return 2
    return 0


# --------------------------------------------------------------------------
# The runner
# --------------------------------------------------------------------------

def device_info(variant):
    info = {"variant": variant}
    if variant.startswith("cuda"):
        try:
            out = subprocess.run(["nvidia-smi", "--query-gpu=name,driver_version", "--format=csv,noheader"],
                                 capture_output=True, text=True, timeout=20)
            if out.returncode == 0 and out.stdout.strip():
                name, driver = [s.strip() for s in out.stdout.strip().splitlines()[0].split(",", 1)]
                info.update({"device": name, "driver": driver})
        except (OSError, subprocess.SubprocessError, ValueError):
            pass
    else:
        info["device"] = platform.processor() or platform.machine()
    return info


def pass_plan(width, height, spp, mode, lane_budget, passes):
    """Samples per pass. Symbolic loops keep a path's state in registers: one
    pass (up to Dr.Jit's 2^32 lanes). Evaluated loops keep it in memory, about
    a hundred bytes and more a lane: passes of at most lane_budget lanes."""
    pixels = width * height
    if passes in (None, "auto"):
        limit = (2 ** 32 - 1) if mode == "symbolic" else lane_budget
        per = max(1, min(spp, limit // pixels))
        n = -(-spp // per)
    else:
        n = max(1, min(int(passes), spp))
    base, extra = divmod(spp, n)
    return [base + (1 if i < extra else 0) for i in range(n)]


def render_once(mi, dr, scene, plan, seed):
    """All passes of one render: the spp-weighted mean of the passes' images."""
    if len(plan) == 1:
        img = mi.render(scene, spp=plan[0], seed=seed)
        dr.eval(img)
        return img
    total = sum(plan)
    acc = None
    for i, spp in enumerate(plan):
        img = mi.render(scene, spp=spp, seed=seed + i)
        acc = img * (spp / total) if acc is None else acc + img * (spp / total)
    dr.eval(acc)
    return acc


def run_mode(mi, dr, scene, conv, mode, args):
    dr.set_flag(dr.JitFlag.SymbolicLoops, mode == "symbolic")
    s = conv.settings
    plan = pass_plan(s["width"], s["height"], s["spp"], mode, args.lane_budget, args.passes)
    dr.sync_thread()
    t0 = time.perf_counter()
    for _ in range(args.warmup):
        render_once(mi, dr, scene, plan, s["seed"])
    dr.sync_thread()
    warmup_seconds = time.perf_counter() - t0
    seconds = []
    img = None
    for _ in range(args.repeats):
        del img
        dr.sync_thread()
        t0 = time.perf_counter()
        img = render_once(mi, dr, scene, plan, s["seed"])
        dr.sync_thread()
        seconds.append(time.perf_counter() - t0)
    kernel = None
    if args.kernel_history and hasattr(dr.JitFlag, "KernelHistory"):
        dr.kernel_history_clear()
        with dr.scoped_set_flag(dr.JitFlag.KernelHistory, True):
            render_once(mi, dr, scene, plan, s["seed"])
            dr.sync_thread()
            hist = dr.kernel_history()
        jit = [h for h in hist if h.get("type") == dr.KernelType.JIT]
        kernel = {"kernels": len(jit), "kernel_seconds": sum(h.get("execution_time", 0.0) for h in hist) / 1000.0}
    return img, plan, warmup_seconds, seconds, kernel


def median(xs):
    ys = sorted(xs)
    n = len(ys)
    return ys[n // 2] if n % 2 else 0.5 * (ys[n // 2 - 1] + ys[n // 2])


class XmlScene:
    """A Mitsuba scene file rendered as it is: its own sensor, film and integrator
    (the spp may be given), read with the parameters `defines`."""

    def __init__(self, path, defines, spp=None, seed=None):
        import xml.etree.ElementTree as ET
        self.path, self.defines = path, defines
        self.notes, self.python_plugins = [], []
        params = {}
        root = ET.parse(path).getroot()
        for d in root.iter("default"):
            params[d.get("name")] = d.get("value")
        params.update(defines)

        def resolve(text):
            return re.sub(r"\$([A-Za-z0-9_]+)", lambda m: params.get(m.group(1), m.group(0)), text or "")

        def number(parent, kind, name, default):
            for e in parent.iter(kind):
                if e.get("name") == name:
                    return int(float(resolve(e.get("value"))))
            return default
        film = next(root.iter("film"), None)
        sampler = next(root.iter("sampler"), None)
        integrator = next(root.iter("integrator"), None)
        depth = -1
        if integrator is not None:
            depth = 2 if integrator.get("type") == "direct" else number(integrator, "integer", "max_depth", -1)
        self.settings = {
            "width": number(film, "integer", "width", 768) if film is not None else 768,
            "height": number(film, "integer", "height", 576) if film is not None else 576,
            "spp": spp or (number(sampler, "integer", "sample_count", 4) if sampler is not None else 4),
            "depth": depth,
            "roulette_depth": number(integrator, "integer", "rr_depth", 5) if integrator is not None else 5,
            "seed": seed or 0, "nee": 1}


def cmd_render(args):
    if args.scene.lower().endswith(".xml"):
        conv = XmlScene(args.scene, dict(d.split("=", 1) for d in (args.define or [])), args.spp, args.seed)
    else:
        conv = convert(args.scene, **convert_kwargs(args))
    for n in conv.notes:
        print("note: " + n, file=sys.stderr)
    import mitsuba as mi
    import drjit as dr
    t0 = time.perf_counter()
    mi.set_variant(args.variant)
    scene = load_scene(conv, args.variant)
    dr.sync_thread()
    load_seconds = time.perf_counter() - t0
    s = conv.settings
    paths = s["width"] * s["height"] * s["spp"]
    modes = ["symbolic", "evaluated"] if args.mode == "both" else [args.mode]
    records = []
    for mode in modes:
        img, plan, warm, seconds, kernel = run_mode(mi, dr, scene, conv, mode, args)
        med = median(seconds)
        rec = {
            "renderer": "mitsuba3",
            "scene": os.path.relpath(os.path.abspath(args.scene)),
            "width": s["width"], "height": s["height"], "spp": s["spp"], "depth": s["depth"],
            "roulette_depth": s["roulette_depth"], "seed": s["seed"], "nee": s["nee"],
            "mode": mode, "variant": args.variant, "passes": plan,
            "warmup": args.warmup, "warmup_seconds": warm, "repeats": args.repeats,
            "seconds": seconds, "median_seconds": med, "m_paths_per_s": paths / med / 1e6,
            "load_seconds": load_seconds,
            "notes": conv.notes, "python_plugins": conv.python_plugins,
            "mitsuba_version": mi.__version__, "drjit_version": dr.__version__,
            "python": platform.python_version(),
            "time": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        }
        rec.update(device_info(args.variant))
        if kernel:
            rec.update(kernel)
        if args.output:
            base = "%s-%s" % (args.output, mode)
            os.makedirs(os.path.dirname(os.path.abspath(base)), exist_ok=True)
            mi.util.write_bitmap(base + ".exr", img)
            mi.util.write_bitmap(base + ".png", img)
            # RGB floats for readers without OpenEXR (bench/mitsuba_xml_tables.py).
            mi.Bitmap(img, mi.Bitmap.PixelFormat.RGB).write(base + ".pfm")
            rec["images"] = [base + ".exr", base + ".png", base + ".pfm"]
        print("%s %s %dx%d %d spp depth %d: %s s (median %.4f s), %.1f M paths/s"
              % (os.path.basename(args.scene), mode, s["width"], s["height"], s["spp"], s["depth"],
                 " ".join("%.4f" % x for x in seconds), med, paths / med / 1e6))
        records.append(rec)
        del img
    if args.json:
        existing = []
        if os.path.exists(args.json):
            with open(args.json, encoding="utf-8") as f:
                existing = json.load(f)
        existing.extend(records)
        tmp = args.json + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            json.dump(existing, f, indent=1)
            f.write("\n")
        os.replace(tmp, args.json)
    return 0


def cmd_convert(args):
    conv = convert(args.scene, **convert_kwargs(args))
    print(json.dumps({"settings": conv.settings, "plugins": conv.plugins(), "python_plugins": conv.python_plugins,
                      "scene": conv.scene}, indent=1))
    print("could not map (%d):" % len(conv.notes), file=sys.stderr)
    for n in conv.notes:
        print("  - " + n, file=sys.stderr)
    return 0


def convert_kwargs(args):
    return {"width": args.width, "height": args.height, "spp": args.spp, "depth": args.depth,
            "roulette_depth": args.roulette_depth, "seed": args.seed, "nee": args.nee,
            "instancing": args.instancing, "sky_sampling": args.sky_sampling,
            "python_plugins": not args.no_python_plugins}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("regions", help="each placed glTF mesh's pixel box (peer_regions.py --regions)")
    p.add_argument("scene")
    p.add_argument("--width", type=int)
    p.add_argument("--height", type=int)
    p.add_argument("--shrink", type=float, default=0.5,
                   help="the inner box's share of the tile's projected box, about its centre (default 0.5)")
    p.add_argument("-o", "--output", help="the regions file (default: stdout)")
    for name in ("convert", "render", "xml"):
        p = sub.add_parser(name)
        p.add_argument("scene")
        if name == "xml":
            p.add_argument("-o", "--output", required=True, help="the Mitsuba scene to write (.xml)")
        if name == "render":
            p.add_argument("-D", "--define", action="append",
                           help="a parameter of an .xml scene, name=value (the file itself is rendered)")
        p.add_argument("--width", type=int)
        p.add_argument("--height", type=int)
        p.add_argument("--spp", type=int)
        p.add_argument("--depth", type=int)
        p.add_argument("--roulette-depth", type=int)
        p.add_argument("--seed", type=int)
        p.add_argument("--nee", type=int, choices=(0, 1))
        p.add_argument("--instancing", action="store_true",
                       help="share a mesh placed more than once through a Mitsuba shapegroup (default: every "
                            "placement is a shape of its own; see the note the conversion prints)")
        p.add_argument("--no-python-plugins", action="store_true",
                       help="only Mitsuba's own plugins: checker -> mean colour, no albedo x image, and the sky "
                            "sampled as a light even where wavetrace does not sample it (notes say so)")
        p.add_argument("--sky-sampling", choices=("auto", "always"), default="auto",
                       help="auto: the sky is a sampled light where wavetrace samples it (not the gradient)")
        if name == "render":
            p.add_argument("--mode", choices=("symbolic", "evaluated", "both"), default="both")
            p.add_argument("--variant", default="cuda_ad_rgb")
            p.add_argument("-o", "--output", help="image prefix: PREFIX-MODE.exr and .png")
            p.add_argument("--json", help="append a record per mode to this JSON list")
            p.add_argument("--warmup", type=int, default=1)
            p.add_argument("--repeats", type=int, default=3)
            p.add_argument("--passes", default="auto", help="render passes per image (auto: see pass_plan)")
            p.add_argument("--lane-budget", type=int, default=2 ** 26,
                           help="most samples a pass of the evaluated mode holds (default 2^26)")
            p.add_argument("--kernel-history", action="store_true",
                           help="one more render with Dr.Jit's kernel history: kernel count and device seconds")
    args = ap.parse_args(argv)
    try:
        if args.command == "regions":
            return cmd_regions(args)
        if args.command == "xml":
            return cmd_xml(args)
        return cmd_convert(args) if args.command == "convert" else cmd_render(args)
    except ConversionError as e:
        print("%s: %s" % (args.scene, e), file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
