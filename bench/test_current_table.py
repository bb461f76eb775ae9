"""Tests of bench/current_table.py: RESULTS.md's table is the one the committed
results files give, and the table builder on small made-up results files.

    /usr/bin/python3 -m pytest bench/test_current_table.py
"""

import json
import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import current_table as ct  # noqa: E402

GPU = "NVIDIA H100 80GB HBM3"


def point(scene, kernel, m_paths, width=64, height=32, spp=4, depth=8, status="ok"):
    p = {"scene": scene, "kernel": kernel, "status": status, "width": width,
         "height": height, "spp": spp, "depth": depth, "nee": 1, "group": "g"}
    if status == "ok":
        p["m_paths_per_s"] = m_paths
    return p


def write_bench(path, points, commit="abcdef0123456789", date="2026-01-02T03:04:05Z",
                gpu=GPU, kernels=("megakernel", "wavefront")):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    doc = {"backend": "cuda", "commit": commit, "date": date, "device": {"name": gpu},
           "kernels": list(kernels), "repeats": 3, "warmup": 1, "points": points}
    with open(path, "w") as f:
        json.dump(doc, f)
    return path


def table_rows(table):
    """The table's lines as lists of cells, header first (separator dropped)."""
    lines = [ln for ln in table.splitlines() if ln.startswith("| ")]
    return [[c.strip() for c in ln.strip("|").split("|")] for ln in lines if "---" not in ln]


# The committed files against the committed RESULTS.md.

def test_results_md_is_current():
    assert ct.main(["--check"]) == 0, "run: python3 bench/current_table.py"


def test_results_md_keeps_its_history_under_the_table():
    with open(ct.DEFAULT_RESULTS_MD, encoding="utf-8") as f:
        text = f.read()
    b, e = text.index(ct.BEGIN), text.index(ct.END)
    assert text.index(ct.HEADING) < b < e < text.index(ct.HISTORY_HEADING)
    assert text.index("## Headline (issue 10)") > text.index(ct.HISTORY_HEADING)
    assert "python3 bench/current_table.py" in text[e:text.index(ct.HISTORY_HEADING)]


# The builder on made-up files.

def test_rows_columns_and_caption(tmp_path):
    path = write_bench(str(tmp_path / "results" / "results.json"), [
        point("scenes/a.json", "megakernel", 10.0),
        point("scenes/a.json", "wavefront", 250.4),
        point("scenes/b.json", "megakernel", 300.0),
        point("scenes/b.json", "wavefront", 123.0),
    ])
    table = ct.build_table([ct.read_bench_json(path)], link_base=str(tmp_path))
    rows = table_rows(table)
    assert rows[0] == ["scene", "size, spp, depth", "megakernel", "wavefront", "commit, date"]
    assert rows[1] == ["a.json", "64x32, 4 spp, depth 8", "10.0", "**250**",
                       "`abcdef0`, 2026-01-02"]
    assert rows[2] == ["b.json", "64x32, 4 spp, depth 8", "**300**", "123",
                       "`abcdef0`, 2026-01-02"]
    assert len(rows) == 3
    caption = table.splitlines()[0]
    assert caption.startswith("M paths/s")
    assert GPU in caption and "2026-01-02" in caption
    assert "[results/results.json](results/results.json): `abcdef0`" in table


def test_newest_run_at_the_largest_configuration_wins(tmp_path):
    res = tmp_path / "results"
    write_bench(str(res / "old" / "results.json"), [
        point("scenes/a.json", "megakernel", 1.0, spp=64),
        point("scenes/a.json", "megakernel", 2.0, spp=4),
        point("scenes/c.json", "megakernel", 7.0),
    ], commit="1111111", date="2026-01-01T00:00:00Z")
    write_bench(str(res / "new" / "results.json"), [
        point("scenes/a.json", "megakernel", 3.0, spp=64),
        point("scenes/a.json", "wavefront", 4.0, spp=64),
        point("scenes/a.json", "megakernel", 5.0, spp=4),
    ], commit="2222222", date="2026-02-01T00:00:00Z")
    write_bench(str(res / "quick" / "results.json"), [  # newer, but smaller
        point("scenes/a.json", "megakernel", 6.0, spp=1),
    ], commit="3333333", date="2026-03-01T00:00:00Z")
    write_bench(str(res / "scaling" / "x" / "results.json"), [  # never read
        point("scenes/s.json", "megakernel", 8.0),
    ], date="2026-04-01T00:00:00Z")
    table = ct.build_table(ct.discover(str(res), "", tsvs=()))
    rows = table_rows(table)
    assert [r[0] for r in rows[1:]] == ["a.json", "c.json"]
    assert rows[1][1:] == ["64x32, 64 spp, depth 8", "3.0", "**4.0**", "`2222222`, 2026-02-01"]
    assert rows[2][1:] == ["64x32, 4 spp, depth 8", "7.0", "-", "`1111111`, 2026-01-01"]
    assert "quick" not in table and "scaling" not in table


def test_another_gpu_is_left_out_and_named(tmp_path):
    res = tmp_path / "results"
    write_bench(str(res / "a" / "results.json"), [point("scenes/a.json", "megakernel", 1.0)],
                date="2026-01-01T00:00:00Z")
    write_bench(str(res / "b" / "results.json"), [point("scenes/b.json", "megakernel", 2.0)],
                gpu="NVIDIA H200", date="2025-01-01T00:00:00Z")
    table = ct.build_table(ct.discover(str(res), "", tsvs=()))
    assert [r[0] for r in table_rows(table)[1:]] == ["a.json"]
    assert "Left out, measured on another GPU:" in table and "(NVIDIA H200)" in table
    table = ct.build_table(ct.discover(str(res), "", tsvs=()), gpu="NVIDIA H200")
    assert [r[0] for r in table_rows(table)[1:]] == ["b.json"]


def test_failed_points_and_the_xml_tsv(tmp_path):
    res = tmp_path / "results"
    write_bench(str(res / "results.json"), [
        point("scenes/a.json", "megakernel", 1.0),
        point("scenes/a.json", "wavefront", None, status="error: too large"),
    ])
    os.makedirs(res / "mitsuba-xml-gpu")
    (res / "mitsuba-xml-gpu" / "mitsuba-xml.tsv").write_text(
        "scene\twidth\theight\tspp\tmitsuba_m_paths_per_s\tmegakernel_m_paths_per_s\t"
        "wavefront_m_paths_per_s\n"
        "box\t512\t512\t512\t99.0\t50.25\t700.0\n")
    history = ("Intro.\n\n`bench/mitsuba_xml.sh` at `fd3cd4d` on an NVIDIA H100 80GB HBM3\n"
               "(driver 1), 2026-12-07: pictures in `bench/results/mitsuba-xml-gpu/`.\n")
    table = ct.build_table(ct.discover(str(res), history))
    rows = table_rows(table)
    assert rows[1] == ["a.json", "64x32, 4 spp, depth 8", "1.0", "error",
                       "`abcdef0`, 2026-01-02"]
    assert rows[2] == ["box.xml", "512x512, 512 spp", "50.2", "**700**", "`fd3cd4d`, 2026-12-07"]
    assert "mitsuba" not in rows[0]  # the peer is not a kernel
    assert "as RESULTS.md records the run" in table


def test_missing_files_are_named(tmp_path):
    missing = str(tmp_path / "nowhere" / "results.json")
    with pytest.raises(ct.SourceError, match="nowhere/results.json: no such results file"):
        ct.read_bench_json(missing)
    res = tmp_path / "results"
    write_bench(str(res / "results.json"), [point("scenes/a.json", "megakernel", 1.0)])
    with pytest.raises(ct.SourceError, match="mitsuba-xml-gpu/mitsuba-xml.tsv: no such results"):
        ct.discover(str(res), "`bench/mitsuba_xml.sh` at `fd3cd4d` on an NVIDIA H100 80GB HBM3, "
                              "2026-12-07, in `bench/results/mitsuba-xml-gpu/`.")
    os.makedirs(res / "mitsuba-xml-gpu")
    (res / "mitsuba-xml-gpu" / "mitsuba-xml.tsv").write_text("scene\twavefront_m_paths_per_s\n")
    with pytest.raises(ct.SourceError, match="mitsuba-xml.tsv: records no commit or GPU"):
        ct.discover(str(res), "nothing about it")


def test_update_inserts_once_then_replaces_only_the_region(tmp_path):
    original = "# Results\n\nIntro.\n\n## Old section\n\nText.\n"
    first = ct.update_results_md(original, "TABLE 1")
    assert first.startswith("# Results\n\n## Current figures\n\n" + ct.BEGIN + "\nTABLE 1\n" + ct.END)
    assert first.endswith(ct.HISTORY_HEADING + "\n\n" + ct.HISTORY_INTRO + "\n\n"
                          "Intro.\n\n## Old section\n\nText.\n")
    second = ct.update_results_md(first, "TABLE 2")
    assert second == first.replace("TABLE 1", "TABLE 2")
    assert ct.update_results_md(second, "TABLE 2") == second


def test_check_fails_on_a_stale_copy(tmp_path, capsys):
    with open(ct.DEFAULT_RESULTS_MD, encoding="utf-8") as f:
        text = f.read()
    os.symlink(ct.DEFAULT_RESULTS_DIR, tmp_path / "results")  # the links as from bench/
    copy = tmp_path / "RESULTS.md"
    args = ["--check", "--results-md", str(copy), "--results-dir", str(tmp_path / "results")]
    copy.write_text(text, encoding="utf-8")
    assert ct.main(args) == 0
    copy.write_text(text.replace("| seed57.json |", "| seed57.json (old) |", 1), encoding="utf-8")
    assert ct.main(args) == 1
    assert "stale" in capsys.readouterr().err
    copy.write_text(text.replace(ct.BEGIN, "").replace(ct.END, ""), encoding="utf-8")
    assert ct.main(args) == 1
    assert copy.read_text(encoding="utf-8") == text.replace(ct.BEGIN, "").replace(ct.END, "")
