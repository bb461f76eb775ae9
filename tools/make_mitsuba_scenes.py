#!/usr/bin/env python3
"""The Mitsuba 3 scenes of scenes/mitsuba/ (docs/scenes.md, "Mitsuba 3 scenes"):

- the project's mesh and material scenes whose models Mitsuba has, written as
  Mitsuba XML by bench/mitsuba_peer.py's converter (the round trip: wavetrace reads
  them back), their mesh parts in scenes/mitsuba/meshes/ under names of their own;
- the meshes of showcase.xml, a scene written by hand in Mitsuba's idiom: a rock as
  Mitsuba's .serialized (two shapes in one file) and a tree's trunk and leaves as
  PLY (binary and ASCII), written by tools/meshfile.py's writers.

    python3 tools/make_mitsuba_scenes.py

Plain python3; deterministic (run twice, the same bytes).
"""

import json
import os
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "bench"))

import meshfile  # noqa: E402

OUT = os.path.join(ROOT, "scenes", "mitsuba")
MESHES = os.path.join(OUT, "meshes")

# The scenes written by the round trip: those whose every material and sky is a
# model Mitsuba has (the others need the peer's Python plugins, or hold the study's
# fuzzy metal, which Mitsuba can only approximate: glossy-lights).
ROUND_TRIP = ("cornell-box", "cornell-materials-single", "bump-single")


def round_trip(name, cache):
    import mitsuba_peer as mp
    conv = mp.convert(os.path.join(ROOT, "scenes", name + ".json"))
    if conv.python_plugins:
        raise SystemExit("%s: needs Python plugins %s" % (name, conv.python_plugins))
    # The converter's cache files under names of this scene's own, in the order met.
    renamed = {}

    def walk(d):
        if isinstance(d, dict):
            for k, v in d.items():
                if k == "filename" and isinstance(v, str) and os.path.dirname(os.path.abspath(v)) == cache:
                    if v not in renamed:
                        target = os.path.join(MESHES, "%s-%d%s" % (name, len(renamed) + 1, os.path.splitext(v)[1]))
                        shutil.copyfile(v, target)
                        renamed[v] = target
                    d[k] = renamed[v]
                else:
                    walk(v)
        elif isinstance(d, list):
            for v in d:
                walk(v)
    walk(conv.scene)
    mp.write_xml(conv, os.path.join(OUT, name + ".xml"),
                 "scenes/%s.json as a Mitsuba 3 scene, written by tools/make_mitsuba_scenes.py through "
                 "bench/mitsuba_peer.py's converter" % name)


def showcase_meshes():
    # A rock (two shapes in one .serialized file: the rock, and a pebble), smooth
    # normals and UVs; single precision.
    verts, faces = meshfile.displaced_sphere(4, 7, 0.25, 1.6, squash=(1.0, 0.7, 1.0))
    normals = meshfile.vertex_normals(verts, faces)
    uvs = meshfile.spherical_uvs(verts)
    pverts, pfaces = meshfile.displaced_sphere(2, 3, 0.2, 2.0, squash=(1.0, 0.6, 0.8), radius=0.35)
    meshfile.write_serialized(os.path.join(MESHES, "showcase-rocks.serialized"), [
        {"name": "rock", "positions": verts, "triangles": faces, "normals": normals, "uvs": uvs},
        {"name": "pebble", "positions": pverts, "triangles": pfaces, "normals": meshfile.vertex_normals(pverts, pfaces)},
    ])
    # A tree: its blobs of leaves as binary PLY with normals, its trunk as ASCII PLY
    # without (flat shaded).
    parts = meshfile.tree_parts(seed=3, blob_subdivisions=3)
    for part, name, binary in ((parts[0], "showcase-trunk.ply", False), (parts[1], "showcase-leaves.ply", True)):
        p, ind = part.positions, part.indices
        positions = [(p[3 * i], p[3 * i + 1], p[3 * i + 2]) for i in range(len(p) // 3)]
        triangles = [(ind[3 * i], ind[3 * i + 1], ind[3 * i + 2]) for i in range(len(ind) // 3)]
        normals = None
        if binary:
            n = part.normals
            normals = [(n[3 * i], n[3 * i + 1], n[3 * i + 2]) for i in range(len(n) // 3)]
        meshfile.write_ply(os.path.join(MESHES, name), positions, triangles, normals=normals, binary=binary)


def main():
    os.makedirs(MESHES, exist_ok=True)
    for f in os.listdir(MESHES):
        os.remove(os.path.join(MESHES, f))
    with tempfile.TemporaryDirectory() as cache:
        os.environ["WAVETRACE_PEER_CACHE"] = cache
        for name in ROUND_TRIP:
            round_trip(name, os.path.realpath(cache))
    showcase_meshes()
    print("scenes/mitsuba: %s, showcase.xml's meshes" % ", ".join(n + ".xml" for n in ROUND_TRIP))


if __name__ == "__main__":
    main()
