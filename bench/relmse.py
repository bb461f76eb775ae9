#!/usr/bin/env python3
"""Relative mean squared error of PFM images against a reference PFM.

    bench/relmse.py REFERENCE.pfm IMAGE.pfm [IMAGE.pfm ...]

prints, for each image, mean over pixels and channels of (x - r)^2 / (r^2 + 0.01):
the error measure of the adaptive-sampling results in bench/RESULTS.md (relative,
so that bright and dark regions weigh alike, with 0.01 keeping black pixels finite).
Pure Python (no numpy), so that it runs on the lent GPU machine as it is.
"""
import array
import sys


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind != b"PF":
            sys.exit(f"{path}: not a 3-channel PFM")
        w, h = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        data = array.array("f")
        data.frombytes(f.read())
        if scale > 0:
            data.byteswap()
        if len(data) != w * h * 3:
            sys.exit(f"{path}: {len(data)} values for {w} x {h} x 3")
        return w, h, data


def relmse(ref, img):
    total = 0.0
    for r, x in zip(ref, img):
        d = x - r
        total += d * d / (r * r + 0.01)
    return total / len(ref)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    w, h, ref = read_pfm(sys.argv[1])
    for path in sys.argv[2:]:
        iw, ih, img = read_pfm(path)
        if (iw, ih) != (w, h):
            sys.exit(f"{path}: {iw} x {ih}, the reference is {w} x {h}")
        print(f"{path} {relmse(ref, img):.6g}")


if __name__ == "__main__":
    main()
