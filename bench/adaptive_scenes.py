#!/usr/bin/env python3
"""Time to a clean image on every shipped scene (bench/RESULTS.md, issue 25).

    bench/adaptive_scenes.py WAVETRACE OUT_DIR [SCENE.json ...]

For each scene (default: every scenes/*.json), at about 640 x 360 pixels in the
scene's own aspect, on the CUDA backend:
  - a 16384-spp uniform reference (wavefront, seed 99);
  - uniform 1024 spp, wavefront and megakernel;
  - adaptive sampling at T 0.1, 0.05, 0.03, 0.02 (at most 4096 spp), the wavefront,
    and T 0.05 on the megakernel too;
  - adaptive T 0.1 denoised, and uniform 16 and 64 spp denoised (OIDN on the GPU);
and writes OUT_DIR/adaptive_scenes.tsv: scene, size, render, kernel, mean spp,
render seconds (CUDA events; an adaptive render's rounds summed), the first-surface
pass's seconds and OIDN's (denoised rows), relMSE against the reference
(bench/relmse.py's measure). Where numpy and Pillow are present (the GPU machine's
Python has both) it also writes OUT_DIR/pictures/SCENE.png: uniform 64 spp, adaptive
T 0.05, uniform 64 denoised and the reference side by side (sRGB, clipped), and the
adaptive render's samples per pixel as a heat map (log scale, 16 to 4096).
A scene that fails to render is a row saying so; the others go on.
"""
import json
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from relmse import read_pfm, relmse  # noqa: E402

PIXELS = int(os.environ.get("ADAPTIVE_BENCH_PIXELS", 640 * 360))
BACKEND = os.environ.get("ADAPTIVE_BENCH_BACKEND", "cuda")  # cpu: a smoke run of the script itself
SPP_DIVISOR = int(os.environ.get("ADAPTIVE_BENCH_SPP_DIVISOR", 1))
THRESHOLDS = [0.1, 0.05, 0.03, 0.02]


def size_of(scene):
    with open(scene) as f:
        r = json.load(f).get("render", {})
    w, h = r.get("width", 640), r.get("height", 360)
    s = math.sqrt(PIXELS / (w * h))
    return max(8, round(w * s / 8) * 8), max(8, round(h * s / 8) * 8)


def render(wt, scene, out, name, size, args):
    stats = os.path.join(out, name + ".json")
    cmd = [wt, "render", scene, "-o", os.path.join(out, name + ".pfm"), "--backend", BACKEND, "--width",
           str(size[0]), "--height", str(size[1]), "-q", "--warmup", "1", "--stats", stats] + args
    if SPP_DIVISOR > 1:
        i = cmd.index("--spp") + 1
        cmd[i] = str(max(16, int(cmd[i]) // SPP_DIVISOR))
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(p.stderr.strip().splitlines()[-1] if p.stderr.strip() else f"exit {p.returncode}")
    with open(stats) as f:
        return json.load(f)


def pictures(out, scene_name, size):
    try:
        import numpy as np
        from PIL import Image
    except ImportError:
        return "no numpy/Pillow"

    def image(name):
        w, h, data = read_pfm(os.path.join(out, name + ".pfm"))
        a = np.frombuffer(data.tobytes(), dtype=np.float32).reshape(h, w, 3)[::-1]  # PFM rows run bottom up
        a = np.clip(a, 0.0, 1.0)
        a = np.where(a <= 0.0031308, 12.92 * a, 1.055 * np.power(a, 1 / 2.4) - 0.055)
        return (a * 255 + 0.5).astype(np.uint8)

    def heat(name):
        with open(os.path.join(out, name), "rb") as f:
            assert f.readline().strip() == b"Pf"
            w, h = (int(v) for v in f.readline().split())
            scale = float(f.readline())
            v = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4").reshape(h, w)[::-1]
        t = np.clip((np.log2(np.maximum(v, 1)) - 4) / 8, 0, 1)  # 16 .. 4096 spp
        # A dark-blue to yellow ramp through magenta: a few hand-placed stops.
        stops = np.array([[13, 8, 135], [126, 3, 168], [204, 71, 120], [248, 149, 64], [240, 249, 33]], float)
        x = t * (len(stops) - 1)
        i = np.minimum(x.astype(int), len(stops) - 2)
        f = (x - i)[..., None]
        return (stops[i] * (1 - f) + stops[i + 1] * f).astype(np.uint8)

    panels = [image("u64.noisy"), image("a0.05"), image("u64"), image("ref"), heat("a0.05.spp.pfm")]
    gap = np.full((size[1], 4, 3), 255, np.uint8)
    row = panels[0]
    for p in panels[1:]:
        row = np.concatenate([row, gap, p], axis=1)
    folder = os.path.join(out, "..", "..", "pictures")  # OUT_DIR/pictures
    os.makedirs(folder, exist_ok=True)
    Image.fromarray(row).save(os.path.join(folder, scene_name + ".png"), optimize=True)
    return "ok"


def main():
    wt, out_root = sys.argv[1], sys.argv[2]
    scenes = sys.argv[3:] or sorted(os.path.join("scenes", f) for f in os.listdir("scenes") if f.endswith(".json"))
    os.makedirs(out_root, exist_ok=True)
    tsv = open(os.path.join(out_root, "adaptive_scenes.tsv"), "w")
    tsv.write("scene\tsize\trender\tkernel\tmean_spp\tseconds\tguide_seconds\toidn_seconds\trelmse\n")
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        out = os.path.join(out_root, "work", name)
        os.makedirs(out, exist_ok=True)
        size = size_of(scene)
        tag = f"{size[0]}x{size[1]}"
        try:
            render(wt, scene, out, "ref", size, ["--kernel", "wavefront", "--spp", "16384", "--seed", "99"])
            _, _, ref = read_pfm(os.path.join(out, "ref.pfm"))
            runs = [("uniform 1024", "wavefront", "u1024", ["--spp", "1024"]),
                    ("uniform 1024", "megakernel", "u1024m", ["--spp", "1024"])]
            for t in THRESHOLDS:
                runs.append((f"adaptive T {t}", "wavefront", f"a{t}",
                             ["--spp", "4096", "--noise-threshold", str(t), "--aov", "spp"]))
            runs.append(("adaptive T 0.05", "megakernel", "a0.05m", ["--spp", "4096", "--noise-threshold", "0.05"]))
            runs.append(("adaptive T 0.1 denoised", "wavefront", "a0.1d",
                         ["--spp", "4096", "--noise-threshold", "0.1", "--denoise"]))
            for n in (16, 64):
                runs.append((f"uniform {n} denoised", "wavefront", f"u{n}", ["--spp", str(n), "--denoise", "--keep-noisy"]))
            for label, kernel, file, args in runs:
                s = render(wt, scene, out, file, size, ["--kernel", kernel] + args)
                _, _, img = read_pfm(os.path.join(out, file + ".pfm"))
                spp = s.get("adaptive", {}).get("mean_spp", s["settings"]["spp"])
                guide = s.get("aovs", {}).get("seconds", 0.0) if "denoise" in s else 0.0
                oidn = s.get("denoise", {}).get("seconds", 0.0)
                tsv.write(f"{name}\t{tag}\t{label}\t{kernel}\t{spp:.1f}\t{s['seconds']:.4f}\t{guide:.4f}\t{oidn:.4f}\t"
                          f"{relmse(ref, img):.3e}\n")
                if "--keep-noisy" in args:
                    _, _, noisy = read_pfm(os.path.join(out, file + ".noisy.pfm"))
                    tsv.write(f"{name}\t{tag}\t{label.replace(' denoised', '')}\t{kernel}\t{spp:.1f}\t"
                              f"{s['seconds']:.4f}\t0\t0\t{relmse(ref, noisy):.3e}\n")
                tsv.flush()
            print(name, tag, "pictures:", pictures(out, name, size), flush=True)
        except Exception as e:  # one failing scene is a row; the rest go on
            tsv.write(f"{name}\t{tag}\tFAILED: {e}\t\t\t\t\t\t\n")
            tsv.flush()
            print(name, "FAILED:", e, flush=True)


if __name__ == "__main__":
    main()
