#!/usr/bin/env python3
"""Light sampling against pure path tracing at equal time, from the renders that
scripts/nee-efficiency.sh makes: each render's mean squared error against the
scene's high-sample reference, its GPU seconds, and the error each would have at
the other's time (error falls as 1 / time for an unbiased estimator, so
MSE x seconds is a render's constant at any sample count).

    python3 bench/nee_efficiency.py RESULTS_DIR > table.md
"""
import json
import struct
import sys
from pathlib import Path


def read_pfm(path):
    data = Path(path).read_bytes()
    header, dims, scale, body = data.split(b"\n", 3)
    if header != b"PF":
        raise SystemExit(f"{path}: not a colour PFM")
    width, height = (int(v) for v in dims.split())
    little = float(scale) < 0
    values = struct.unpack(("<" if little else ">") + "%df" % (width * height * 3), body[: width * height * 12])
    return width, height, values


def mse(a, b):
    return sum((x - y) ** 2 for x, y in zip(a, b)) / len(a)


def main():
    out = Path(sys.argv[1])
    rows = []
    for ref in sorted(out.glob("*-reference.pfm")):
        scene = ref.name[: -len("-reference.pfm")]
        _, _, reference = read_pfm(ref)
        by_mode = {}
        for mode in ("nee", "pt"):
            for pfm in sorted(out.glob(f"{scene}-{mode}-*.pfm")):
                spp = int(pfm.stem.rsplit("-", 1)[1])
                stats = json.loads(pfm.with_suffix(".json").read_text())
                _, _, image = read_pfm(pfm)
                e = mse(image, reference)
                by_mode.setdefault(mode, []).append((spp, stats["seconds"], e, stats.get("shadow_rays", 0),
                                                     stats["rays"]))
        print(f"### {scene}\n")
        print("| mode | spp | GPU seconds | path rays | shadow rays | MSE vs reference | MSE x seconds |")
        print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
        for mode, label in (("pt", "path tracing"), ("nee", "light sampling + MIS")):
            for spp, seconds, e, shadows, rays in sorted(by_mode.get(mode, [])):
                print(f"| {label} | {spp} | {seconds:.4f} | {rays} | {shadows} | {e:.4e} | {e * seconds:.3e} |")
        if "pt" in by_mode and "nee" in by_mode:
            pt = max(by_mode["pt"])  # the highest sample count: the steadiest estimate
            nee = max(by_mode["nee"])
            ratio = (pt[2] * pt[1]) / (nee[2] * nee[1])
            rows.append((scene, ratio))
            print(f"\nAt equal time light sampling's MSE is {ratio:.1f}x lower (MSE x seconds, {pt[0]} spp "
                  f"path tracing against {nee[0]} spp light sampling).\n")
        else:
            print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
