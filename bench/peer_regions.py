#!/usr/bin/env python3
"""Compares a wavetrace render with the Mitsuba peer's render of the same scene,
sphere by sphere (the regions tools/make_materials.py writes) or over the whole
image, and writes them side by side with their difference.

    peer_regions.py WAVETRACE.pfm PEER.exr [--regions REGIONS.json] [--png OUT.png]
                    [--json OUT.json] [--bound 0.01]

Each sphere's (and the plane's, or each glTF tile's: bench/mitsuba_peer.py
regions) mean over its `inner` box (every pixel inside
the silhouette), both images' channel means, and the relative difference
(wavetrace - peer) / peer.
The noise of that difference is estimated from the 2 x 2 blocks of the box: the
standard error of the block means' differences, an upper bound where the shading
varies inside a block. --bound marks the spheres whose |difference| exceeds it.
The PNG: wavetrace | peer | difference (red where wavetrace is brighter, blue
where darker, full scale at +-10%), sRGB-encoded, clamped.

Needs numpy, and Mitsuba 3 (mitsuba.Bitmap) to read EXR files.
"""
import argparse
import json
import sys

import numpy as np


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind not in (b"PF", b"Pf"):
            raise SystemExit("%s: not a PFM file" % path)
        width, height = (int(x) for x in f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    channels = 3 if kind == b"PF" else 1
    image = data.reshape(height, width, channels).astype(np.float64)
    return image[::-1]  # PFM rows run bottom to top


def read_image(path):
    if path.lower().endswith(".pfm"):
        return read_pfm(path)
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    return np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False),
                    dtype=np.float64)


def block_error(a, b):
    """The standard error of mean(a - b) over a box, from its 2 x 2 blocks."""
    h, w = (a.shape[0] // 2) * 2, (a.shape[1] // 2) * 2
    d = (a[:h, :w] - b[:h, :w]).mean(axis=2)
    blocks = d.reshape(h // 2, 2, w // 2, 2).mean(axis=(1, 3)).ravel()
    return blocks.std(ddof=1) / np.sqrt(blocks.size) if blocks.size > 1 else float("nan")


def srgb(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def write_png(path, wt, peer):
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    mean = np.maximum(peer.mean(axis=2), 1e-6)
    rel = np.clip((wt.mean(axis=2) - peer.mean(axis=2)) / mean / 0.1, -1.0, 1.0)
    diff = np.stack([np.maximum(rel, 0), np.zeros_like(rel), np.maximum(-rel, 0)], axis=2)
    sheet = np.concatenate([srgb(wt), srgb(peer), diff], axis=1)
    bitmap = mi.Bitmap(np.ascontiguousarray(sheet, dtype=np.float32), mi.Bitmap.PixelFormat.RGB)
    bitmap.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, False).write(path)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("wavetrace")
    p.add_argument("peer")
    p.add_argument("--regions", help="tools/make_materials.py --regions or bench/mitsuba_peer.py regions output "
                                     "for this size")
    p.add_argument("--png")
    p.add_argument("--json")
    p.add_argument("--bound", type=float, default=0.01)
    a = p.parse_args(argv)
    wt, peer = read_image(a.wavetrace), read_image(a.peer)
    if wt.shape != peer.shape:
        raise SystemExit("the images differ in size: %s and %s" % (wt.shape, peer.shape))
    rows = []
    if a.regions:
        with open(a.regions) as f:
            regions = json.load(f)
        if (regions["width"], regions["height"]) != (wt.shape[1], wt.shape[0]):
            raise SystemExit("%s is for %d x %d, the images are %d x %d" % (
                a.regions, regions["width"], regions["height"], wt.shape[1], wt.shape[0]))
        # make_materials.py's spheres and planes (named by material), or
        # mitsuba_peer.py regions' tiles (by mesh).
        boxes = [(s.get("material") or s["name"], s["inner"])
                 for s in regions.get("spheres", []) + regions.get("planes", []) + regions.get("tiles", [])]
    else:
        boxes = [("image", [0, 0, wt.shape[1], wt.shape[0]])]
    for name, (x0, y0, x1, y1) in boxes:
        aw, ap = wt[y0:y1, x0:x1], peer[y0:y1, x0:x1]
        mw, mp = aw.mean(), ap.mean()
        rel = (mw - mp) / mp if mp > 0 else float("nan")
        err = block_error(aw, ap) / mp if mp > 0 else float("nan")
        rows.append({"region": name, "wavetrace": mw, "peer": mp, "relative": rel, "error": err})
    print("%-28s %10s %10s %9s %9s" % ("region", "wavetrace", "peer", "diff", "+-"))
    over = 0
    for r in rows:
        flag = " *" if abs(r["relative"]) > a.bound else ""
        over += bool(flag)
        print("%-28s %10.5f %10.5f %+8.3f%% %8.3f%%%s" % (r["region"], r["wavetrace"], r["peer"],
                                                        100 * r["relative"], 100 * r["error"], flag))
    print("%d of %d regions differ by more than %.1f%%" % (over, len(rows), 100 * a.bound))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    if a.png:
        write_png(a.png, wt, peer)
    return 0


if __name__ == "__main__":
    sys.exit(main())
