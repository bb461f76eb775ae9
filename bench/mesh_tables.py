#!/usr/bin/env python3
"""Tables of the mesh benchmark: counted rays per second per scene and kernel, over
whole paths (depth 16) and primary rays alone (depth 1), with each scene's
geometry (triangles stored and placed, BVH build time and SAH cost), and for the
scenes with emitters the shadow rays of light sampling, counted apart.

    python3 bench/mesh_tables.py RESULTS.json [RESULTS.json ...] > tables.md
"""
import json
import sys


def main():
    rows = []
    for path in sys.argv[1:]:
        with open(path) as f:
            rows += json.load(f)["points"]
    scenes = []
    for r in rows:
        if r["group"] not in scenes:
            scenes.append(r["group"])
    kernels = []
    for r in rows:
        if r["kernel"] not in kernels:
            kernels.append(r["kernel"])
    print("| scene | triangles stored | placed | BVH build s | SAH cost (largest mesh) |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for s in scenes:
        g = next((r for r in rows if r["group"] == s and r.get("status") == "ok"), None)
        if not g:
            continue
        geo = g["geometry"]
        largest = max(geo["meshes"], key=lambda m: m["triangles"]) if geo["meshes"] else None
        print("| %s | %d | %d | %.3f | %s |" % (s, geo["triangles"], geo["instanced_triangles"],
                                              g["load_seconds"]["bvh_build"],
                                              "%.1f" % largest["bvh"]["sah_cost"] if largest else "-"))
    print()
    for label, depth in (("whole paths (depth 16)", lambda d: d > 1), ("primary rays (depth 1)", lambda d: d == 1)):
        print("M counted rays/s, %s, 1920x1080, 64 spp, median of 3:" % label)
        print()
        table(rows, scenes, kernels, depth, lambda r: "%.0f" % r["m_rays_per_s"])
    # Light sampling's shadow rays (not in the counts above), where a scene has them.
    lit = [s for s in scenes if any(r["group"] == s and r.get("shadow_rays", 0) > 0 for r in rows)]
    if lit:
        print("Light sampling, whole paths: M shadow rays/s (apart from the path rays above), and shadow rays per path ray:")
        print()
        table(rows, lit, kernels, lambda d: d > 1,
              lambda r: "%.0f (%.2f)" % (r.get("m_shadow_rays_per_s", 0.0), r.get("shadow_rays", 0) / r["rays"]))


def table(rows, scenes, kernels, depth, value):
    """One row per scene, one column per kernel: value(row) of the point at a depth
    depth() accepts; "-" where there is none, the reason where it did not run."""
    print("| scene | " + " | ".join(kernels) + " |")
    print("| --- |" + " ---: |" * len(kernels))
    for s in scenes:
        cells = []
        for k in kernels:
            r = next((r for r in rows if r["group"] == s and r["kernel"] == k and depth(r["depth"])), None)
            if r is None:
                cells.append("-")
            elif r["status"] != "ok":
                cells.append("refused" if "constant memory" in r["status"] else r["status"][:30])
            else:
                cells.append(value(r))
        print("| %s | %s |" % (s, " | ".join(cells)))
    print()


if __name__ == "__main__":
    main()
