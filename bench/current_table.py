#!/usr/bin/env python3
"""The table of current figures at the top of bench/RESULTS.md: one row per scene,
one column per wavetrace kernel, M paths/s in the cells, generated from the results
files under bench/results/.

    python3 bench/current_table.py            # rewrite the table in RESULTS.md
    python3 bench/current_table.py --check    # exit 1 if the table there is stale
    python3 bench/current_table.py --print    # the table on stdout, nothing written

What it reads:

- every `wavetrace bench` results file (JSON with `commit`, `date`, `device` and
  `points`) under bench/results/, but for results/scaling/, whose sweeps over scene
  size, resolution and spp are synthetic series, not scenes;
- results/mitsuba-xml-gpu/mitsuba-xml.tsv (bench/mitsuba_xml.sh, the scenes of
  scenes/mitsuba/ read from their .xml). The TSV records neither the commit nor the
  GPU; those and the date are read from the paragraph of RESULTS.md that names its
  directory.

For each scene it keeps the largest configuration any file holds (most paths, then
the deepest), and of the files holding that configuration the newest (the file's
`date`). Only files measured on one GPU model are combined: that of the newest file,
unless --gpu names another; the rest are named under the table as left out. Each row
names the commit and date of its run, and the files are listed under the table.

Standard library only.
"""

import argparse
import csv
import difflib
import glob
import json
import os
import re
import sys
from dataclasses import dataclass, field

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_RESULTS_DIR = os.path.join(HERE, "results")
DEFAULT_RESULTS_MD = os.path.join(HERE, "RESULTS.md")

BEGIN = "<!-- current-figures:begin -->"
END = "<!-- current-figures:end -->"
HEADING = "## Current figures"
HISTORY_HEADING = "## History"
REGENERATE = ("Regenerate the table from the results files with "
              "`python3 bench/current_table.py` (`--check` writes nothing and exits 1 "
              "if it is stale).")
HISTORY_INTRO = ("Every run so far as it was written up at the time, later sections "
                 "above earlier ones.")

# Left out of the discovery: directories (relative to results/) and why.
EXCLUDED_DIRS = {
    "scaling": "synthetic sweeps of scene size, resolution and spp, not scenes",
}
# TSV results of bench/mitsuba_xml.sh on a GPU (relative to results/).
XML_TSVS = ["mitsuba-xml-gpu/mitsuba-xml.tsv"]
KERNEL_ORDER = ["megakernel", "megakernel-constant", "wavefront", "wavefront-sorted",
                "wavefront-unsorted"]


class SourceError(Exception):
    """A results file is missing, unreadable or lacks what the table needs."""


@dataclass
class Cell:
    m_paths_per_s: float | None  # None where the point did not run (status)
    status: str = "ok"


@dataclass
class Row:
    scene: str   # the scene's file, as the results name it
    config: tuple  # (width, height, spp, depth or None, nee or None)
    cells: dict = field(default_factory=dict)  # kernel -> Cell


@dataclass
class Source:
    path: str      # the file
    commit: str
    date: str      # ISO 8601, as recorded
    gpu: str
    method: str    # how a figure was timed, in words
    kernels: list  # in the file's order
    rows: list     # of Row, in the file's order
    origin: str = ""  # where commit/GPU/date came from, if not the file itself
    rank: int = 0     # rows of lower ranks first: bench files 0, the XML scenes 1


def short_commit(commit):
    return commit[:7] if re.fullmatch(r"[0-9a-f]{8,40}", commit) else commit


def _open_text(path):
    try:
        with open(path, encoding="utf-8") as f:
            return f.read()
    except FileNotFoundError:
        raise SourceError(f"{path}: no such results file") from None
    except OSError as e:
        raise SourceError(f"{path}: cannot be read ({e.strerror})") from None


def _rows_from_points(points, path):
    rows = {}
    for i, p in enumerate(points):
        try:
            scene, kernel, status = p["scene"], p["kernel"], p.get("status", "ok")
            config = (int(p["width"]), int(p["height"]), int(p["spp"]),
                      int(p["depth"]), int(p["nee"]) if "nee" in p else None)
            value = float(p["m_paths_per_s"]) if status == "ok" else None
        except (KeyError, TypeError, ValueError) as e:
            raise SourceError(f"{path}: point {i} lacks a usable field ({e})") from None
        row = rows.setdefault((scene, config), Row(scene, config))
        row.cells[kernel] = Cell(value, status)
    return list(rows.values())


def read_bench_json(path):
    """A `wavetrace bench` results file (results.json) as a Source."""
    try:
        doc = json.loads(_open_text(path))
    except json.JSONDecodeError as e:
        raise SourceError(f"{path}: not JSON ({e})") from None
    if not is_bench_results(doc):
        raise SourceError(f"{path}: not a `wavetrace bench` results file "
                          "(needs commit, date, device.name and points)")
    rows = _rows_from_points(doc["points"], path)
    kernels = list(doc.get("kernels") or [])
    for row in rows:
        kernels += [k for k in row.cells if k not in kernels]
    repeats, warmup = doc.get("repeats"), doc.get("warmup")
    method = "`wavetrace bench`"
    if repeats is not None and warmup is not None:
        method += (f", the median of {repeats} timed render{'s' * (repeats != 1)} "
                   f"after {warmup} warm-up{'s' * (warmup != 1)}")
    return Source(path, str(doc["commit"]), str(doc["date"]), str(doc["device"]["name"]),
                  method, kernels, rows)


def is_bench_results(doc):
    return (isinstance(doc, dict) and isinstance(doc.get("points"), list)
            and bool(doc.get("commit")) and bool(doc.get("date"))
            and isinstance(doc.get("device"), dict) and bool(doc["device"].get("name")))


def find_provenance(history, directory):
    """Commit, GPU and date of a run whose files lack them, from the first paragraph of
    RESULTS.md's text (history) that names its directory and records all three."""
    for para in re.split(r"\n\s*\n", history):
        if directory not in para:
            continue
        text = " ".join(para.split())
        commit = re.search(r"\bat `([0-9a-f]{7,40})`", text)
        gpu = re.search(r"\bon (?:an? |one )?(NVIDIA [A-Za-z0-9 ]+?)\s*[(,:.]", text)
        date = re.search(r"\b(\d{4}-\d{2}-\d{2})\b", text)
        if commit and gpu and date:
            return {"commit": commit.group(1), "gpu": gpu.group(1), "date": date.group(1)}
    return None


def read_xml_tsv(path, provenance, origin=""):
    """bench/mitsuba_xml.sh's mitsuba-xml.tsv (one row per scene of scenes/mitsuba/)."""
    text = _open_text(path)
    reader = csv.DictReader(text.splitlines(), delimiter="\t")
    suffix = "_m_paths_per_s"
    kernels = [c[:-len(suffix)] for c in (reader.fieldnames or [])
               if c.endswith(suffix) and c != "mitsuba" + suffix]
    if not kernels:
        raise SourceError(f"{path}: no <kernel>_m_paths_per_s column")
    rows = []
    for i, r in enumerate(reader):
        try:
            config = (int(r["width"]), int(r["height"]), int(r["spp"]), None, None)
            row = Row(f"scenes/mitsuba/{r['scene']}.xml", config)
            for k in kernels:
                row.cells[k] = Cell(float(r[k + suffix]))
        except (KeyError, TypeError, ValueError) as e:
            raise SourceError(f"{path}: row {i + 1} lacks a usable field ({e})") from None
        rows.append(row)
    return Source(path, provenance["commit"], provenance["date"], provenance["gpu"],
                  "`bench/mitsuba_xml.sh`, one timed render after a warm-up",
                  kernels, rows, origin, rank=1)


def discover(results_dir, history, results_md_name="RESULTS.md", tsvs=tuple(XML_TSVS)):
    """Every source under results_dir: the bench JSON files (but EXCLUDED_DIRS) and
    the TSVs (relative to results_dir; each must be there), their commit, GPU and
    date from history (RESULTS.md's text)."""
    if not os.path.isdir(results_dir):
        raise SourceError(f"{results_dir}: no such results directory")
    sources = []
    for path in sorted(glob.glob(os.path.join(results_dir, "**", "*.json"), recursive=True)):
        rel = os.path.relpath(path, results_dir).replace(os.sep, "/")
        if rel.split("/")[0] in EXCLUDED_DIRS:
            continue
        try:
            doc = json.loads(_open_text(path))
        except json.JSONDecodeError:
            continue  # not a results file of either kind
        if is_bench_results(doc):
            sources.append(read_bench_json(path))
    for rel in tsvs:
        path = os.path.join(results_dir, rel)
        if not os.path.isfile(path):
            raise SourceError(f"{path}: no such results file")
        directory = "results/" + os.path.dirname(rel) + "/"
        prov = find_provenance(history, directory)
        if prov is None:
            raise SourceError(f"{path}: records no commit or GPU, and no paragraph of "
                              f"{results_md_name} naming {directory} records them "
                              "(`at <commit>`, `on an NVIDIA ...`, a date)")
        sources.append(read_xml_tsv(path, prov, f"as {results_md_name} records the run"))
    if not sources:
        raise SourceError(f"{results_dir}: holds no results file")
    return sources


def _config_size(config):
    w, h, spp, depth, nee = config
    return (w * h * spp, depth or 0, nee or 0)


def select(sources, gpu=None):
    """(gpu, rows as (Row, Source), sources left out for their GPU)."""
    if gpu is None:
        gpu = max(sources, key=lambda s: s.date).gpu
    used = [s for s in sources if s.gpu == gpu]
    other = [s for s in sources if s.gpu != gpu]
    if not used:
        raise SourceError(f"no results file was measured on {gpu}")
    # The study's grid first (the headline scene), then the other bench files, then
    # the XML scenes; by file within each.
    used.sort(key=lambda s: (s.rank, not any(r.scene.endswith("seed57.json") for r in s.rows),
                             s.path))
    largest = {}
    for s in used:
        for r in s.rows:
            if r.scene not in largest or _config_size(r.config) > _config_size(largest[r.scene]):
                largest[r.scene] = r.config
    best = {}
    order = []
    for s in used:
        for r in s.rows:
            if r.config != largest[r.scene]:
                continue
            if r.scene not in best:
                order.append(r.scene)
                best[r.scene] = (r, s)
            elif s.date > best[r.scene][1].date:
                best[r.scene] = (r, s)
    return gpu, [best[scene] for scene in order], other


def _fmt(value):
    return f"{value:.0f}" if value >= 100 else f"{value:.1f}"


def _config_text(config):
    w, h, spp, depth, nee = config
    text = f"{w}x{h}, {spp} spp"
    if depth is not None:
        text += f", depth {depth}"
    if nee == 0:
        text += ", no light sampling"
    return text


def _scene_names(rows):
    base = {}
    for r, _ in rows:
        base.setdefault(os.path.basename(r.scene), set()).add(r.scene)
    return {r.scene: (os.path.basename(r.scene) if len(base[os.path.basename(r.scene)]) == 1
                      else r.scene) for r, _ in rows}


def build_table(sources, gpu=None, link_base=None):
    """The Markdown between the markers. link_base: the directory the file links are
    relative to (RESULTS.md's); None gives the paths as they are."""
    gpu, rows, other = select(sources, gpu)
    kernels = []
    for _, s in rows:
        kernels += [k for k in s.kernels if k not in kernels]
    kernels.sort(key=lambda k: (KERNEL_ORDER.index(k) if k in KERNEL_ORDER else len(KERNEL_ORDER), k))
    used = []
    for _, s in rows:
        if s not in used:
            used.append(s)
    newest = max(s.date for s in used)[:10]

    def where(path):
        return (os.path.relpath(path, link_base) if link_base else path).replace(os.sep, "/")

    names = _scene_names(rows)
    out = [f"M paths/s (millions of paths, width x height x spp, per second of render "
           f"time) of each wavetrace kernel on one {gpu}, as of {newest}: each scene's "
           f"newest run at its largest measured configuration, the row's fastest in bold, "
           f"`-` where a kernel did not run; each row names the commit and date of its "
           f"run, and its file is listed below the table.",
           "",
           "| scene | size, spp, depth | " + " | ".join(kernels) + " | commit, date |",
           "| --- | --- | " + " | ".join("---:" for _ in kernels) + " | --- |"]
    for r, s in rows:
        values = [_fmt(c.m_paths_per_s) for c in r.cells.values() if c.m_paths_per_s is not None]
        top = max(values, key=float) if len(values) > 1 else None  # ties as printed all bold
        cells = []
        for k in kernels:
            c = r.cells.get(k)
            if c is None:
                cells.append("-")
            elif c.m_paths_per_s is None:
                cells.append("error")
            elif top is not None and _fmt(c.m_paths_per_s) == top:
                cells.append(f"**{_fmt(c.m_paths_per_s)}**")
            else:
                cells.append(_fmt(c.m_paths_per_s))
        out.append(f"| {names[r.scene]} | {_config_text(r.config)} | " + " | ".join(cells)
                   + f" | `{short_commit(s.commit)}`, {s.date[:10]} |")
    out += ["", "Files:", ""]
    for s in used:
        line = (f"- [{where(s.path)}]({where(s.path)}): `{short_commit(s.commit)}`, "
                f"{s.date}, {s.method}")
        if s.origin:
            line += f"; commit, GPU and date {s.origin} (the file has none)"
        out.append(line + ".")
    if other:
        out += ["", "Left out, measured on another GPU: " + ", ".join(
            f"{where(s.path)} ({s.gpu})" for s in other) + "."]
    return "\n".join(out)


def split_results_md(text):
    """(before, region, after) around the markers, or None where they are absent."""
    b, e = text.find(BEGIN), text.find(END)
    if b < 0 and e < 0:
        return None
    if b < 0 or e < b:
        raise SourceError(f"RESULTS.md: the markers {BEGIN} and {END} are not a pair")
    return text[:b + len(BEGIN)], text[b + len(BEGIN):e], text[e:]


def history_text(text):
    """RESULTS.md without the generated region (where provenance is looked up)."""
    parts = split_results_md(text)
    return text if parts is None else parts[0] + parts[2]


def update_results_md(text, table):
    """RESULTS.md's text with the region replaced by table; where there are no markers
    yet, a Current figures section under the title and a History heading above the
    rest, which is kept as it is."""
    parts = split_results_md(text)
    if parts is not None:
        return parts[0] + "\n" + table + "\n" + parts[2]
    lines = text.split("\n")
    title, rest = ([lines[0]], lines[1:]) if lines and lines[0].startswith("# ") else ([], lines)
    while rest and not rest[0].strip():
        rest = rest[1:]
    head = title + ([""] if title else []) + [
        HEADING, "", BEGIN, table, END, "", REGENERATE, "", HISTORY_HEADING, "",
        HISTORY_INTRO, ""]
    return "\n".join(head + rest)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true",
                    help="exit 1 if RESULTS.md's table differs from the files'")
    ap.add_argument("--print", action="store_true", help="print the table, write nothing")
    ap.add_argument("--results-dir", default=DEFAULT_RESULTS_DIR)
    ap.add_argument("--results-md", default=DEFAULT_RESULTS_MD)
    ap.add_argument("--gpu", help="the GPU model to tabulate (default: the newest file's)")
    args = ap.parse_args(argv)
    name = os.path.basename(args.results_md)
    try:
        text = _open_text(args.results_md)
        sources = discover(args.results_dir, history_text(text), name)
        table = build_table(sources, args.gpu, os.path.dirname(os.path.abspath(args.results_md)))
    except SourceError as e:
        print(f"current_table: {e}", file=sys.stderr)
        return 2
    if args.print:
        print(table)
        return 0
    new = update_results_md(text, table)
    if args.check:
        if new == text:
            return 0
        sys.stderr.writelines(difflib.unified_diff(
            text.splitlines(True), new.splitlines(True),
            f"{name} (as it is)", f"{name} (from the files)"))
        print(f"current_table: {name}'s current figures are stale; run "
              "python3 bench/current_table.py", file=sys.stderr)
        return 1
    if new != text:
        with open(args.results_md, "w", encoding="utf-8") as f:
            f.write(new)
    return 0


if __name__ == "__main__":
    sys.exit(main())
