#!/usr/bin/env python3
"""Tables (and a plot) of the scaling benchmark: each kernel's throughput against
resolution, samples per pixel and scene size, and where its cost grows faster than
the work.

    python3 bench/scaling_tables.py RESULTS.json [RESULTS.json ...] [--md FILE] [--svg FILE]

RESULTS.json are `wavetrace bench` results (scripts/scaling.sh writes one per group:
bench/results/scaling/GROUP/results.json). Groups are read as series by name:
`resolution` (x: pixels) and `spp` (x: samples per pixel), `spheres-1eK` and
`triangles-1eK` (x: N = 10^K primitives; one series per depth: whole paths and
camera rays alone); any other group is a series of its own, x its configs in order.
The markdown goes to --md (default: stdout), the SVG (hand-written: no matplotlib)
to --svg where given. Python 3, standard library only.

What the columns say: the work of a point is its counted rays; `M rays/s` and
`M paths/s` are per second of GPU time (median of the repeats); `ns/ray` is its
inverse; `rel.` is the point's M rays/s over the same kernel's at the series' first
(smallest) point: below 1, each ray costs more than it did there. In the resolution
and spp series, `exp.` is the slope of log(seconds) against log(rays) from the
point before: 1 is cost growing as the work, above 1 faster, below 1 slower (a GPU
still filling up).

Exit code 1 when a point failed for any reason but megakernel-constant's refusal of
a scene too large for constant memory (which the tables show as `refused`), or when
no results could be read.
"""

import argparse
import json
import math
import os
import re
import sys

SIZE_GROUP = re.compile(r"(spheres|triangles)-(\d+(?:\.\d+)?(?:e\d+)?)")
STAGES = ["intersect", "compact", "readback", "sort", "shade", "shadow"]
KERNEL_COLOURS = {"megakernel": "#1f77b4", "megakernel-constant": "#9467bd", "wavefront": "#d62728",
                  "wavefront-sorted": "#2ca02c", "wavefront-unsorted": "#ff7f0e"}
COLOURS = list(KERNEL_COLOURS.values()) + ["#8c564b", "#e377c2", "#7f7f7f", "#17becf"]


def refused(p):
    return p.get("status", "").startswith("error") and "constant memory" in p.get("status", "")


def ok(p):
    return p.get("status") == "ok"


def load(paths):
    points, headers = [], []
    for path in paths:
        try:
            with open(path) as f:
                doc = json.load(f)
        except (OSError, ValueError) as e:
            print("scaling_tables: %s: %s" % (path, e), file=sys.stderr)
            continue
        headers.append((path, doc))
        for p in doc.get("points", []):
            p = dict(p)
            p["_file"] = path
            points.append(p)
    return points, headers


def kernel_order(points, headers):
    order = []
    for _, doc in headers:
        for k in doc.get("kernels", []):
            if k not in order:
                order.append(k)
    for p in points:
        if p["kernel"] not in order:
            order.append(p["kernel"])
    return [k for k in order if any(p["kernel"] == k for p in points)]


class Series:
    """Points of one curve family: kind (resolution, spp, size, other), a title,
    and rows {x: {kernel: point}} with x labels."""

    def __init__(self, key, kind, title, xname):
        self.key, self.kind, self.title, self.xname = key, kind, title, xname
        self.rows = {}      # x -> {kernel: point}
        self.labels = {}    # x -> text

    def add(self, x, label, p):
        self.rows.setdefault(x, {})[p["kernel"]] = p
        self.labels[x] = label

    def xs(self):
        return sorted(self.rows)


def size_label(n):
    """10 -> '10', 1000 -> '1e3', 10^7 -> '1e7'."""
    k = round(math.log10(n)) if n > 0 else 0
    return str(n) if n < 1000 or 10 ** k != n else "1e%d" % k


def settings_text(p, keys):
    parts = []
    if "res" in keys:
        parts.append("%dx%d" % (p["width"], p["height"]))
    if "spp" in keys:
        parts.append("%d spp" % p["spp"])
    if "depth" in keys:
        rd = p.get("roulette_depth", p["depth"])
        parts.append("depth %d" % p["depth"] + ("" if rd >= p["depth"] else ", roulette from %d" % rd))
    return ", ".join(parts)


def scene_name(p):
    return os.path.splitext(os.path.basename(p.get("scene", "?")))[0]


def build_series(points):
    series = {}
    order = []

    def get(key, kind, title, xname):
        if key not in series:
            series[key] = Series(key, kind, title, xname)
            order.append(key)
        return series[key]

    by_group = {}
    for p in points:
        by_group.setdefault(p["group"], []).append(p)
    for group, ps in by_group.items():
        m = SIZE_GROUP.fullmatch(group)
        if m:
            n = int(float(m.group(2)))
            for p in ps:
                what = "whole paths" if p["depth"] > 1 else "camera rays only"
                key = (m.group(1), p["depth"], p["width"], p["height"], p["spp"])
                s = get(key, "size", "%s: %s, %s, N varies" % (m.group(1), settings_text(p, ("res", "spp", "depth")),
                                                            what), "N")
                s.add(n, size_label(n), p)
            continue
        res = {(p["width"], p["height"]) for p in ps}
        spps = {p["spp"] for p in ps}
        if group == "resolution" or (len(res) > 1 and len(spps) == 1):
            key = (group,)
            s = get(key, "resolution", "%s: %s, %s, %s" % (group, scene_name(ps[0]),
                                                          settings_text(ps[0], ("spp", "depth")), "resolution varies"),
                    "pixels")
            for p in ps:
                s.add(p["width"] * p["height"], "%dx%d" % (p["width"], p["height"]), p)
        elif group == "spp" or (len(spps) > 1 and len(res) == 1):
            key = (group,)
            s = get(key, "spp", "%s: %s, %s, %s" % (group, scene_name(ps[0]), settings_text(ps[0], ("res", "depth")),
                                                   "samples per pixel vary"), "spp")
            for p in ps:
                s.add(p["spp"], str(p["spp"]), p)
        else:
            key = (group,)
            s = get(key, "other", "%s: %s" % (group, scene_name(ps[0])), "config")
            configs = []
            for p in ps:
                c = (p["width"], p["height"], p["spp"], p["depth"])
                if c not in configs:
                    configs.append(c)
                s.add(configs.index(c), settings_text(p, ("res", "spp", "depth")), p)
    # resolution, spp, then the size series (spheres before triangles, whole paths first), then the rest.
    rank = {"resolution": 0, "spp": 1, "size": 2, "other": 3}

    def sort_key(k):
        s = series[k]
        if s.kind == "size":
            return (2, k[0], -k[1], k[2:])
        return (rank[s.kind], order.index(k))
    return [series[k] for k in sorted(order, key=sort_key)]


def fnum(x, digits=3):
    if x is None:
        return "-"
    if x == 0:
        return "0"
    mag = math.floor(math.log10(abs(x)))
    d = max(0, digits - 1 - mag)
    return "%.*f" % (d, x)


def cell_failed(p):
    if p is None:
        return "-"
    if refused(p):
        return "refused (constant memory)"
    return "FAILED: " + p.get("status", "?")[:60].replace("|", "/")


def first_ok(s, kernel):
    for x in s.xs():
        p = s.rows[x].get(kernel)
        if p and ok(p) and p.get("m_rays_per_s", 0) > 0:
            return x, p
    return None, None


def write_series(out, s, kernels):
    w = out.append
    ks = [k for k in kernels if any(k in r for r in s.rows.values())]
    w("### %s" % s.title)
    w("")
    # The points' work and, for scene sizes, what the scene holds.
    any_point = {x: next((p for p in s.rows[x].values() if ok(p)), None) for x in s.xs()}
    if s.kind == "size":
        w("| N | spheres | triangles (placed) | BVH nodes | BVH depth | device MB | load s: parse + mesh + BVH | M rays | rays/path |")
        w("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
        for x in s.xs():
            p = any_point[x]
            if p is None:
                w("| %s | all kernels failed | | | | | | | |" % s.labels[x])
                continue
            g = p.get("geometry", {})
            depth = max([g.get("sphere_bvh", {}).get("depth", 0)] + [m["bvh"]["depth"] for m in g.get("meshes", [])]
                        ) + g.get("top_level_bvh", {}).get("depth", 0)
            ls = p.get("load_seconds", {})
            w("| %s | %d | %d (%d) | %d | %d | %.1f | %.2f + %.2f + %.2f | %s | %.2f |" % (
                s.labels[x], g.get("spheres", 0), g.get("triangles", 0), g.get("instanced_triangles", 0),
                g.get("bvh_nodes", 0), depth, g.get("device_bytes", 0) / 1e6, ls.get("parse", 0),
                ls.get("mesh_load", 0), ls.get("bvh_build", 0), fnum(p["rays"] / 1e6), p["rays_per_path"]))
        w("")
        w("Spheres include the ground sphere. BVH depth: the deepest leaf, top level included. Device MB: the "
          "scene on the GPU. Load: the scene's parse, mesh file and BVH build seconds on the host. Rays and "
          "rays/path: the first ok kernel's (every kernel traces the same paths).")
        w("")
    # At a glance: relative throughput per kernel.
    w("Throughput relative to the first point (M rays/s over the same kernel's at %s %s):" %
      (s.xname, s.labels[s.xs()[0]]))
    w("")
    w("| %s | %s |" % (s.xname, " | ".join(ks)))
    w("| ---: |" + " ---: |" * len(ks))
    for x in s.xs():
        cells = []
        for k in ks:
            p = s.rows[x].get(k)
            x0, p0 = first_ok(s, k)
            if p is None or not ok(p):
                cells.append("refused" if p is not None and refused(p) else ("-" if p is None else "FAILED"))
            else:
                cells.append("%.2f" % (p["m_rays_per_s"] / p0["m_rays_per_s"]))
        w("| %s | %s |" % (s.labels[x], " | ".join(cells)))
    w("")
    # Every point.
    growth = s.kind in ("resolution", "spp")
    head = "| kernel | %s | M rays | seconds (min-max) | M rays/s | M paths/s | ns/ray | rel. |%s" % (
        s.xname, " exp. |" if growth else "")
    w(head)
    w("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |" + (" ---: |" if growth else ""))
    for k in ks:
        x0, p0 = first_ok(s, k)
        prev = None
        for x in s.xs():
            p = s.rows[x].get(k)
            if p is None:
                continue
            if not ok(p):
                w("| %s | %s | %s |%s" % (k, s.labels[x], cell_failed(p), " |" * (5 if not growth else 6)))
                prev = None
                continue
            rel = p["m_rays_per_s"] / p0["m_rays_per_s"] if p0 else None
            exp = "-"
            if growth and prev is not None and p["rays"] != prev["rays"] and prev["seconds_median"] > 0:
                exp = "%.2f" % (math.log(p["seconds_median"] / prev["seconds_median"]) /
                                math.log(p["rays"] / prev["rays"]))
            w("| %s | %s | %s | %s (%s-%s) | %s | %s | %s | %.2f |%s" % (
                k, s.labels[x], fnum(p["rays"] / 1e6), fnum(p["seconds_median"]), fnum(p["seconds_min"]),
                fnum(p["seconds_max"]), fnum(p["m_rays_per_s"], 4), fnum(p["m_paths_per_s"], 4),
                fnum(1e3 / p["m_rays_per_s"]),
                rel, " %s |" % exp if growth else ""))
            prev = p
    w("")
    # The wavefront's stages: which part of the cost grows.
    staged = [(x, k, s.rows[x][k]) for k in ks for x in s.xs()
              if k in s.rows[x] and ok(s.rows[x][k]) and s.rows[x][k].get("stage_ms")]
    if staged:
        names = [n for n in STAGES if any(n in p["stage_ms"] for _, _, p in staged)]
        names += sorted({n for _, _, p in staged for n in p["stage_ms"]} - set(names))
        w("Wavefront stages, ms of the median run (and intersect's share of the stages' sum):")
        w("")
        w("| kernel | %s | %s | intersect share |" % (s.xname, " | ".join(names)))
        w("| --- | ---: |" + " ---: |" * len(names) + " ---: |")
        for x, k, p in staged:
            st = p["stage_ms"]
            total = sum(st.values())
            w("| %s | %s | %s | %s |" % (k, s.labels[x], " | ".join(fnum(st.get(n, 0.0)) for n in names),
                                         "%.0f%%" % (100 * st.get("intersect", 0.0) / total) if total else "-"))
        w("")


def summary(out, series, kernels):
    """One line per series: each kernel's M rays/s at the first and the last point."""
    w = out.append
    w("## Summary: M rays/s at the first and at the last point of each series (last / first)")
    w("")
    w("| series | first - last | %s |" % " | ".join(kernels))
    w("| --- | --- |" + " ---: |" * len(kernels))
    for s in series:
        xs = s.xs()
        cells = []
        for k in kernels:
            done = [x for x in xs if k in s.rows[x] and ok(s.rows[x][k]) and s.rows[x][k]["m_rays_per_s"] > 0]
            tried = [x for x in xs if k in s.rows[x]]
            if not tried:
                cells.append("-")
                continue
            if not done:
                cells.append("refused" if all(refused(s.rows[x][k]) for x in tried) else "failed")
                continue
            a, b = s.rows[done[0]][k], s.rows[done[-1]][k]
            text = "%s - %s (%.2f)" % (fnum(a["m_rays_per_s"], 4), fnum(b["m_rays_per_s"], 4),
                                       b["m_rays_per_s"] / a["m_rays_per_s"])
            if done[0] != xs[0] or done[-1] != xs[-1]:
                text += " over %s - %s" % (s.labels[done[0]], s.labels[done[-1]])
            later = [x for x in tried if x > done[-1]]
            if later:
                text += "; refused from %s" % s.labels[later[0]] if refused(s.rows[later[0]][k]) else "; failed"
            cells.append(text)
        w("| %s | %s - %s | %s |" % (s.title.split(":")[0] + (" " + s.title.split(", ")[-2] if s.kind == "size" else ""),
                                     s.labels[xs[0]], s.labels[xs[-1]], " | ".join(cells)))
    w("")


def markdown(points, headers, kernels, series, timings):
    out = []
    w = out.append
    w("# Scaling: throughput against resolution, samples per pixel and scene size")
    w("")
    devices = sorted({d.get("device", {}).get("name", "?") + (" (%s SMs)" % d["device"]["sm_count"]
                                                             if "sm_count" in d.get("device", {}) else "")
                      for _, d in headers})
    commits = sorted({d.get("commit", "?") for _, d in headers})
    dates = sorted(d.get("date", "?") for _, d in headers)
    reps = sorted({"warm-up %s, median of %s" % (d.get("warmup"), d.get("repeats")) for _, d in headers})
    w("Device: %s. Backend: %s. Commit: %s. Runs: %s to %s; %s." % (
        "; ".join(devices), ", ".join(sorted({d.get("backend", "?") for _, d in headers})), ", ".join(commits),
        dates[0] if dates else "?", dates[-1] if dates else "?", "; ".join(reps)))
    w("")
    bad = [p for p in points if not ok(p) and not refused(p)]
    n_refused = sum(1 for p in points if refused(p))
    w("%d points from %d results files: %d ok, %d refused by megakernel-constant (scene over its constant "
      "memory), %d failed otherwise." % (len(points), len(headers), sum(1 for p in points if ok(p)), n_refused,
                                         len(bad)))
    w("")
    for p in bad:
        w("- FAILED: %s %dx%d %d spp depth %d %s: %s" % (p["group"], p["width"], p["height"], p["spp"], p["depth"],
                                                        p["kernel"], p.get("status")))
    if bad:
        w("")
    if timings:
        total = sum(t for _, _, t in timings)
        w("Wall time of each group's `wavetrace bench` (scene loading, checks, warm-up and repeats; "
          "%.0f s in all):" % total)
        w("")
        w("| group | exit | seconds |")
        w("| --- | ---: | ---: |")
        for g, rc, t in timings:
            w("| %s | %s | %.1f |" % (g, rc, t))
        w("")
    w("`rel.`: M rays/s over the same kernel's at the series' first point (below 1: a ray costs more). "
      "`exp.`: slope of log seconds against log rays from the point before (1: cost grows as the work; "
      "above 1: faster). `ns/ray`: 1000 / (M rays/s). Seconds are %s, medians." %
      ("GPU time (CUDA events)" if all(d.get("backend") == "cuda" for _, d in headers) else
       "GPU time (CUDA events) on the cuda backend, wall clock on the cpu backend"))
    w("")
    summary(out, series, kernels)
    for s in series:
        write_series(out, s, kernels)
    return "\n".join(out) + "\n", bad


def read_timings(paths):
    seen, rows = set(), []
    for path in paths:
        t = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(path))), "timings.tsv")
        if t in seen or not os.path.exists(t):
            continue
        seen.add(t)
        with open(t) as f:
            for line in f.read().splitlines()[1:]:
                parts = line.split("\t")
                if len(parts) == 3:
                    try:
                        rows.append((parts[0], parts[1], float(parts[2])))
                    except ValueError:
                        pass
    return rows


# ---------------------------------------------------------------- SVG

def esc(t):
    return str(t).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def nice_ticks(lo, hi):
    """Ticks at 1, 2, 5 x 10^k inside [lo, hi] (fewer where the range is wide)."""
    ticks = []
    k = math.floor(math.log10(lo))
    while 10 ** k <= hi * 1.0001:
        for m in (1, 2, 5):
            v = m * 10 ** k
            if lo * 0.9999 <= v <= hi * 1.0001:
                ticks.append(v)
        k += 1
    if len(ticks) > 8:
        ticks = [t for t in ticks if abs(math.log10(t) - round(math.log10(t))) < 1e-9] or ticks
    return ticks


def svg(series, kernels):
    panels = [s for s in series if any(ok(p) for r in s.rows.values() for p in r.values())]
    cols = 2
    pw, ph = 520, 330
    ml, mr, mt, mb = 70, 20, 40, 60
    rows = max(1, (len(panels) + cols - 1) // cols)
    legend_h = 40
    W, H = cols * pw, rows * ph + legend_h
    o = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" viewBox="0 0 %d %d" '
         'font-family="sans-serif" font-size="12">' % (W, H, W, H),
         '<rect width="100%" height="100%" fill="white"/>']
    spare = iter(COLOURS[len(KERNEL_COLOURS):] * 4)
    colour = {k: KERNEL_COLOURS.get(k) or next(spare) for k in kernels}
    dash = {k: ' stroke-dasharray="6 3"' if k.endswith("sorted") else ' stroke-dasharray="2 2"' if "constant" in k
            else "" for k in kernels}
    x = 10
    for k in kernels:
        o.append('<line x1="%d" y1="22" x2="%d" y2="22" stroke="%s" stroke-width="2.5"%s/>' % (x, x + 24, colour[k],
                                                                                          dash[k]))
        o.append('<text x="%d" y="26">%s</text>' % (x + 30, esc(k)))
        x += 40 + 8 * len(k)
    for i, s in enumerate(panels):
        ox, oy = (i % cols) * pw, legend_h + (i // cols) * ph
        x0, x1 = ox + ml, ox + pw - mr
        y0, y1 = oy + ph - mb, oy + mt
        xs = s.xs()
        vals = [p["m_rays_per_s"] for r in s.rows.values() for p in r.values() if ok(p) and p["m_rays_per_s"] > 0]
        if not vals:
            continue
        xlog = s.kind != "other" and min(xs) > 0
        vlo, vhi = min(vals) / 1.3, max(vals) * 1.3
        ticks = nice_ticks(vlo, vhi)
        if len(ticks) < 2:
            vlo, vhi = 10 ** math.floor(math.log10(vlo)), 10 ** math.ceil(math.log10(vhi))
            ticks = nice_ticks(vlo, vhi)

        def px(v):
            a, b = (math.log10(min(xs)), math.log10(max(xs))) if xlog else (min(xs), max(xs))
            t = ((math.log10(v) if xlog else v) - a) / (b - a) if b > a else 0.5
            return x0 + 10 + t * (x1 - x0 - 20)

        def py(v):
            t = (math.log10(v) - math.log10(vlo)) / (math.log10(vhi) - math.log10(vlo))
            return y0 - t * (y0 - y1)
        o.append('<rect x="%d" y="%d" width="%d" height="%d" fill="none" stroke="#888"/>' % (x0, y1, x1 - x0, y0 - y1))
        o.append('<text x="%d" y="%d" font-weight="bold">%s</text>' % (ox + 10, oy + 20, esc(s.title[:80])))
        for t in ticks:
            o.append('<line x1="%d" y1="%.1f" x2="%d" y2="%.1f" stroke="#ddd"/>' % (x0, py(t), x1, py(t)))
            o.append('<text x="%d" y="%.1f" text-anchor="end">%s</text>' % (x0 - 4, py(t) + 4, "%g" % t))
        o.append('<text transform="translate(%d,%d) rotate(-90)" text-anchor="middle">M rays/s (log)</text>'
                 % (ox + 16, (y0 + y1) // 2))
        step = max(1, len(xs) // 8)
        for j, xv in enumerate(xs):
            if j % step == 0 or j == len(xs) - 1:
                o.append('<text x="%.1f" y="%d" text-anchor="middle" font-size="10">%s</text>' %
                         (px(xv), y0 + 14, esc(s.labels[xv])))
        o.append('<text x="%d" y="%d" text-anchor="middle">%s%s</text>' % ((x0 + x1) // 2, y0 + 32, esc(s.xname),
                                                                           " (log)" if xlog else ""))
        for k in kernels:
            pts = [(px(xv), py(s.rows[xv][k]["m_rays_per_s"])) for xv in xs
                   if k in s.rows[xv] and ok(s.rows[xv][k]) and s.rows[xv][k]["m_rays_per_s"] > 0]
            if len(pts) > 1:
                o.append('<polyline fill="none" stroke="%s" stroke-width="2"%s points="%s"/>' % (
                    colour[k], dash[k], " ".join("%.1f,%.1f" % q for q in pts)))
            for q in pts:
                o.append('<circle cx="%.1f" cy="%.1f" r="3" fill="%s"/>' % (q[0], q[1], colour[k]))
    o.append("</svg>")
    return "\n".join(o) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", nargs="+", help="results.json of wavetrace bench")
    ap.add_argument("--md", help="markdown file to write (default: stdout)")
    ap.add_argument("--svg", help="SVG plot to write")
    args = ap.parse_args()
    points, headers = load(args.results)
    if not points:
        sys.exit("scaling_tables: no points in %s" % " ".join(args.results))
    kernels = kernel_order(points, headers)
    series = build_series(points)
    text, bad = markdown(points, headers, kernels, series, read_timings(args.results))
    if args.md:
        with open(args.md, "w") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    if args.svg:
        with open(args.svg, "w") as f:
            f.write(svg(series, kernels))
    if bad:
        print("scaling_tables: %d points failed (not counting constant-memory refusals)" % len(bad), file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
