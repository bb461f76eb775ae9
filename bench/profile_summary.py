#!/usr/bin/env python3
"""Summarises the Nsight Compute profiles written by scripts/profile.sh.

Reads profile-<scene>-<kernel>.csv (ncu --csv --page raw) from a results folder and
writes profiles.md there: per scene and profiled launch, registers per thread, achieved occupancy,
warp execution efficiency, DRAM and memory-system throughput and duration. The
same numbers go to profiles.json for plots and tables.
"""
import argparse
import csv
import glob
import json
import os
import re

SCENES = ["seed57", "divergent"]
COLUMNS = {
    "registers": "launch__registers_per_thread",
    "occupancy_pct": "sm__warps_active.avg.pct_of_peak_sustained_active",
    "threads_per_warp_instruction": "smsp__thread_inst_executed_per_inst_executed.ratio",
    "dram_pct": "dram__throughput.avg.pct_of_peak_sustained_elapsed",
    "memory_pct": "gpu__compute_memory_throughput.avg.pct_of_peak_sustained_elapsed",
    "duration_ns": "gpu__time_duration.sum",
}


def number(text):
    return float(text.replace(",", ""))


def read_profile(path):
    """Rows of one ncu CSV: its header line starts with "ID"; a units line follows."""
    with open(path, newline="") as f:
        lines = [line for line in f if line.startswith('"')]
    rows = list(csv.reader(lines))
    if len(rows) < 3:
        return []
    header, data = rows[0], rows[2:]
    out = []
    for row in data:
        rec = dict(zip(header, row))
        function = rec["Kernel Name"].split("(")[0]
        # A wavefront stage runs as the generic stage kernel over its item type:
        # "for_each_kernel<wt::ShadeItem>" is the shade stage.
        stage = re.search(r"<(?:\w+::)*(\w+)Item>", function)
        name = stage.group(1).lower() if stage else function.split("::")[-1]
        item = {"launch": name}
        for key, column in COLUMNS.items():
            item[key] = number(rec[column]) if column in rec else float("nan")
        item["warp_efficiency_pct"] = 100.0 * item["threads_per_warp_instruction"] / 32.0
        out.append(item)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", help="folder holding profile-<scene>-<kernel>.csv")
    args = ap.parse_args()
    profiles = {}
    for scene in SCENES:
        prefix = os.path.join(args.results, "profile-%s-" % scene)
        for path in sorted(glob.glob(prefix + "*.csv")):
            profiles.setdefault(scene, {})[path[len(prefix):-len(".csv")]] = read_profile(path)
    lines = [
        "| scene | kernel | launch | registers / thread | achieved occupancy | warp execution efficiency "
        "| DRAM throughput | memory throughput | duration |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for scene, kernels in profiles.items():
        for k, rows in kernels.items():
            for r in rows:
                lines.append("| %s | %s | %s | %d | %.1f%% | %.1f%% | %.1f%% | %.1f%% | %.3f ms |" % (
                    scene, k, r["launch"], r["registers"], r["occupancy_pct"], r["warp_efficiency_pct"],
                    r["dram_pct"], r["memory_pct"], r["duration_ns"] / 1e6))
    with open(os.path.join(args.results, "profiles.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(args.results, "profiles.json"), "w") as f:
        json.dump(profiles, f, indent=1)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
