#!/usr/bin/env python3
"""Bytes per ray of the wavefront's stages, from the profiles scripts/bytes-per-ray.sh writes.

Reads bytes-<label>-<kernel>.csv (ncu --csv --page raw: one row per kernel launch)
with its bytes-<label>-<kernel>.stats.json (the render's --stats) and .cmd (the
command) from a results folder, and writes bytes_per_ray.md and bytes_per_ray.json
there: per stage (the item type of the generic stage kernel, or CUB's compact and
sort), the DRAM bytes read and written, the L2 traffic, the items the stage handled
and the bytes per item and per ray; the whole render's DRAM bytes per ray; each
bounce on its own. With --before OLD_RESULTS (a folder holding an earlier
bytes_per_ray.json) it adds a before/after table per stage.

Items, from the source (stages/wavefront.hpp, stages/intersect.hpp, stages/shade.hpp):
  intersect  launched over the wave's capacity; its items are the bounce's live rays
             (the stats' live_per_bounce, one entry per intersect launch, in order).
             The slots past them only write a miss entry.
  advance    AdvanceCountersItem, one thread a bounce.
  compact    CUB's select over the capacity's sort entries (items: entries scanned).
  sort       CUB's radix sort over the bounce's hits (items: hits).
  shade      launched over the bounce's hits: grid x block, which exceeds the hits
             by less than one block (ncu sees no other count).
  shadow     launched over the hits, works on the queued light samples: the stats'
             shadow_rays (a window of launches: the render's share of them).
A profile of a window of launches (--launch-skip/--launch-count) is taken to lie in
the full-wave steady state: every slot live, so a bounce's rays are the wave's
capacity (the largest entry of live_per_bounce). Only the window's whole bounces,
from one intersect launch to the next, are counted.

  python3 bench/bytes_per_ray.py RESULTS [--before OLD_RESULTS]
  python3 bench/bytes_per_ray.py --self-test
"""
import argparse
import csv
import glob
import json
import os
import re
import sys
import tempfile

METRICS = {
    "dram_read": "dram__bytes_read.sum",
    "dram_write": "dram__bytes_write.sum",
    "l2": "lts__t_bytes.sum",
    "l2_read_sectors": "lts__t_sectors_op_read.sum",
    "l2_write_sectors": "lts__t_sectors_op_write.sum",
    "l2_atom_sectors": "lts__t_sectors_op_atom.sum",
    "l2_red_sectors": "lts__t_sectors_op_red.sum",
    "duration_ns": "gpu__time_duration.sum",
    "grid": "launch__grid_size",
    "block": "launch__block_size",
    "threads": "launch__thread_count",
    "passes": "profiler__replayer_passes",
    "backed_up": "profiler__replayer_bytes_mem_backed_up.sum",
}
SECTOR_BYTES = 32
# Stage order in the tables: the order they run in a bounce.
STAGE_ORDER = ["intersect", "advance", "compact", "sort", "shade", "shadow"]
ITEM_STAGES = {"Intersect": "intersect", "AdvanceCounters": "advance", "Shade": "shade", "Shadow": "shadow"}
UNITS = {"intersect": "rays", "advance": "launches", "compact": "entries", "sort": "hits", "shade": "hits",
         "shadow": "shadow rays"}

_PREFIX = {"": 1.0, "K": 1e3, "k": 1e3, "M": 1e6, "G": 1e9, "T": 1e12}
_TIME = {"ns": 1.0, "nsecond": 1.0, "us": 1e3, "usecond": 1e3, "ms": 1e6, "msecond": 1e6, "s": 1e9, "second": 1e9}


def number(text, unit=""):
    """A value of ncu's CSV in its base unit (bytes, sectors, ns): "1,234" -> 1234.0,
    ("1.5", "Mbyte") -> 1.5e6. Empty or "n/a" -> None."""
    text = text.strip().replace(",", "")
    if text in ("", "n/a", "N/A", "nan"):
        return None
    value = float(text)
    unit = unit.strip()
    if unit in _TIME:
        return value * _TIME[unit]
    m = re.fullmatch(r"([KkMGT]?)i?(byte|B|sector|cycle|inst|warp|thread|block|request|pass)?", unit)
    if m and (m.group(1) == "" or m.group(2)):
        scale = _PREFIX[m.group(1)]
        if unit.startswith(("Ki", "Mi", "Gi", "Ti")):
            scale = 1024.0 ** (" KMGT".index(m.group(1)))
        return value * scale
    return value  # %, ratios and units without a prefix


def stage_of(kernel_name):
    """(stage, function) of a kernel launch: the stage kernels are
    for_each_kernel<IntersectItem<1u>> and the like; compact and sort are CUB's."""
    function = kernel_name.strip()
    if function.startswith("void "):
        function = function[5:]
    # The item type: the first "...Item" name in the template arguments.
    m = re.search(r"(?:\w+::)*(\w+?)Item\b", function)
    if m and "for_each" in function:
        return ITEM_STAGES.get(m.group(1), m.group(1).lower()), function
    if re.search(r"RadixSort|Onesweep", function):
        return "sort", function
    if re.search(r"Select|Compact", function):
        return "compact", function
    return function.split("<")[0].split("(")[0].split("::")[-1], function


def read_ncu_csv(path):
    """One dict per launch, in launch order: id, kernel, stage and the METRICS
    present (base units). Lines that are not CSV rows (ncu's ==PROF== notes, the
    application's output) are skipped; the header row starts with "ID", the units
    row follows it."""
    with open(path, newline="") as f:
        lines = [line for line in f if line.startswith('"')]
    rows = list(csv.reader(lines))
    start = next((i for i, r in enumerate(rows) if r and r[0] == "ID"), None)
    if start is None or len(rows) < start + 2:
        return []
    header, units = rows[start], rows[start + 1]
    out = []
    for row in rows[start + 2:]:
        if not row or row[0] == "ID":
            continue
        rec = dict(zip(header, row))
        unit = dict(zip(header, units))
        launch = {"id": int(number(rec["ID"])), "kernel": rec.get("Kernel Name", "")}
        launch["stage"], launch["function"] = stage_of(launch["kernel"])
        for key, column in METRICS.items():
            if column in rec:
                launch[key] = number(rec[column], unit.get(column, ""))
        if launch.get("threads") is None and launch.get("grid") is not None and launch.get("block") is not None:
            launch["threads"] = launch["grid"] * launch["block"]
        out.append(launch)
    out.sort(key=lambda r: r["id"])
    return out


def group_bounces(launches):
    """Launches split at each intersect launch: [(launches before the first), [bounce 0], ...]."""
    before, bounces = [], []
    for launch in launches:
        if launch["stage"] == "intersect":
            bounces.append([launch])
        elif bounces:
            bounces[-1].append(launch)
        else:
            before.append(launch)
    return before, bounces


def value(launch, key):
    v = launch.get(key)
    return 0.0 if v is None else v


def add_launch(stages, launch):
    """Adds one launch's counters to stages[its stage]."""
    t = stages.setdefault(launch["stage"], {"launches": 0, "dram_read": 0.0, "dram_write": 0.0, "l2": 0.0,
                                            "l2_read": 0.0, "l2_write": 0.0, "l2_atom": 0.0, "l2_red": 0.0,
                                            "duration_ns": 0.0})
    t["launches"] += 1
    for key in ("dram_read", "dram_write", "l2", "duration_ns"):
        t[key] += value(launch, key)
    for key in ("read", "write", "atom", "red"):
        t["l2_" + key] += value(launch, "l2_%s_sectors" % key) * SECTOR_BYTES


def analyse(launches, stats, command=""):
    """Per stage, per bounce and whole-render sums of one profile."""
    live = [int(x) for x in stats.get("live_per_bounce", [])]
    capacity = max(live) if live else 0
    before, bounces = group_bounces(launches)
    window = "--launch-skip" in command or "--launch-count" in command
    aligned = not window and len(bounces) == len(live) and not before
    notes = []
    if window:
        if before:
            notes.append("%d launches before the window's first intersect launch left out" % len(before))
        if len(bounces) > 1:
            notes.append("%d launches after the window's last intersect launch left out (an incomplete bounce)" %
                         len(bounces[-1]))
            bounces = bounces[:-1]
        else:
            notes.append("the window holds no whole bounce: widen --launch-count")
            bounces = []
        before = []
    elif not aligned:
        notes.append("%d intersect launches profiled but %d bounces in the stats: rays per launch are the "
                     "launch's threads (an upper bound)" % (len(bounces), len(live)))
    have = {k for launch in launches for k, v in launch.items() if v is not None}

    per_bounce = []
    for b, group in enumerate(bounces):
        inter = group[0]
        if aligned:
            rays = live[b]
        elif window and capacity:
            rays = capacity
            if inter.get("threads") and not (capacity <= inter["threads"] < capacity + 1024):
                notes.append("bounce %d: the intersect launch's %d threads are not the wave's %d slots" %
                             (b, inter["threads"], capacity))
        else:
            rays = int(value(inter, "threads"))
        entries = capacity if capacity else int(value(inter, "threads"))
        shades = [x for x in group if x["stage"] == "shade"]
        hits = int(sum(value(x, "threads") for x in shades))
        rec = {"bounce": b, "rays": rays, "entries": entries, "hits": hits,
               "sorted": any(x["stage"] == "sort" for x in group), "stages": {}}
        for x in group:
            add_launch(rec["stages"], x)
        per_bounce.append(rec)

    rays_counted = sum(r["rays"] for r in per_bounce)
    shadow_rays = int(stats.get("shadow_rays", 0))
    if window and stats.get("rays"):
        shadow_items = shadow_rays * rays_counted / float(stats["rays"])
    else:
        shadow_items = shadow_rays

    def sum_stages(records, extra):
        stages = {}
        for r in records:
            for name, s in r["stages"].items():
                t = stages.setdefault(name, {k: 0.0 for k in s})
                for k, v in s.items():
                    t[k] += v
        for launch in extra:
            add_launch(stages, launch)
        rays = sum(r["rays"] for r in records)
        for name, t in stages.items():
            if name == "intersect":
                t["items"] = rays
            elif name == "compact":
                t["items"] = sum(r["entries"] for r in records if "compact" in r["stages"])
            elif name == "sort":
                t["items"] = sum(r["hits"] for r in records if r["sorted"])
            elif name == "shade":
                t["items"] = sum(r["hits"] for r in records)
            elif name == "shadow":
                t["items"] = shadow_items if rays == rays_counted else None
            else:
                t["items"] = t["launches"]
            t["unit"] = UNITS.get(name, "launches")
        return stages, rays

    def summary(records, extra):
        stages, rays = sum_stages(records, extra)
        total = {k: sum(t[k] for t in stages.values())
                 for k in ("dram_read", "dram_write", "l2", "l2_read", "l2_write", "l2_atom", "l2_red",
                           "duration_ns")}
        return {"rays": rays, "stages": stages, "total": total}

    result = {"mode": "window" if window else ("whole" if aligned else "unaligned"), "capacity": capacity,
              "notes": notes, "metrics": sorted(have), "per_bounce": per_bounce,
              "all": summary(per_bounce, before), "shadow_rays": shadow_items,
              "paths": stats.get("paths"), "stats_rays": stats.get("rays"),
              "passes": max((value(x, "passes") for x in launches), default=0),
              "backed_up": max((value(x, "backed_up") for x in launches), default=0)}
    # The full-wave bounces of a render that regenerates paths (a wave smaller than
    # its paths): every slot live, the first bounce (all new paths) left out.
    full = [r for r in per_bounce[1:] if aligned and capacity and r["rays"] == capacity]
    if len(full) >= 3:
        result["full_wave"] = summary(full, [])
        result["full_wave"]["bounces"] = len(full)
    return result


def fmt_bytes(b):
    if b is None:
        return ""
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if abs(b) >= scale:
            return "%.2f %s" % (b / scale, unit)
    return "%.0f B" % b


def per(b, n):
    return "%.1f" % (b / n) if n else ""


def stage_table(summary, have_ops):
    rays = summary["rays"]
    lines = ["| stage | launches | items | DRAM read / item | DRAM write / item | L2 / item | DRAM read / ray "
             "| DRAM write / ray | DRAM / ray | L2 / ray | DRAM read | DRAM write | L2 | time |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    names = sorted(summary["stages"], key=lambda n: (STAGE_ORDER.index(n) if n in STAGE_ORDER else 99, n))
    for name in names:
        t = summary["stages"][name]
        items = t["items"]
        lines.append("| %s | %d | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            name, t["launches"], ("%d %s" % (items, t["unit"])) if items is not None else "",
            per(t["dram_read"], items), per(t["dram_write"], items), per(t["l2"], items),
            per(t["dram_read"], rays), per(t["dram_write"], rays), per(t["dram_read"] + t["dram_write"], rays),
            per(t["l2"], rays), fmt_bytes(t["dram_read"]), fmt_bytes(t["dram_write"]), fmt_bytes(t["l2"]),
            "%.2f ms" % (t["duration_ns"] / 1e6) if t["duration_ns"] else ""))
    tot = summary["total"]
    lines.append("| **all** | %d | %d rays | | | | %s | %s | **%s** | %s | %s | %s | %s | %s |" % (
        sum(t["launches"] for t in summary["stages"].values()), rays, per(tot["dram_read"], rays),
        per(tot["dram_write"], rays), per(tot["dram_read"] + tot["dram_write"], rays), per(tot["l2"], rays),
        fmt_bytes(tot["dram_read"]), fmt_bytes(tot["dram_write"]), fmt_bytes(tot["l2"]),
        "%.2f ms" % (tot["duration_ns"] / 1e6) if tot["duration_ns"] else ""))
    if have_ops:
        lines += ["", "L2 requests by kind (sectors x 32 bytes), per ray:", "",
                  "| stage | L2 read / ray | L2 write / ray | L2 atomic / ray | L2 reduction / ray | per item: read "
                  "| write | atomic | reduction |",
                  "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
        for name in names + ["**all**"]:
            t = summary["stages"].get(name, tot)
            items = summary["stages"][name]["items"] if name in summary["stages"] else None
            lines.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                name, per(t["l2_read"], rays), per(t["l2_write"], rays), per(t["l2_atom"], rays),
                per(t["l2_red"], rays), per(t["l2_read"], items), per(t["l2_write"], items),
                per(t["l2_atom"], items), per(t["l2_red"], items)))
    return lines


def bounce_table(result):
    lines = ["| bounce | rays | hits (shade threads) | sorted | DRAM read | DRAM write | L2 | DRAM / ray | L2 / ray |",
             "| ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: |"]
    for r in result["per_bounce"]:
        dr = sum(s["dram_read"] for s in r["stages"].values())
        dw = sum(s["dram_write"] for s in r["stages"].values())
        l2 = sum(s["l2"] for s in r["stages"].values())
        lines.append("| %d | %d | %d | %s | %s | %s | %s | %s | %s |" % (
            r["bounce"], r["rays"], r["hits"], "yes" if r["sorted"] else "", fmt_bytes(dr), fmt_bytes(dw),
            fmt_bytes(l2), per(dr + dw, r["rays"]), per(l2, r["rays"])))
    return lines


def run_name(path, results):
    return os.path.relpath(path, results)[len("bytes-"):-len(".csv")]


def load_runs(results):
    runs = {}
    for path in sorted(glob.glob(os.path.join(results, "bytes-*.csv"))):
        name = run_name(path, results)
        base = path[:-len(".csv")]
        stats, command = {}, ""
        if os.path.exists(base + ".stats.json"):
            with open(base + ".stats.json") as f:
                stats = json.load(f)
        if os.path.exists(base + ".cmd"):
            with open(base + ".cmd") as f:
                command = f.read().strip()
        launches = read_ncu_csv(path)
        if not launches:
            runs[name] = {"error": "no launches in %s" % os.path.basename(path)}
            continue
        result = analyse(launches, stats, command)
        result["command"] = command
        if "--cache-control none" in command and result["backed_up"] > 0:
            result["notes"].append("ncu saved %s of memory before a kernel (kernel replay): with --cache-control "
                                   "none the L2 still started each kernel as if flushed" %
                                   fmt_bytes(result["backed_up"]))
        if not stats:
            result["notes"].append("no stats file: rays are the intersect launches' threads")
        missing = [METRICS[k] for k in ("dram_read", "dram_write", "l2") if k not in result["metrics"]]
        if missing:
            result["notes"].append("the CSV lacks %s (counted as 0)" % ", ".join(missing))
        runs[name] = result
    return runs


def headline(result):
    s = result["all"]
    tot = s["total"]
    rays = s["rays"]
    dram = tot["dram_read"] + tot["dram_write"]
    return rays, dram, tot["l2"]


def markdown(runs, before=None):
    lines = ["# Bytes per ray of the wavefront's stages", "",
             "Nsight Compute over `wavetrace render` (scripts/bytes-per-ray.sh). DRAM bytes are "
             "dram__bytes_read.sum and dram__bytes_write.sum, L2 bytes lts__t_bytes.sum (every request at the "
             "L2, whatever it hits); a ray is a path ray intersected (the stats' `rays`; shadow rays apart). "
             "Per ray: a stage's bytes over the profile's rays, so a column's stages add up to the whole. Items: "
             "see bench/bytes_per_ray.py.", "",
             "| profile | mode | rays | shadow rays | paths | DRAM / ray | DRAM / (ray + shadow ray) | DRAM / path "
             "| L2 / ray | ncu passes |",
             "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for name, r in runs.items():
        if "error" in r:
            lines.append("| %s | %s | | | | | | | | |" % (name, r["error"]))
            continue
        rays, dram, l2 = headline(r)
        shadow = r["shadow_rays"] or 0
        paths = r["paths"] if r["mode"] != "window" else None
        lines.append("| %s | %s | %d | %d | %s | **%s** | %s | %s | %s | %s |" % (
            name, r["mode"], rays, shadow, paths if paths else "", per(dram, rays), per(dram, rays + shadow),
            per(dram, paths) if paths else "", per(l2, rays), "%d" % r["passes"] if r["passes"] else ""))
    for name, r in runs.items():
        if "error" in r:
            continue
        have_ops = "l2_read_sectors" in r["metrics"]
        lines += ["", "## %s" % name, ""]
        if r.get("command"):
            lines += ["`%s`" % r["command"], ""]
        for note in r["notes"]:
            lines.append("- note: %s" % note)
        if r["notes"]:
            lines.append("")
        lines += stage_table(r["all"], have_ops)
        if "full_wave" in r:
            lines += ["", "The %d full-wave bounces (every one of the %d slots live; the first bounce left out):" %
                      (r["full_wave"]["bounces"], r["capacity"]), ""]
            lines += stage_table(r["full_wave"], have_ops)
        if r["mode"] != "window" and r["per_bounce"]:
            lines += ["", "<details><summary>each bounce</summary>", ""] + bounce_table(r) + ["", "</details>"]
        if before and name in before and "error" not in before[name]:
            lines += ["", "Before and after (DRAM bytes per ray; L2 bytes per ray):", ""] + compare(before[name], r)
    return "\n".join(lines) + "\n"


def compare(old, new):
    lines = ["| stage | DRAM / ray before | after | change | L2 / ray before | after | change |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"]
    o, n = old["all"], new["all"]
    names = sorted(set(o["stages"]) | set(n["stages"]),
                   key=lambda x: (STAGE_ORDER.index(x) if x in STAGE_ORDER else 99, x))

    def cell(summary, name, key):
        t = summary["stages"].get(name) if name else summary["total"]
        if t is None or not summary["rays"]:
            return None
        b = t["dram_read"] + t["dram_write"] if key == "dram" else t["l2"]
        return b / summary["rays"]

    for name in names + [None]:
        row = ["**all**" if name is None else name]
        for key in ("dram", "l2"):
            a, b = cell(o, name, key), cell(n, name, key)
            row += ["" if a is None else "%.1f" % a, "" if b is None else "%.1f" % b,
                    "%+.1f%%" % (100.0 * (b - a) / a) if a and b is not None else ""]
        lines.append("| " + " | ".join(row) + " |")
    return lines


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", nargs="?", help="folder holding bytes-<label>-<kernel>.csv")
    ap.add_argument("--before", help="an earlier results folder (its bytes_per_ray.json) to compare with")
    ap.add_argument("--self-test", action="store_true", help="check the parser on a made-up ncu CSV")
    args = ap.parse_args(argv)
    if args.self_test:
        return self_test()
    if not args.results:
        ap.error("RESULTS is required")
    runs = load_runs(args.results)
    before = None
    if args.before:
        with open(os.path.join(args.before, "bytes_per_ray.json")) as f:
            before = json.load(f)
    text = markdown(runs, before)
    with open(os.path.join(args.results, "bytes_per_ray.md"), "w") as f:
        f.write(text)
    with open(os.path.join(args.results, "bytes_per_ray.json"), "w") as f:
        json.dump(runs, f, indent=1)
    print(text)
    return 0 if runs and all("error" not in r for r in runs.values()) else 1


# --- the self-test: a made-up profile in the format of ncu --csv --page raw ---------

_CUB_INIT = ("void cub::CUB_200700_900_NS::DeviceCompactInitKernel<cub::CUB_200700_900_NS::ScanTileState<long, true>, "
             "long *>(T1, int, T2)")
_CUB_SWEEP = ("void cub::CUB_200700_900_NS::DeviceSelectSweepKernel<cub::CUB_200700_900_NS::DeviceSelectPolicy<"
              "unsigned int, unsigned char, unsigned int *, unsigned int *, long>::Policy900, unsigned int *, "
              "cub::CUB_200700_900_NS::NullType *, unsigned int *, long *, cub::CUB_200700_900_NS::ScanTileState<long, "
              "true>, wt::HitSomething, cub::CUB_200700_900_NS::NullType, long, false>(T2, T3, T4, T5, T6, T7, T8, int)")
_SORT = ("void cub::CUB_200700_900_NS::DeviceRadixSortOnesweepKernel<cub::CUB_200700_900_NS::DeviceRadixSortPolicy<"
         "unsigned int, cub::CUB_200700_900_NS::NullType, long>::Policy900, false, unsigned int, "
         "cub::CUB_200700_900_NS::NullType, long, int, int>(T5 *, T5 *, T3 *, const T3 *, T4 *, const T4 *, T6, int, int)")


def _fake_profile(folder, label, kernel, launches, stats, command, scale_unit=False):
    """Writes bytes-LABEL-KERNEL.csv, .stats.json and .cmd as the script would."""
    header = ["ID", "Process ID", "Process Name", "Host Name", "Kernel Name", "Context", "Stream", "Block Size",
              "Grid Size", "Device", "CC", "dram__bytes_read.sum", "dram__bytes_write.sum", "gpu__time_duration.sum",
              "launch__block_size", "launch__grid_size", "launch__thread_count", "lts__t_bytes.sum",
              "lts__t_sectors_op_atom.sum", "lts__t_sectors_op_read.sum", "lts__t_sectors_op_red.sum",
              "lts__t_sectors_op_write.sum", "profiler__replayer_passes"]
    units = ["", "", "", "", "", "", "", "", "", "", "", "Mbyte" if scale_unit else "byte", "byte", "ns", "", "",
             "thread", "byte", "sector", "sector", "sector", "sector", "pass"]
    base = os.path.join(folder, "bytes-%s-%s" % (label, kernel))
    with open(base + ".csv", "w", newline="") as f:
        f.write("==PROF== Connected to process 1234 (/tmp/bin/wavetrace)\n")
        w = csv.writer(f, quoting=csv.QUOTE_ALL, lineterminator="\n")
        w.writerow(header)
        w.writerow(units)
        for i, (name, block, grid, read, write, l2, ops) in enumerate(launches):
            r = "{:,}".format(read) if not scale_unit else "%.6f" % (read / 1e6)
            w.writerow([str(i), "1234", "wavetrace", "127.0.0.1", name, "1", "7", "(%d, 1, 1)" % block,
                        "(%d, 1, 1)" % grid, "0", "9.0", r, "{:,}".format(write), "{:,}".format(1000 + i), str(block),
                        "{:,}".format(grid), "{:,}".format(grid * block), "{:,}".format(l2), str(ops[2]),
                        "{:,}".format(ops[0]), str(ops[3]), "{:,}".format(ops[1]), "1"])
        f.write("==PROF== Disconnected from process 1234\n")
    with open(base + ".stats.json", "w") as f:
        json.dump(stats, f)
    with open(base + ".cmd", "w") as f:
        f.write(command + "\n")


def self_test():
    inter = "void for_each_kernel<IntersectItem<1>>(T1, unsigned int)"
    bounded = "void wt::cuda::for_each_bounded_kernel<wt::IntersectItem<3u>>(T1, unsigned int)"
    advance = "void for_each_kernel<AdvanceCountersItem>(T1, unsigned int)"
    shade = "void for_each_kernel<ShadeItem<2147483649>>(T1, unsigned int)"
    shadow = "void wt::cuda::for_each_bounded_kernel<wt::ShadowItem<2147483651u>>(T1, unsigned int)"
    assert stage_of(inter)[0] == "intersect" and stage_of(bounded)[0] == "intersect"
    assert stage_of(advance)[0] == "advance" and stage_of(shade)[0] == "shade" and stage_of(shadow)[0] == "shadow"
    assert stage_of(_CUB_INIT)[0] == "compact" and stage_of(_CUB_SWEEP)[0] == "compact"
    assert stage_of(_SORT)[0] == "sort"
    assert stage_of("void megakernel_global<1>(X)")[0] == "megakernel_global"
    assert number("1,234,567") == 1234567 and number("1.5", "Mbyte") == 1.5e6 and number("2", "usecond") == 2000
    assert number("3", "KiB") == 3072 and number("n/a") is None and number("46.5", "%") == 46.5

    # A wave of 1024 slots, three bounces (live 1024, 600, 0): intersect 1024 threads
    # (block 128), hits 500 then 0 (shade 512 threads, then no launch), a sort in
    # bounce 0, a shadow launch.
    ops = (0, 0, 0, 0)
    launches = [
        (inter, 128, 8, 40000, 30000, 100000, (1000, 800, 0, 2)),
        (advance, 128, 1, 0, 0, 64, (1, 0, 1, 0)),
        (_CUB_INIT, 128, 1, 0, 0, 512, ops),
        (_CUB_SWEEP, 128, 4, 4096, 2000, 8192, (128, 64, 0, 0)),
        (_SORT, 256, 2, 2000, 2000, 4000, (63, 63, 0, 0)),
        (shade, 128, 4, 36000, 24000, 70000, (1100, 750, 0, 3)),
        (shadow, 128, 4, 10000, 0, 22000, (700, 0, 0, 12)),
        (inter, 128, 8, 24000, 20000, 60000, (600, 600, 0, 0)),
        (advance, 128, 1, 0, 0, 64, ops),
        (_CUB_INIT, 128, 1, 0, 0, 512, ops),
        (_CUB_SWEEP, 128, 4, 4096, 0, 4096, ops),
        (inter, 128, 8, 0, 4096, 4096, ops),
        (advance, 128, 1, 0, 0, 64, ops),
        (_CUB_INIT, 128, 1, 0, 0, 512, ops),
        (_CUB_SWEEP, 128, 4, 4096, 0, 4096, ops),
    ]
    stats = {"rays": 1624, "shadow_rays": 300, "paths": 1024, "live_per_bounce": [1024, 600, 0]}
    with tempfile.TemporaryDirectory() as folder:
        _fake_profile(folder, "whole", "wavefront", launches, stats, "ncu --csv --page raw wavetrace render x.json")
        _fake_profile(folder, "whole", "scaled", launches, stats, "ncu wavetrace render x.json", scale_unit=True)
        # A window of a render whose wave is 1024 slots: the end of one bounce (left
        # out: before the first intersect launch), a whole bounce, and the start of the
        # next (left out: it may be incomplete).
        _fake_profile(folder, "steady", "wavefront", launches[4:7] + launches[0:8], stats,
                      "ncu --launch-skip 40 --launch-count 11 wavetrace render x.json")
        runs = load_runs(folder)
        text = markdown(runs)
        w = runs["whole-wavefront"]
        assert w["mode"] == "whole", w["notes"]
        a = w["all"]
        assert a["rays"] == 1624
        st = a["stages"]
        assert st["intersect"]["items"] == 1624 and st["intersect"]["launches"] == 3
        assert st["intersect"]["dram_read"] == 64000 and st["intersect"]["dram_write"] == 54096
        assert st["compact"]["launches"] == 6 and st["compact"]["items"] == 3 * 1024
        assert st["shade"]["items"] == 512 and st["sort"]["items"] == 512 and st["shadow"]["items"] == 300
        assert st["advance"]["items"] == 3
        assert st["shade"]["l2_read"] == 1100 * 32 and st["shadow"]["l2_red"] == 12 * 32
        total = sum(x[3] + x[4] for x in launches)
        assert abs(a["total"]["dram_read"] + a["total"]["dram_write"] - total) < 1e-6
        assert [r["rays"] for r in w["per_bounce"]] == [1024, 600, 0]
        assert w["per_bounce"][0]["sorted"] and not w["per_bounce"][1]["sorted"]
        assert "full_wave" not in w
        scaled = runs["whole-scaled"]["all"]["total"]
        assert abs(scaled["dram_read"] - a["total"]["dram_read"]) < 1e-3
        s = runs["steady-wavefront"]
        assert s["mode"] == "window", s
        assert len(s["per_bounce"]) == 1 and s["all"]["rays"] == 1024, s["per_bounce"]
        assert s["all"]["stages"]["shadow"]["items"] == 300 * 1024 / 1624.0
        assert s["all"]["stages"]["advance"]["launches"] == 1 and s["all"]["stages"]["shade"]["launches"] == 1
        assert s["all"]["total"]["dram_read"] == sum(x[3] for x in launches[0:7])
        assert len(s["notes"]) == 2, s["notes"]
        assert "| **all** |" in text and "## steady-wavefront" in text
        assert "%.1f" % (total / 1624.0) in text
        # Before and after: the same profile compared with itself changes nothing.
        with open(os.path.join(folder, "bytes_per_ray.json"), "w") as f:
            json.dump(runs, f)
        with open(os.path.join(folder, "bytes_per_ray.json")) as f:
            old = json.load(f)
        assert "+0.0%" in markdown(runs, old)
        # A render that regenerates paths: four full bounces after the first.
        regen = []
        for _ in range(6):
            regen += [(inter, 128, 8, 40000, 30000, 100000, ops), (advance, 128, 1, 0, 0, 64, ops),
                      (_CUB_SWEEP, 128, 4, 4096, 2000, 8192, ops), (shade, 128, 4, 36000, 24000, 70000, ops)]
        regen += [(inter, 128, 8, 0, 4096, 4096, ops)]
        _fake_profile(folder, "whole-w1024", "wavefront-unsorted", regen,
                      {"rays": 5 * 1024 + 700, "paths": 3000, "live_per_bounce": [1024] * 5 + [700, 0]},
                      "ncu wavetrace render x.json --wave-size 1024")
        r = load_runs(folder)["whole-w1024-wavefront-unsorted"]
        assert r["full_wave"]["bounces"] == 4 and r["full_wave"]["rays"] == 4 * 1024
        assert r["full_wave"]["stages"]["intersect"]["dram_read"] == 4 * 40000
    print("bytes_per_ray self-test: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
