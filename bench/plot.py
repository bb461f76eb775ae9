#!/usr/bin/env python3
"""Plots and markdown tables from the results file of `wavetrace bench`.

    python3 bench/plot.py bench/results/results.json --out bench/results

Writes seven PNGs and tables.md into --out. Points whose status is not "ok" (failed
image check, error) carry no timings: plots leave them out, tables show them as
FAILED with their status. See bench/README.md.
"""

import argparse
import json
import math
import os
import sys
import textwrap
import traceback

try:
    import matplotlib

    matplotlib.use("Agg")  # files only; no display on the bench machine
    import matplotlib.pyplot as plt
    from matplotlib import colors as mcolors
    from matplotlib import ticker
    import numpy as np
except ImportError as e:
    sys.exit(f"plot.py: {e}; needs matplotlib (Debian: apt-get install python3-matplotlib, "
             "then run it with the system python3)")

DPI = 150

# The headline configuration: the reference study's largest render.
HEADLINE_GROUP = "study"
HEADLINE = (1920, 1080, 300, 30)

# Facts from the reference study at the headline configuration: label, GPU,
# seconds, M paths/s. The study estimated rays as paths x 22.5.
STUDY_RAYS_PER_PATH = 22.5
REFERENCE_ROWS = [
    ("study, global-memory megakernel", "GTX 1070", 74.94, 8.30),
    ("study, constant-memory megakernel", "GTX 1070", 105.29, 5.91),
    ("study's code, global memory", "H100 SXM", 9.03, 68.9),
    ("study's code, constant memory", "H100 SXM", 10.06, 61.8),
]

# The kernels and the wavefront's stages come from the results: the bench writes
# the command's kernel list ("kernels") and the stages in the order they run
# ("stages"). Colour and marker per kernel, the same in every figure. Kernels not
# listed here (added to the bench later) get the extra styles in turn.
KERNEL_STYLE = {
    "megakernel": ("#1f77b4", "o"),
    "megakernel-constant": ("#17becf", "s"),
    "wavefront": ("#d62728", "^"),
    "wavefront-sorted": ("#9467bd", "P"),
    "wavefront-unsorted": ("#ff7f0e", "v"),
}
EXTRA_STYLES = [("#2ca02c", "D"), ("#9467bd", "P"), ("#8c564b", "X"), ("#e377c2", "*")]

# Colour per stage. A stage not listed here is drawn in an extra colour, with a
# warning: never left out.
STAGE_COLORS = {"generate": "#8dd3c7", "intersect": "#4575b4", "compact": "#fdb462", "readback": "#969696",
                "sort": "#e7298a", "shade": "#66a61e"}
EXTRA_STAGE_COLORS = ["#b15928", "#6a3d9a", "#ffff99", "#1b9e77", "#e6ab02", "#a6761d"]

plt.rcParams.update({
    "font.size": 10,
    "axes.titlesize": 11,
    "axes.labelsize": 10,
    "legend.fontsize": 9,
    "xtick.labelsize": 9,
    "ytick.labelsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.axisbelow": True,
    "text.parse_math": False,  # statuses and names are shown as written, "$" included
})


# ----------------------------------------------------------------------------
# Reading the results


def number(v):
    """v as a finite float, or None (the bench writes null for NaN)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return None
    v = float(v)
    return v if math.isfinite(v) else None


def ok(p):
    return p is not None and p.get("status") == "ok" and (number(p.get("seconds_median")) or 0) > 0


def seconds(p):
    return number(p.get("seconds_median"))


def m_paths(p):
    v = number(p.get("m_paths_per_s"))
    if v is None and number(p.get("paths")) and seconds(p):
        v = p["paths"] / seconds(p) / 1e6
    return v


def m_rays(p):
    v = number(p.get("m_rays_per_s"))
    if v is None and number(p.get("rays")) and seconds(p):
        v = p["rays"] / seconds(p) / 1e6
    return v


def rays_per_path(p):
    v = number(p.get("rays_per_path"))
    if v is None and number(p.get("rays")) and number(p.get("paths")):
        v = p["rays"] / p["paths"]
    return v


def config_of(p):
    return tuple(int(number(p.get(k)) or 0) for k in ("width", "height", "spp", "depth"))


def res_label(cfg):
    return f"{cfg[0]}x{cfg[1]}"


def cfg_label(cfg):
    return f"{cfg[0]}x{cfg[1]} {cfg[2]}/{cfg[3]}"


def scene_name(path):
    return os.path.basename(path or "") or "?"


def stages_of(doc, points):
    """The stages in the order they run, and a colour for each. From the results'
    "stages" list, with any further stage a row names; results written before the
    list was kept give the known stages in their order, then the others."""
    stages = [s for s in doc.get("stages") or [] if isinstance(s, str)]
    listed = bool(stages)
    for p in points:
        if isinstance(p.get("stage_ms"), dict):
            stages += [s for s in p["stage_ms"] if s not in stages]
    if not listed:
        known = list(STAGE_COLORS)
        stages.sort(key=lambda s: known.index(s) if s in known else len(known))
    extra = iter(EXTRA_STAGE_COLORS * 4)
    colors = {}
    for s in stages:
        colors[s] = STAGE_COLORS.get(s)
        if colors[s] is None:
            colors[s] = next(extra)
            print(f"plot.py: WARNING: stage '{s}' has no colour of its own; drawn in {colors[s]}", file=sys.stderr)
    return stages, colors


class Results:
    def __init__(self, doc):
        self.header = {k: v for k, v in doc.items() if k != "points"}
        self.points = [p for p in doc.get("points", []) if isinstance(p, dict)]
        self.by_key = {}
        self.groups = []
        kernels = []
        for p in self.points:
            g = p.get("group", "?")
            if g not in self.groups:
                self.groups.append(g)
            k = p.get("kernel", "?")
            if k not in kernels:
                kernels.append(k)
            self.by_key[(g, config_of(p), k)] = p
        listed = [k for k in doc.get("kernels") or [] if isinstance(k, str)]
        self.kernels = [k for k in listed if k in kernels] + [k for k in kernels if k not in listed]
        extra = iter(EXTRA_STYLES * 4)
        self.style = {k: KERNEL_STYLE.get(k) or next(extra) for k in self.kernels}
        self.stages, self.stage_color = stages_of(doc, self.points)


    def get(self, group, cfg, kernel):
        return self.by_key.get((group, cfg, kernel))

    def get_ok(self, group, cfg, kernel):
        p = self.get(group, cfg, kernel)
        return p if ok(p) else None

    def configs(self, group):
        """The group's configurations, by pixels, then samples, then depth."""
        cfgs = {config_of(p) for p in self.points if p.get("group") == group}
        return sorted(cfgs, key=lambda c: (c[0] * c[1], c[2], c[3]))

    def largest(self, group):
        cfgs = self.configs(group)
        return max(cfgs, key=lambda c: (c[0] * c[1] * c[2], c[3])) if cfgs else None

    def headline(self):
        """(group, cfg) of the headline row: the study's largest render where it was run."""
        if HEADLINE_GROUP not in self.groups:
            return None
        if HEADLINE in self.configs(HEADLINE_GROUP):
            return HEADLINE_GROUP, HEADLINE
        return HEADLINE_GROUP, self.largest(HEADLINE_GROUP)

    def scene(self, group):
        for p in self.points:
            if p.get("group") == group:
                return scene_name(p.get("scene"))
        return "?"

    def study_scene(self):
        """The headline group's scene, for titles; seed57, the study's, when there is none."""
        name = self.scene(HEADLINE_GROUP)
        return os.path.splitext(name)[0] if name != "?" else "seed57"

    def device_name(self):
        return (self.header.get("device") or {}).get("name", "unknown device")

    def median_of(self):
        n = self.header.get("repeats")
        return f"median of {n}" if isinstance(n, int) else "median"


# ----------------------------------------------------------------------------
# Formatting


def fmt_seconds(v):
    if v is None:
        return "—"
    return f"{v:.2f}" if v >= 1 else f"{v:#.3g}"


def fmt_rate(v):
    """Three significant figures, whole numbers above 100 (M paths/s, M rays/s)."""
    if v is None:
        return "—"
    if abs(v) >= 100:
        return f"{v:.0f}"
    return f"{v:.1f}" if abs(v) >= 10 else f"{v:.2f}"


def fmt_rpp(v):
    return "—" if v is None else f"{v:.2f}"


def short_status(p, width=60):
    s = str(p.get("status", "no status")) if p else "not run"
    if s == "ok":
        s = "status ok but no timings"
    return s if len(s) <= width else s[: width - 1] + "…"


def md_cell(s):
    return str(s).replace("|", "\\|").replace("\n", " ")


def md_table(head, rows):
    lines = ["| " + " | ".join(md_cell(h) for h in head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(md_cell(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)


# ----------------------------------------------------------------------------
# Figures


def save(fig, out, name):
    path = os.path.join(out, name)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def empty_figure(out, name, title, why):
    """A figure saying what is missing, so that the set of files is always the same."""
    fig, ax = plt.subplots(figsize=(8, 3), layout="constrained")
    ax.set_title(title)
    ax.axis("off")
    ax.text(0.5, 0.5, why, ha="center", va="center", fontsize=12, transform=ax.transAxes)
    return save(fig, out, name)


def headline_rows(res):
    """Rows of the memory-strategy table: ours at the headline, then the study's.

    Each row: label, GPU, seconds, M paths/s, M rays/s counted, rays/path,
    study-style estimate (M paths/s x 22.5), failure status or None.
    """
    rows = []
    hl = res.headline()
    if hl:
        group, cfg = hl
        for k in res.kernels:
            p = res.get(group, cfg, k)
            if p is None:
                continue
            label = f"wavetrace {k}"
            if ok(p):
                mp = m_paths(p)
                rows.append([label, res.device_name(), fmt_seconds(seconds(p)), fmt_rate(mp), fmt_rate(m_rays(p)),
                             fmt_rpp(rays_per_path(p)), fmt_rate(mp * STUDY_RAYS_PER_PATH if mp else None), None])
            else:
                rows.append([label, res.device_name(), "FAILED", "—", "—", "—", "—", short_status(p, 200)])
    for label, gpu, secs, mp in REFERENCE_ROWS:
        rows.append([label, gpu, fmt_seconds(secs), fmt_rate(mp), "not counted", f"{STUDY_RAYS_PER_PATH} (assumed)",
                     fmt_rate(mp * STUDY_RAYS_PER_PATH), None])
    return rows


HEADLINE_COLUMNS = ["", "GPU", "seconds\n(median)", "M paths/s", "M rays/s\n(counted)", "rays/path",
                    "study's estimated\nM rays/s (paths × 22.5)"]


def plot_table1(res, out):
    name = "table1_memory.png"
    hl = res.headline()
    rows = headline_rows(res)
    cfg = hl[1] if hl else HEADLINE
    title = (f"Memory strategy: {res.study_scene()} at {cfg[0]}x{cfg[1]}, {cfg[2]} spp, depth {cfg[3]}"
             f" (ours: {res.device_name()}, {res.median_of()})")
    failures = [(r[0], r[7]) for r in rows if r[7]]
    notes = ["Shaded rows: the reference study. Its rays/s is its estimate, paths × 22.5; ours counts every ray."]
    for label, status in failures:
        notes += textwrap.wrap(f"{label}: FAILED, {status}", 150, subsequent_indent="    ")
    # Sized in inches from the top: title, header (two lines), rows, notes.
    title_h, head_h, row_h, note_h = 0.45, 0.5, 0.3, 0.2
    table_h = head_h + row_h * len(rows)
    fig_h = title_h + table_h + 0.15 + note_h * len(notes) + 0.1
    fig = plt.figure(figsize=(10, fig_h))
    fig.text(0.01, 1 - 0.12 / fig_h, title, ha="left", va="top", fontsize=11)
    ax = fig.add_axes([0.01, 1 - (title_h + table_h) / fig_h, 0.98, table_h / fig_h])
    ax.axis("off")
    table = ax.table(cellText=[r[:7] for r in rows], colLabels=HEADLINE_COLUMNS, bbox=[0, 0, 1, 1],
                     cellLoc="center", colWidths=[0.27, 0.17, 0.08, 0.08, 0.09, 0.12, 0.19])
    table.auto_set_font_size(False)
    table.set_fontsize(9)
    ours = len(rows) - len(REFERENCE_ROWS)
    for (r, c), cell in table.get_celld().items():
        cell.set_height((head_h if r == 0 else row_h) / table_h)
        if r == 0:
            cell.set_text_props(weight="bold")
            cell.set_facecolor("#dddddd")
        elif r - 1 >= ours:
            cell.set_facecolor("#f3f3f3")  # the study's rows
        if c == 0 and r > 0:
            cell.set_text_props(ha="left")
            cell.PAD = 0.02
        if r > 0 and rows[r - 1][7] and c == 2:
            cell.set_text_props(color="#b00000", weight="bold")
    fig.text(0.01, (note_h * len(notes) + 0.1) / fig_h, "\n".join(notes), ha="left", va="top", fontsize=8.5,
             linespacing=1.4)
    return save(fig, out, name)


def plot_resolution_scaling(res, out):
    name = "resolution_scaling.png"
    title = "Render time vs resolution: study scene, 10 spp, depth 5"
    group = "study"
    cfgs = [c for c in res.configs(group) if c[2] == 10 and c[3] == 5]
    if not cfgs:
        return empty_figure(out, name, title, "no study points at 10 spp, depth 5")
    fig, ax = plt.subplots(figsize=(8, 5), layout="constrained")
    drawn = False
    for k in res.kernels:
        pts = [(c[0] * c[1], res.get_ok(group, c, k)) for c in cfgs]
        pts = [(x, p) for x, p in pts if p]
        if not pts:
            continue
        color, marker = res.style[k]
        x = [a for a, _ in pts]
        y = [seconds(p) for _, p in pts]
        lo = [seconds(p) - (number(p.get("seconds_min")) or seconds(p)) for _, p in pts]
        hi = [(number(p.get("seconds_max")) or seconds(p)) - seconds(p) for _, p in pts]
        ax.errorbar(x, y, yerr=[lo, hi], color=color, marker=marker, label=k, capsize=3, lw=1.5, ms=6)
        drawn = True
    if not drawn:
        plt.close(fig)
        return empty_figure(out, name, title, "every point at 10 spp, depth 5 failed")
    ax.set_xscale("log")
    ax.set_yscale("log")
    pixels = [c[0] * c[1] for c in cfgs]
    ax.xaxis.set_major_locator(ticker.FixedLocator(pixels))
    ax.xaxis.set_major_formatter(
        ticker.FixedFormatter([f"{res_label(c)}\n{c[0] * c[1] / 1e6:.2f} Mpixel" for c in cfgs]))
    ax.xaxis.set_minor_locator(ticker.NullLocator())
    ax.set_xlim(min(pixels) / 1.4, max(pixels) * 1.4)
    plain_log_axis(ax.yaxis)
    # A guide for linear scaling, through the first kernel's smallest resolution.
    first = next(((c, p) for k in res.kernels for c in cfgs for p in [res.get_ok(group, c, k)] if p), None)
    if first and len(pixels) > 1:
        c0, p0 = first
        x0 = c0[0] * c0[1]
        ax.plot([min(pixels), max(pixels)], [seconds(p0) * min(pixels) / x0, seconds(p0) * max(pixels) / x0],
                ls="--", color="grey", lw=1, label="time ∝ pixels (guide)")
    ax.set_xlabel("pixels (width × height), log scale")
    ax.set_ylabel(f"render time (s, {res.median_of()}; bars: min–max), log scale")
    ax.set_title(f"{title} ({res.device_name()})")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(title="kernel", loc="upper left")
    return save(fig, out, name)


def plain_log_axis(axis):
    """Log ticks at 1, 2 and 5 per decade, written as plain numbers (0.02, not 2x10^-2)."""
    axis.set_major_locator(ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_locator(ticker.LogLocator(subs=np.arange(2, 10)))
    axis.set_minor_formatter(ticker.NullFormatter())


def bar_offsets(n, width=0.8):
    w = width / max(n, 1)
    return w, [(i - (n - 1) / 2) * w for i in range(n)]


def mark_missing(ax, x, p):
    """A failed or absent point in a bar chart: a label standing where the bar would be."""
    text, color = ("FAILED", "#b00000") if p is not None else ("not run", "#666666")
    ax.text(x, 0, " " + text, rotation=90, ha="center", va="bottom", fontsize=7.5, color=color, weight="bold")


def legend_above(ax, handles_labels=None, ncol=4, title="kernel"):
    """One legend above the axes, outside the data (constrained layout makes room)."""
    handles, labels = handles_labels or ax.get_legend_handles_labels()
    ax.legend(handles, labels, title=title, ncol=ncol, loc="lower center", bbox_to_anchor=(0.5, 1.01),
              frameon=False)


def plot_throughput(res, out):
    name = "throughput_configs.png"
    title = "Throughput at each study configuration"
    group = "study"
    cfgs = res.configs(group)
    if not cfgs:
        return empty_figure(out, name, title, "no study points")
    fig, axes = plt.subplots(2, 1, figsize=(11, 8), sharex=True, layout="constrained")
    w, offs = bar_offsets(len(res.kernels))
    xs = np.arange(len(cfgs))
    for ax, metric, label in ((axes[0], m_paths, "M paths/s"), (axes[1], m_rays, "M rays/s (counted)")):
        top = 0
        for k, off in zip(res.kernels, offs):
            color, _ = res.style[k]
            for i, c in enumerate(cfgs):
                p = res.get(group, c, k)
                v = metric(p) if ok(p) else None
                if v is None:
                    mark_missing(ax, xs[i] + off, p)
                else:
                    ax.bar(xs[i] + off, v, w, color=color, edgecolor="white", linewidth=0.5)
                    top = max(top, v)
            ax.bar(np.nan, np.nan, color=color, label=k)  # legend entry
        ax.set_ylabel(label)
        ax.set_xlim(-0.5, len(cfgs) - 0.5)
        ax.set_ylim(0, (top or 1) * 1.18)
        ax.grid(axis="x", visible=False)
    legend_above(axes[0], ncol=len(res.kernels))
    fig.suptitle(f"{title}: {res.study_scene()}, {res.median_of()} ({res.device_name()})")
    axes[1].set_xticks(xs)
    axes[1].set_xticklabels([f"{res_label(c)}\n{c[2]}/{c[3]}" for c in cfgs])
    axes[1].set_xlabel("configuration (W×H, spp/depth)")
    return save(fig, out, name)


def plot_sample_scaling(res, out):
    name = "sample_scaling.png"
    title = "Render time vs samples per pixel, study scene"
    group = "study"
    cfgs = res.configs(group)
    resolutions = sorted({(c[0], c[1]) for c in cfgs}, key=lambda r: r[0] * r[1])
    if not resolutions:
        return empty_figure(out, name, title, "no study points")
    fig, axes = plt.subplots(1, len(resolutions), figsize=(11, 4.8), sharey=True, layout="constrained",
                             squeeze=False)
    axes = axes[0]
    handles = {}
    for ax, r in zip(axes, resolutions):
        rc = [c for c in cfgs if (c[0], c[1]) == r]
        for k in res.kernels:
            pts = [(c[2], res.get_ok(group, c, k)) for c in rc]
            pts = [(x, p) for x, p in pts if p]
            if not pts:
                continue
            color, marker = res.style[k]
            # Hollow markers for the variants, so that overlapping points stay distinguishable.
            hollow = "unsorted" in k or "constant" in k
            (h,) = ax.plot([x for x, _ in pts], [seconds(p) for _, p in pts], color=color, marker=marker, ms=7,
                           lw=1.2, alpha=0.9, label=k, fillstyle="none" if hollow else "full")
            handles[k] = h
        ax.set_xscale("log")
        ax.set_yscale("log")
        spps = [c[2] for c in rc]
        ax.xaxis.set_major_locator(ticker.FixedLocator(spps))
        ax.xaxis.set_major_formatter(ticker.FixedFormatter([f"{c[2]}\nd{c[3]}" for c in rc]))
        ax.xaxis.set_minor_locator(ticker.NullLocator())
        ax.set_xlim(min(spps) / 1.6, max(spps) * 1.6)
        plain_log_axis(ax.yaxis)
        ax.set_title(res_label(r))
        ax.set_xlabel("samples per pixel, log scale\n(d: depth)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel(f"render time (s, {res.median_of()}), log scale")
    if handles:
        axes[0].legend([handles[k] for k in res.kernels if k in handles], [k for k in res.kernels if k in handles],
                       title="kernel", loc="upper left")
    fig.suptitle(f"{title}, one panel per resolution ({res.device_name()})")
    return save(fig, out, name)


def plot_heatmap(res, out):
    name = "config_heatmap.png"
    title = "Wavefront time ÷ megakernel time over the study configurations"
    group = "study"
    cfgs = res.configs(group)
    resolutions = sorted({(c[0], c[1]) for c in cfgs}, key=lambda r: r[0] * r[1])
    if not resolutions:
        return empty_figure(out, name, title, "no study points")
    per_res = [[c for c in cfgs if (c[0], c[1]) == r] for r in resolutions]
    ncol = max(len(rc) for rc in per_res)
    ratio = np.full((len(resolutions), ncol), np.nan)
    for i, rc in enumerate(per_res):
        for j, c in enumerate(rc):
            wf, mk = res.get_ok(group, c, "wavefront"), res.get_ok(group, c, "megakernel")
            if wf and mk:
                ratio[i, j] = seconds(wf) / seconds(mk)
    fig, ax = plt.subplots(figsize=(8, 1.6 + 1.1 * len(resolutions)), layout="constrained")
    finite = ratio[np.isfinite(ratio)]
    # A log scale symmetric about 1: as much colour for 2x slower as for 2x faster.
    span = max(1.05, float(np.max(np.maximum(finite, 1 / finite)))) if finite.size else 2.0
    norm = mcolors.LogNorm(vmin=1 / span, vmax=span)
    cmap = matplotlib.colormaps["RdBu_r"].copy()
    cmap.set_bad("white")
    im = ax.imshow(np.ma.masked_invalid(ratio), cmap=cmap, norm=norm, aspect="auto")
    for i, rc in enumerate(per_res):
        for j, c in enumerate(rc):
            v = ratio[i, j]
            if math.isfinite(v):
                r, g, b, _ = cmap(norm(v))
                color = "black" if 0.299 * r + 0.587 * g + 0.114 * b > 0.5 else "white"
                text = f"{c[2]} spp / depth {c[3]}\n{v:.2f}×"
            else:
                pair = [res.get(group, c, k) for k in ("wavefront", "megakernel")]
                why = "FAILED" if any(p is not None and not ok(p) for p in pair) else "not run"
                color, text = "#555555", f"{c[2]} spp / depth {c[3]}\n({why})"
            ax.text(j, i, text, ha="center", va="center", fontsize=9, color=color)
    ax.set_yticks(range(len(resolutions)))
    ax.set_yticklabels([res_label(r) for r in resolutions])
    ax.set_xticks(range(ncol))
    ax.set_xticklabels([f"configuration {j + 1}" for j in range(ncol)])
    ax.set_ylabel("resolution")
    ax.set_xlabel("configuration within the resolution (spp / depth in each cell)")
    ax.grid(False)
    ax.set_xticks(np.arange(-0.5, ncol, 1), minor=True)
    ax.set_yticks(np.arange(-0.5, len(resolutions), 1), minor=True)
    ax.grid(which="minor", color="white", linewidth=2, alpha=1)
    ax.tick_params(which="minor", length=0)
    cb = fig.colorbar(im, ax=ax, shrink=0.9)
    cb.set_label("wavefront s ÷ megakernel s\n(below 1: wavefront faster)")
    # Ticks out from 1 both ways, no closer than a tenth of the bar's (log) length.
    gap = 0.1 * 2 * math.log(span)
    ticks = [1.0]
    for side in ((1.1, 1.2, 1.3, 1.4, 1.6, 2, 2.5, 3, 4, 5, 10, 20, 50, 100),
                 (0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.33, 0.25, 0.2, 0.1, 0.05, 0.02, 0.01)):
        last = 1.0
        for t in side:
            if 1 / span <= t <= span and abs(math.log(t / last)) >= gap:
                ticks.append(t)
                last = t
    ticks.sort()
    cb.set_ticks(ticks)
    cb.set_ticklabels([f"{t:g}×" for t in ticks])
    cb.ax.yaxis.set_minor_locator(ticker.NullLocator())
    ax.set_title(f"{title}\n{res.study_scene()}, {res.median_of()} ({res.device_name()})")
    return save(fig, out, name)


def wavefront_kernels(res):
    return [k for k in res.kernels if k.startswith("wavefront")]


def plot_stages(res, out):
    name = "wavefront_stages.png"
    title = "Wavefront time per stage"
    kernels = wavefront_kernels(res)
    bars = []  # (label, point or None)
    for g in res.groups:
        cfg = res.headline()[1] if g == HEADLINE_GROUP and res.headline() else res.largest(g)
        for k in kernels:
            bars.append((f"{k}\n{g}\n{cfg_label(cfg)}", res.get(g, cfg, k)))
    if not bars:
        return empty_figure(out, name, title, "no wavefront points")
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(11, 9.5), height_ratios=[1.35, 1], layout="constrained")
    xs = np.arange(len(bars))
    top = 0
    for i, (_, p) in enumerate(bars):
        stage_ms = p.get("stage_ms") if ok(p) else None
        if not isinstance(stage_ms, dict):
            mark_missing(ax, xs[i], p)
            continue
        bottom = 0.0
        for s in res.stages:
            color = res.stage_color[s]
            v = (number(stage_ms.get(s)) or 0) / 1000
            ax.bar(xs[i], v, 0.6, bottom=bottom, color=color, edgecolor="white", linewidth=0.5)
            bottom += v
        ax.plot(xs[i], seconds(p), marker="_", ms=40, mew=2, color="black")
        ax.text(xs[i], max(bottom, seconds(p)), f"stages: {bottom:.3g} s\n", ha="center", va="bottom", fontsize=8.5)
        top = max(top, bottom, seconds(p))
    # Legend entries top to bottom in the order the stages are stacked.
    ax.plot(np.nan, np.nan, marker="_", ms=20, mew=2, color="black", ls="none", label="render time (median)")
    for s in reversed(res.stages):
        ax.bar(np.nan, np.nan, color=res.stage_color[s], label=s)
    per_group = max(len(kernels), 1)
    for b in range(per_group, len(bars), per_group):
        ax.axvline(b - 0.5, color="#bbbbbb", lw=1)
    ax.set_xlim(-0.6, len(bars) - 0.4)
    ax.set_xticks(xs)
    ax.set_xticklabels([b[0] for b in bars], fontsize=8.5)
    ax.set_ylim(0, (top or 1) * 1.2)
    ax.set_ylabel("time (s), stages summed over iterations")
    ax.grid(axis="x", visible=False)
    ax.legend(title="stage", loc="upper left", bbox_to_anchor=(1.005, 1.0))
    ax.set_title(f"{title} at each group's largest configuration ({res.device_name()})")

    # Live paths per iteration of the headline's wavefront row.
    hl = res.headline()
    p = res.get_ok(hl[0], hl[1], "wavefront") if hl else None
    live = p.get("live_per_bounce") if p else None
    if isinstance(live, list) and live:
        live = [number(v) or 0 for v in live]
        it = np.arange(len(live))
        ax2.plot(it, np.asarray(live, dtype=float) / 1e6, color=res.style["wavefront"][0], lw=1.5,
                 label="wavefront, " + cfg_label(hl[1]))
        ax2.set_xlim(0, max(len(live) - 1, 1))
        ax2.set_ylim(0, max(live) / 1e6 * 1.15)
        ax2.legend(loc="best")
        full = sum(1 for v in live if v == max(live))
        ax2.set_title(f"Live paths entering each wavefront iteration: study, {cfg_label(hl[1])}\n"
                      f"{len(live)} iterations, {full} of them at the maximum of {max(live) / 1e6:.2f} M live paths")
    else:
        ax2.text(0.5, 0.5, "no live-path series for the study headline wavefront row", ha="center",
                 va="center", transform=ax2.transAxes)
        ax2.set_title("Live paths entering each wavefront iteration")
    ax2.set_xlabel("iteration")
    ax2.set_ylabel("live paths (millions)")
    return save(fig, out, name)


def plot_kernels_per_scene(res, out):
    name = "kernels_per_scene.png"
    title = "Throughput per kernel at each group's largest configuration"
    groups = [(g, res.headline()[1] if g == HEADLINE_GROUP and res.headline() else res.largest(g)) for g in res.groups]
    if not groups:
        return empty_figure(out, name, title, "no points")
    fig, ax = plt.subplots(figsize=(10, 5.8), layout="constrained")
    w, offs = bar_offsets(len(res.kernels))
    xs = np.arange(len(groups))
    top = 0
    for k, off in zip(res.kernels, offs):
        color, _ = res.style[k]
        for i, (g, cfg) in enumerate(groups):
            p = res.get(g, cfg, k)
            v = m_paths(p) if ok(p) else None
            if v is None:
                mark_missing(ax, xs[i] + off, p)
                continue
            ax.bar(xs[i] + off, v, w, color=color, edgecolor="white", linewidth=0.5)
            ax.text(xs[i] + off, v, fmt_rate(v), ha="center", va="bottom", fontsize=7.5)
            top = max(top, v)
        ax.bar(np.nan, np.nan, color=color, label=k)
    for i, (g, cfg) in enumerate(groups):
        wf, mk = res.get_ok(g, cfg, "wavefront"), res.get_ok(g, cfg, "megakernel")
        text = (f"wavefront ÷ megakernel\nspeed: {seconds(mk) / seconds(wf):.2f}×" if wf and mk
                else "wavefront ÷ megakernel:\nn/a")
        ax.text(xs[i], (top or 1) * 1.1, text, ha="center", va="bottom", fontsize=9,
                bbox=dict(boxstyle="round,pad=0.3", fc="#f7f7f7", ec="#999999"))
    ax.set_ylim(0, (top or 1) * 1.3)
    ax.set_xlim(-0.5, len(groups) - 0.5)
    ax.set_xticks(xs)
    ax.set_xticklabels([f"{g}: {res.scene(g)}\n{cfg[0]}x{cfg[1]}, {cfg[2]} spp, depth {cfg[3]}" for g, cfg in groups])
    ax.set_xlabel("scene (group) and configuration")
    ax.set_ylabel(f"M paths/s ({res.median_of()})")
    ax.grid(axis="x", visible=False)
    legend_above(ax, ncol=len(res.kernels))
    fig.suptitle(f"{title} ({res.device_name()})")
    return save(fig, out, name)


# ----------------------------------------------------------------------------
# tables.md


def tables_md(res):
    h = res.header
    out = ["# Benchmark tables", "",
           f"Generated by bench/plot.py from the results of `wavetrace bench` ({h.get('date', 'no date')}, "
           f"commit {h.get('commit') or 'not recorded'}).", ""]

    hl = res.headline()
    cfg = hl[1] if hl else HEADLINE
    out += [f"## Memory strategy: {res.study_scene()} at {cfg[0]}x{cfg[1]}, {cfg[2]} spp, depth {cfg[3]}", ""]
    rows = headline_rows(res)
    head = [c.replace("\n", " ") for c in HEADLINE_COLUMNS]
    head[0] = "kernel / source"
    body = []
    for r in rows:
        if r[7]:
            body.append([r[0], r[1], f"FAILED: {r[7]}", "—", "—", "—", "—"])
        else:
            body.append(r[:7])
    out += [md_table(head, body), "",
            "The study's rows are from the reference study; it estimated rays as paths × 22.5. "
            "Our rays are counted.", ""]

    out += ["## Every point", ""]
    head = ["group", "scene", "WxH", "spp", "depth", "kernel", "seconds median (min–max)", "M rays/s",
            "M paths/s", "rays/path", "check diff", "check"]
    body = []
    order = {k: i for i, k in enumerate(res.kernels)}
    gorder = {g: i for i, g in enumerate(res.groups)}
    points = sorted(res.points, key=lambda p: (gorder.get(p.get("group"), 0), config_of(p)[0] * config_of(p)[1],
                                              config_of(p)[2], config_of(p)[3], order.get(p.get("kernel"), 99)))
    for p in points:
        c = config_of(p)
        depth = str(c[3])
        rr = p.get("roulette_depth")
        if isinstance(rr, int) and rr != c[3]:
            depth += f" (roulette from {rr})"
        check = p.get("check") if isinstance(p.get("check"), dict) else {}
        diff = number(check.get("mean_abs_diff"))
        passed = check.get("passed")
        verdict = "pass" if passed is True else ("FAIL" if passed is False else "not run")
        if ok(p):
            lo, hi = number(p.get("seconds_min")), number(p.get("seconds_max"))
            secs = fmt_seconds(seconds(p))
            if lo is not None and hi is not None:
                secs += f" ({fmt_seconds(lo)}–{fmt_seconds(hi)})"
            rest = [fmt_rate(m_rays(p)), fmt_rate(m_paths(p)), fmt_rpp(rays_per_path(p))]
        else:
            secs = f"FAILED: {short_status(p, 200)}"
            rest = ["—", "—", "—"]
        body.append([p.get("group", "?"), scene_name(p.get("scene")), res_label(c), c[2], depth, p.get("kernel", "?"),
                     secs] + rest + ["—" if diff is None else f"{diff:.2e}", verdict])
    chk = h.get("check") or {}
    out += [md_table(head, body) if body else "No points.", "",
            f"Image check: mean absolute difference per channel from the {chk.get('against', 'megakernel')}'s "
            f"image at {chk.get('spp', '?')} spp, bound {chk.get('max_mean_abs_diff', '?')}.", ""]

    out += ["## Wavefront stages (ms, summed over iterations, from the median run)", ""]
    head = ["group", "WxH", "spp/depth", "kernel"] + res.stages + ["sum", "render ms (median)", "iterations"]
    body = []
    for p in points:
        if not str(p.get("kernel", "")).startswith("wavefront"):
            continue
        c = config_of(p)
        stage_ms = p.get("stage_ms")
        if not ok(p) or not isinstance(stage_ms, dict):
            body.append([p.get("group", "?"), res_label(c), f"{c[2]}/{c[3]}", p.get("kernel", "?")]
                        + [f"FAILED: {short_status(p)}" if not ok(p) else "no stage times"]
                        + [""] * (len(res.stages) + 2))
            continue
        vals = [number(stage_ms.get(s)) for s in res.stages]
        live = p.get("live_per_bounce")
        body.append([p.get("group", "?"), res_label(c), f"{c[2]}/{c[3]}", p.get("kernel", "?")]
                    + ["—" if v is None else f"{v:.1f}" for v in vals]
                    + [f"{sum(v or 0 for v in vals):.1f}", f"{seconds(p) * 1000:.1f}",
                       len(live) if isinstance(live, list) else "—"])
    out += [md_table(head, body) if body else "No wavefront points.", ""]

    out += ["## Device and build", ""]
    d = h.get("device") or {}
    info = [("date", h.get("date")), ("commit", h.get("commit") or "not recorded"), ("backend", h.get("backend")),
            ("build flags", h.get("build_flags")), ("device", d.get("name")), ("SMs", d.get("sm_count")),
            ("SM clock (MHz)", d.get("sm_clock_mhz")), ("memory clock (MHz)", d.get("memory_clock_mhz")),
            ("memory (GiB)", f"{d['memory_gib']:.1f}" if number(d.get("memory_gib")) else None),
            ("driver version", d.get("driver_version")), ("runtime version", d.get("runtime_version")),
            ("warm-up renders", h.get("warmup")), ("timed repeats", h.get("repeats")),
            ("image check", f"{chk.get('spp', '?')} spp against the {chk.get('against', '?')}, "
                            f"mean abs diff ≤ {chk.get('max_mean_abs_diff', '?')}" if chk else None)]
    out += [md_table(["", ""], [[k, v] for k, v in info if v is not None]), ""]
    return "\n".join(out)


# ----------------------------------------------------------------------------


def main():
    ap = argparse.ArgumentParser(description="Plots and tables from the results.json of `wavetrace bench`.")
    ap.add_argument("results", help="results.json written by wavetrace bench")
    ap.add_argument("--out", default=None, help="folder for the PNGs and tables.md (default: the results' folder)")
    args = ap.parse_args()
    try:
        with open(args.results, encoding="utf-8") as f:
            doc = json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"plot.py: {args.results}: {e}")
    if not isinstance(doc, dict):
        sys.exit(f"plot.py: {args.results}: not a results object")
    out = args.out or os.path.dirname(os.path.abspath(args.results))
    os.makedirs(out, exist_ok=True)
    res = Results(doc)
    failed = [p for p in res.points if not ok(p)]
    print(f"plot.py: {len(res.points)} points, {len(failed)} not ok", file=sys.stderr)

    status = 0
    # One broken figure should not cost the others, nor the tables.
    for fn in (plot_table1, plot_resolution_scaling, plot_throughput, plot_sample_scaling, plot_heatmap,
               plot_stages, plot_kernels_per_scene):
        try:
            print(f"wrote {fn(res, out)}")
        except Exception:  # noqa: BLE001 - reported and counted in the exit code
            plt.close("all")
            status = 1
            print(f"plot.py: {fn.__name__} failed:\n{traceback.format_exc()}", file=sys.stderr)
    path = os.path.join(out, "tables.md")
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(tables_md(res))
    os.replace(tmp, path)
    print(f"wrote {path}")
    return status


if __name__ == "__main__":
    sys.exit(main())
