#!/usr/bin/env python3
"""The tables of bench/RESULTS.md's "every shipped scene" section, from the TSV that
bench/adaptive_scenes.py writes:

    bench/adaptive_tables.py bench/results/adaptive/adaptive_scenes.tsv

Per scene, the time to the relMSE of the 1024-spp uniform wavefront render: uniform
(that render), adaptive (the largest threshold whose relMSE is at most it), and
denoised (the quickest of uniform 16, uniform 64 and adaptive T 0.1 denoised that
reaches it: render + first-surface pass + OIDN); then the two kernels' seconds.
"""
import csv
import sys


def main():
    rows = [r for r in csv.DictReader(open(sys.argv[1]), delimiter="\t") if r["kernel"]]
    scenes = []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    print("| scene (size) | uniform 1024: s, relMSE | adaptive to it: T, spp, s (x uniform) | denoised to it: what, s "
          "(x uniform) |")
    print("| --- | --- | --- | --- |")
    kernel_lines = []
    for s in scenes:
        mine = {(r["render"], r["kernel"]): r for r in rows if r["scene"] == s}
        u = mine[("uniform 1024", "wavefront")]
        target, t_u = float(u["relmse"]), float(u["seconds"])
        last = mine[("adaptive T 0.02", "wavefront")]
        adaptive = f"not by T 0.02 ({float(last['relmse']):.2e} at {float(last['mean_spp']):.0f} spp)"
        for t in ("0.1", "0.05", "0.03", "0.02"):
            a = mine[(f"adaptive T {t}", "wavefront")]
            if float(a["relmse"]) <= target:
                adaptive = (f"T {t}, {float(a['mean_spp']):.0f} spp, {float(a['seconds']):.3f} "
                            f"({t_u / float(a['seconds']):.1f}x)")
                break
        best = None
        for what in ("uniform 16 denoised", "uniform 64 denoised", "adaptive T 0.1 denoised"):
            d = mine[(what, "wavefront")]
            total = float(d["seconds"]) + float(d["guide_seconds"]) + float(d["oidn_seconds"])
            if float(d["relmse"]) <= target and (best is None or total < best[1]):
                best = (what.replace(" denoised", ""), total)
        d64 = mine[("uniform 64 denoised", "wavefront")]
        denoised = (f"{best[0]}, {best[1]:.3f} ({t_u / best[1]:.1f}x)" if best
                    else f"none (64 spp denoised: {float(d64['relmse']):.2e})")
        print(f"| {s} ({u['size']}) | {t_u:.3f}, {target:.2e} | {adaptive} | {denoised} |")
        m = mine[("uniform 1024", "megakernel")]
        am, aw = mine[("adaptive T 0.05", "megakernel")], mine[("adaptive T 0.05", "wavefront")]
        kernel_lines.append(f"| {s} | {float(m['seconds']):.3f} / {t_u:.3f} ({float(m['seconds']) / t_u:.1f}x) | "
                            f"{float(am['seconds']):.3f} / {float(aw['seconds']):.3f} "
                            f"({float(am['seconds']) / float(aw['seconds']):.1f}x) |")
    print()
    print("| scene | uniform 1024: megakernel / wavefront s | adaptive T 0.05: megakernel / wavefront s |")
    print("| --- | --- | --- |")
    print("\n".join(kernel_lines))


if __name__ == "__main__":
    main()
