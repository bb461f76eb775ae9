#!/usr/bin/env python3
"""Checks that the folders of src/ include one another only downward.

Each folder of src/ may include the folders listed for it below (and the core,
include/wavetrace, which every folder may use); an include of any other project
folder runs back up and is reported with its file and line. docs/architecture.md
draws the same picture. Exit 0 when every arrow runs downward, 1 otherwise.
"""
import pathlib
import re
import sys

# Folder -> the folders of src/ it may include.
ALLOWED = {
    "app": {"image", "dispatch", "cpu", "cuda", "device", "scene", "render", "errors"},
    "image": {"cpu", "errors"},
    "dispatch": {"cpu", "cuda", "device", "scene", "render", "errors"},
    "cpu": {"stages", "queues", "scene", "render", "errors"},
    "cuda": {"megakernel", "device", "stages", "queues", "scene", "render", "errors"},
    "megakernel": {"device", "stages", "queues", "scene", "render", "errors"},
    "stages": {"queues", "render"},
    "scene": {"render", "errors"},
    "render": {"queues", "errors"},
    "device": {"errors"},
    "queues": set(),
    "errors": set(),
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([a-z_]+)/')


def main() -> int:
    root = pathlib.Path(__file__).resolve().parent.parent / "src"
    folders = {p.name for p in root.iterdir() if p.is_dir()}
    wrong = []
    for folder in sorted(folders - ALLOWED.keys()):
        wrong.append(f"src/{folder}/: a folder the list does not know (add it to tools/check_includes.py)")
    for path in sorted(root.rglob("*")):
        if path.suffix not in {".cpp", ".hpp", ".cu", ".cuh"}:
            continue
        here = path.relative_to(root).parts[0]
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            m = INCLUDE.match(line)
            if not m or m.group(1) in (here, "wavetrace") or m.group(1) not in folders:
                continue
            if m.group(1) not in ALLOWED.get(here, set()):
                wrong.append(f"src/{path.relative_to(root)}:{number}: {here} includes {m.group(1)}, which is not below it")
    for w in wrong:
        print(w)
    print(f"check_includes: {len(wrong)} arrows that run back up" if wrong else "check_includes: every arrow runs downward")
    return 1 if wrong else 0


if __name__ == "__main__":
    sys.exit(main())
