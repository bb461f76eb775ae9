"""What the scene generators in tools/ share: writing a scene file and the
command line around it.

Every make_*.py script builds a scene (a dict in the layout of
docs/scene-format.md) and hands it to main() here, which parses the command
line, writes the file and prints a one-line summary. The scripts import this
module as a sibling (python3 puts the script's own folder first on the path),
so they run from any working directory.
"""

import argparse
import collections
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def scene_path(name):
    """The committed scene file scenes/NAME, wherever the script runs from."""
    return os.path.join(HERE, "..", "scenes", name)


def rounder(digits):
    """A function that rounds to DIGITS decimals: short lines in the scene file."""
    def q(x):
        return round(x, digits)
    return q


def dumps_scene(scene):
    """JSON text with one list entry per line: diffs stay readable."""
    parts = []
    for key, value in scene.items():
        if isinstance(value, list) and not value:
            parts.append("  %s: []" % json.dumps(key))
        elif isinstance(value, list):
            body = ",\n".join("    " + json.dumps(v) for v in value)
            parts.append("  %s: [\n%s\n  ]" % (json.dumps(key), body))
        else:
            parts.append("  %s: %s" % (json.dumps(key), json.dumps(value)))
    return "{\n" + ",\n".join(parts) + "\n}\n"


def spheres_by(scene, label):
    """How many spheres there are per label(material), material being the
    sphere's entry in scene["materials"]."""
    materials = {m["name"]: m for m in scene["materials"]}
    return collections.Counter(label(materials[s["material"]]) for s in scene["spheres"])


def counts_text(counts):
    """'a 3, b 1': the counts sorted by label."""
    return ", ".join("%s %d" % kv for kv in sorted(counts.items()))


def main(doc, build, default_out, summary, input_arg=None):
    """The command line of a generator: [INPUT] [-o OUTPUT].

    doc: the script's docstring (its first line describes the script);
    build: makes the scene, from the parsed INPUT file where input_arg is
    given, from nothing otherwise; default_out: the file written without -o;
    summary(scene): the text printed after the output's name;
    input_arg: (name, help) of a JSON file build() takes, or None. A
    ValueError from build() then ends the script with the input's name and
    the message.
    """
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    if input_arg:
        ap.add_argument(input_arg[0], help=input_arg[1])
    ap.add_argument("-o", "--output", default=default_out, help="scene file to write")
    args = ap.parse_args()
    if input_arg:
        path = getattr(args, input_arg[0])
        with open(path) as f:
            data = json.load(f)
        try:
            scene = build(data)
        except ValueError as e:
            sys.exit("%s: %s" % (path, e))
    else:
        scene = build()
    with open(args.output, "w") as f:
        f.write(dumps_scene(scene))
    print("%s: %s" % (os.path.normpath(args.output), summary(scene)))
