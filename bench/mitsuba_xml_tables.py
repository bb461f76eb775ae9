#!/usr/bin/env python3
"""The Mitsuba scenes' comparison (bench/mitsuba_xml.sh's output): for each scene
of scenes/mitsuba/, wavetrace's image and Mitsuba's of the same file, the mean
relative difference of the whole image and the largest of its 4 x 4 regions', and
both renderers' M paths/s; and a picture per scene: wavetrace | Mitsuba | the
difference (|a - b| per pixel, times 4, on the images' sRGB scale).

    /usr/bin/python3 bench/mitsuba_xml_tables.py RUN_DIR OUT_DIR

RUN_DIR: bench/mitsuba_xml.sh's OUT_DIR (wt/, peer/). OUT_DIR gets mitsuba-xml.tsv,
<scene>.jpg and the table as Markdown on stdout. Needs numpy and PIL (Debian's
python3-numpy, python3-pil).
"""

import json
import os
import sys

import numpy as np
from PIL import Image

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import relmse  # noqa: E402


def read_pfm(path):
    w, h, data = relmse.read_pfm(path)
    return np.frombuffer(data, dtype=np.float32).reshape(h, w, 3)[::-1].astype(np.float64)  # rows bottom to top


def srgb8(img):
    c = np.clip(img, 0, 1)
    c = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    return (c * 255 + 0.5).astype(np.uint8)


def main(run, out):
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(run, "peer", "results.json")) as f:
        peer = {os.path.splitext(os.path.basename(r["scene"]))[0]: r for r in json.load(f)}
    rows = []
    for name in sorted(peer):
        rec = peer[name]
        mi = read_pfm(os.path.join(run, "peer", name + "-symbolic.pfm"))
        row = {"scene": name, "width": rec["width"], "height": rec["height"], "spp": rec["spp"],
               "mitsuba_m_paths_per_s": rec["m_paths_per_s"], "mitsuba_seconds": rec["median_seconds"]}
        for kernel in ("megakernel", "wavefront"):
            with open(os.path.join(run, "wt", "%s-%s.json" % (name, kernel))) as f:
                stats = json.load(f)
            row[kernel + "_m_paths_per_s"] = stats["m_paths_per_s"]
            row[kernel + "_seconds"] = stats["seconds"]
            row["warnings"] = len(stats.get("scene_warnings", []))
        wt = read_pfm(os.path.join(run, "wt", name + "-wavefront.pfm"))
        a, b = wt.mean(axis=2), mi.mean(axis=2)
        row["mean_wavetrace"], row["mean_mitsuba"] = a.mean(), b.mean()
        row["mean_rel_diff"] = (a.mean() - b.mean()) / b.mean()
        h, w = a.shape
        worst = 0.0
        for i in range(4):
            for j in range(4):
                ra = a[i * h // 4:(i + 1) * h // 4, j * w // 4:(j + 1) * w // 4].mean()
                rb = b[i * h // 4:(i + 1) * h // 4, j * w // 4:(j + 1) * w // 4].mean()
                if rb > 0.02 * b.mean():
                    worst = max(worst, abs(ra - rb) / rb)
        row["worst_region_rel_diff"] = worst
        diff = np.abs(wt - mi).mean(axis=2, keepdims=True).repeat(3, axis=2) * 4
        side = np.concatenate([srgb8(wt), srgb8(mi), srgb8(diff)], axis=1)
        Image.fromarray(side).save(os.path.join(out, name + ".jpg"), quality=90)
        rows.append(row)
    keys = list(rows[0].keys())
    with open(os.path.join(out, "mitsuba-xml.tsv"), "w") as f:
        f.write("\t".join(keys) + "\n")
        for r in rows:
            f.write("\t".join(("%.6g" % r[k]) if isinstance(r[k], float) else str(r[k]) for k in keys) + "\n")
    print("| scene | size, spp | mean relative difference | worst 4x4 region | megakernel M paths/s | "
          "wavefront M paths/s | Mitsuba M paths/s | warnings |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        print("| %s | %dx%d, %d | %+.2f%% | %.2f%% | %.1f | %.1f | %.1f | %d |"
              % (r["scene"], r["width"], r["height"], r["spp"], 100 * r["mean_rel_diff"],
                 100 * r["worst_region_rel_diff"], r["megakernel_m_paths_per_s"], r["wavefront_m_paths_per_s"],
                 r["mitsuba_m_paths_per_s"], r["warnings"]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
