#!/usr/bin/env python3
"""What a render through the Python module costs beyond the render itself, against
the command line doing the same work (issue 27: no more than 1% on a 1080p render,
the scene loaded once).

For each kernel, the same render (scene, size, samples, seed, backend):
- the command, `runs` times: its stats' `seconds` (the render alone: CUDA events on
  the GPU, wall clock on the CPU) and `job_seconds` (the whole job: load, upload,
  render, write), and the process's wall clock;
- the module, the scene loaded once and rendered once first (its upload), then
  `runs` timed calls of wavetrace.render: each call's wall clock in Python, and its
  stats' `seconds`; the image returned as a numpy array (device "cpu": brought back
  to the host once) and, on the CUDA backend, left on the device (device "cuda").
  Each command run is followed by a call for each image device, so that drift from
  one batch of renders to the next touches both; then `runs` calls in a row for
  each, as a sweep makes them. With --settle, each call that follows a command waits
  that long after the command's process has exited (on the H100 such a call added
  0.1 to 0.2 ms more than calls in a row; the pause tells whether that is the
  machine still busy with the process that has gone).

The overhead is the module's call against the command's render: median call wall
clock over median command `seconds`, less 1; and, within each call, its wall clock
less its own render `seconds` (what the module adds: on CUDA, finishing the image
on the device and handing it over or writing it into host memory; on the CPU, the
mean and the RGBA array; the settings, the lease of the kept scene, the stats), as a
share of the render's `seconds`: for the calls that each follow a command, and for
the calls in a row. What a call adds is split in two: within the
render session (its stats' `job_seconds` less `seconds`: the settings, the lease,
the image finished and handed over) and around it (the call's wall clock less
`job_seconds`: Python, the keywords, the stats read back, the array). The image
before each call is let go outside it, and that is timed on its own (a numpy
image's page-locked block, or a device image's block, goes back to its pool).

    PYTHONPATH=build/python python3 bench/python_overhead.py --bin build/wavetrace \\
        --backend cuda --out overhead.json
"""

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import wavetrace as wt


def command_run(args, kernel, tmp, i):
    stats = Path(tmp) / ("cli-%s-%d.json" % (kernel, i))
    cmd = [args.bin, "render", args.scene, "-o", str(Path(tmp) / "cli.exr"), "--width", str(args.width),
           "--height", str(args.height), "--spp", str(args.spp), "--seed", "1", "--backend", args.backend,
           "--kernel", kernel, "--stats", str(stats), "-q"]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True)
    wall = time.perf_counter() - t0
    s = json.loads(stats.read_text())
    return {"seconds": s["seconds"], "job_seconds": s["job_seconds"], "process_seconds": wall}


def module_run(scene, settings, device):
    t0 = time.perf_counter()
    img = wt.render(scene, device=device, **settings)
    wall = time.perf_counter() - t0
    out = {"call_seconds": wall, "seconds": img.stats["seconds"], "job_seconds": img.stats["job_seconds"],
           "upload_seconds": img.stats["upload_seconds"]}
    # The image is let go outside the call, and timed on its own: a loop that
    # rebinds `img = wavetrace.render(...)` lets it go as the name is rebound.
    t0 = time.perf_counter()
    del img
    out["let_go_seconds"] = time.perf_counter() - t0
    return out


def runs(args, kernel, scene, devices, tmp):
    """The command's runs and the module's, interleaved (a command, then a call for
    each image device, `runs` times), so that whatever drifts from one batch of
    renders to the next (the same command's render moves by 1 to 2% between
    batches on the H100) touches both alike."""
    settings = dict(width=args.width, height=args.height, spp=args.spp, seed=1, backend=args.backend, kernel=kernel)
    for device in devices:
        wt.render(scene, device=device, **settings)  # the upload (CUDA), and the first render's set-up
    cli, mod = [], {d: [] for d in devices}
    for i in range(args.runs):
        cli.append(command_run(args, kernel, tmp, i))
        # --settle: a pause between the command's exit and the call, for whatever the
        # machine does after a process has gone (its context torn down, its memory
        # given back) to be done before the call is timed.
        time.sleep(args.settle)
        for device in devices:
            mod[device].append(module_run(scene, settings, device))
    # Then calls one after another, as a sweep makes them: a call that follows a
    # command finds the machine's caches and the GPU as another process left them.
    in_a_row = {d: [module_run(scene, settings, d) for _ in range(args.runs)] for d in devices}
    return cli, mod, in_a_row


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", required=True, help="the wavetrace command")
    ap.add_argument("--scene", default="scenes/cornell-box.json")
    ap.add_argument("--backend", default="cuda")
    ap.add_argument("--kernels", nargs="+", default=None, help="default: every kernel of the backend")
    ap.add_argument("--width", type=int, default=1920)
    ap.add_argument("--height", type=int, default=1080)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--settle", type=float, default=0.0,
                    help="seconds to wait after each command before the calls that follow it")
    ap.add_argument("--out", default=None, help="a JSON file of every run and the medians")
    args = ap.parse_args()
    kernels = args.kernels or wt.kernels(args.backend)
    scene = wt.load_scene(args.scene)
    rows = []
    devices = ["cpu", "cuda"] if args.backend == "cuda" else ["cpu"]
    with tempfile.TemporaryDirectory() as tmp:
        for kernel in kernels:
            cli, by_device, in_a_row = runs(args, kernel, scene, devices, tmp)
            cli_render = statistics.median(r["seconds"] for r in cli)
            for device in devices:
                mod = by_device[device]
                row = in_a_row[device]
                row_added = statistics.median(r["call_seconds"] - r["seconds"] for r in row)
                row_render = statistics.median(r["seconds"] for r in row)
                call = statistics.median(r["call_seconds"] for r in mod)
                added = statistics.median(r["call_seconds"] - r["seconds"] for r in mod)
                render = statistics.median(r["seconds"] for r in mod)
                rows.append({"kernel": kernel, "device": device, "command": cli, "module": mod, "in_a_row": row,
                             "command_render_seconds": cli_render,
                             "command_job_seconds": statistics.median(r["job_seconds"] for r in cli),
                             "command_process_seconds": statistics.median(r["process_seconds"] for r in cli),
                             "module_call_seconds": call,
                             "module_render_seconds": render,
                             "module_added_seconds": added,
                             "added_in_session_seconds": statistics.median(r["job_seconds"] - r["seconds"] for r in mod),
                             "added_around_session_seconds": statistics.median(r["call_seconds"] - r["job_seconds"]
                                                                               for r in mod),
                             "in_a_row_added_seconds": row_added,
                             "in_a_row_added_share": row_added / row_render,
                             "in_a_row_in_session_seconds": statistics.median(r["job_seconds"] - r["seconds"]
                                                                              for r in row),
                             "image_let_go_seconds": statistics.median(r["let_go_seconds"] for r in mod),
                             "overhead_vs_command": call / cli_render - 1,
                             "added_share": added / render})
    report = {"scene": args.scene, "backend": args.backend, "width": args.width, "height": args.height,
              "spp": args.spp, "runs": args.runs, "settle_seconds": args.settle, "uploads": scene.uploads,
              "pinned_blocks": wt._wavetrace.pinned_allocations(), "rows": rows}
    print("| kernel | image | command render s | command job s | module call s | module render s | "
          "call vs command render | added, each call after a command (of its render) | in the session | "
          "around it | letting the image go | added, calls in a row | in the session |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for r in rows:
        print("| %s | %s | %.4f | %.3f | %.4f | %.4f | %+.2f%% | %.2f ms (%.2f%%) | %.2f ms | %.2f ms | %.2f ms "
              "| %.2f ms (%.2f%%) | %.2f ms |" % (
                  r["kernel"], "numpy" if r["device"] == "cpu" else "cuda", r["command_render_seconds"],
                  r["command_job_seconds"], r["module_call_seconds"], r["module_render_seconds"],
                  100 * r["overhead_vs_command"], 1e3 * r["module_added_seconds"], 100 * r["added_share"],
                  1e3 * r["added_in_session_seconds"], 1e3 * r["added_around_session_seconds"],
                  1e3 * r["image_let_go_seconds"], 1e3 * r["in_a_row_added_seconds"],
                  100 * r["in_a_row_added_share"], 1e3 * r["in_a_row_in_session_seconds"]))
    print("scene uploads through the module: %d; page-locked image blocks allocated: %d" % (
        scene.uploads, report["pinned_blocks"]))
    if args.out:
        Path(args.out).write_text(json.dumps(report, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
