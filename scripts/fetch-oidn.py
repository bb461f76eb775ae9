#!/usr/bin/env python3
"""Unpacks Intel Open Image Denoise's libraries for the CPU and CUDA devices from the
PyPI wheel `pyoidn` (Debian does not package OIDN) into .deps/oidn/lib, where
src/image/denoise.cpp looks for them. Standard library only: the wheel's URL and
SHA-256 come from PyPI's JSON API, and the download is checked against it.

    python3 scripts/fetch-oidn.py [DEST]      # DEST default: .deps/oidn/lib

Does nothing where DEST already holds the version below. Exits 1 with one line
where the download or the check fails (scripts/setup.sh goes on without OIDN: only
--denoise needs it).
"""
import hashlib
import io
import json
import os
import sys
import urllib.parse
import urllib.request
import zipfile

VERSION = "2.5.1.0"
# What the CPU and CUDA devices need; the wheel's SYCL, HIP and Level Zero parts
# are left out.
KEEP = ("libOpenImageDenoise.so.2", "libOpenImageDenoise_core.so.2.5.1", "libOpenImageDenoise_device_cpu.so.2.5.1",
        "libOpenImageDenoise_device_cuda.so.2.5.1", "libtbb.so.12")


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    dest = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, ".deps", "oidn", "lib")
    stamp = os.path.join(dest, "pyoidn-version")
    if os.path.exists(stamp) and open(stamp).read().strip() == VERSION and all(
            os.path.exists(os.path.join(dest, name)) for name in KEEP):
        return 0
    try:
        index = "https://pypi.org/pypi/pyoidn/json"
        with urllib.request.urlopen(index, timeout=60) as r:
            files = json.load(r)["releases"][VERSION]
        wheel = next(f for f in files if f["filename"].endswith("manylinux2014_x86_64.whl"))
        # A mirror may give the file's address relative to the index's.
        with urllib.request.urlopen(urllib.parse.urljoin(index, wheel["url"]), timeout=600) as r:
            data = r.read()
    except Exception as e:  # no network, PyPI down, no such wheel
        print("fetch-oidn: cannot download pyoidn %s: %s" % (VERSION, e), file=sys.stderr)
        return 1
    if hashlib.sha256(data).hexdigest() != wheel["digests"]["sha256"]:
        print("fetch-oidn: %s does not match PyPI's SHA-256" % wheel["filename"], file=sys.stderr)
        return 1
    os.makedirs(dest, exist_ok=True)
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        for info in z.infolist():
            name = os.path.basename(info.filename)
            if info.filename.startswith("pyoidn/oidn/lib/") and name in KEEP:
                with open(os.path.join(dest, name), "wb") as out:
                    out.write(z.read(info))
    missing = [name for name in KEEP if not os.path.exists(os.path.join(dest, name))]
    if missing:
        print("fetch-oidn: the wheel lacks %s" % ", ".join(missing), file=sys.stderr)
        return 1
    with open(stamp, "w") as f:
        f.write(VERSION + "\n")
    print("fetch-oidn: Open Image Denoise %s in %s" % (VERSION, dest), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
