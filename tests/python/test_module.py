"""The Python module (python/, docs/python.md), with pytest: scripts/test.sh runs it
against the module of the build folder (PYTHONPATH=<build>/python, WAVETRACE_BIN the
command beside it) where the module was built.

- the module renders the image the command line renders for the same seed;
- a dict scene renders as its JSON file, and numpy-array meshes as their OBJ;
- bad input raises ValueError with the command's one-line message, a missing device
  RuntimeError;
- Ctrl-C during a render raises KeyboardInterrupt within a second and leaves the
  scene usable; the progress callback sees the render through to 1.
"""

import json
import os
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import wavetrace as wt

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("WAVETRACE_BIN", ROOT / "build" / "wavetrace"))
CORNELL = ROOT / "scenes" / "cornell-box.json"


def read_pfm(path):
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4").reshape(h, w, 3)
    return data[::-1]  # PFM's rows run bottom to top


def small(**kw):
    return dict(dict(width=48, height=32, spp=4, seed=3, backend="cpu"), **kw)


@pytest.mark.parametrize("kernel", ["megakernel", "wavefront"])
def test_the_module_renders_what_the_command_renders(tmp_path, kernel):
    if not BIN.exists():
        pytest.skip("no wavetrace command at %s" % BIN)
    out = tmp_path / "cli.pfm"
    subprocess.run([str(BIN), "render", str(CORNELL), "-o", str(out), "--backend", "cpu", "--kernel", kernel,
                    "--width", "48", "--height", "32", "--spp", "4", "--seed", "3", "-q"], check=True)
    cli = read_pfm(out)
    img = wt.render(wt.load_scene(str(CORNELL)), kernel=kernel, **small())
    assert img.shape == (32, 48, 4) and img.dtype == np.float32
    assert np.all(img[..., 3] == 1)
    if kernel == "megakernel":
        np.testing.assert_array_equal(img[..., :3], cli)  # one thread a pixel: bit for bit
    else:
        # The wavefront's threads add to the film in their own order: to its rounding.
        np.testing.assert_allclose(img[..., :3], cli, rtol=1e-5, atol=1e-6)
    assert img.stats["kernel"] == kernel and img.stats["settings"]["spp"] == 4
    assert img.stats["backend"] == "cpu" and img.stats["paths"] == 48 * 32 * 4


def test_a_dict_scene_renders_as_its_json_file():
    with open(CORNELL) as f:
        d = json.load(f)
    a = wt.render(wt.load_scene(str(CORNELL)), **small())
    b = wt.render(wt.scene_from_dict(d, source=str(CORNELL)), **small())
    np.testing.assert_array_equal(a, b)


def test_numpy_meshes_render_as_their_obj(tmp_path):
    (tmp_path / "quad.obj").write_text("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\n"
                                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n")
    base = {"camera": {"look_from": [0.3, 0.2, 3], "look_at": [0, 0, 0]},
            "textures": [{"name": "c", "type": "checker", "size": 0.3, "even": [0.9, 0.2, 0.1],
                          "odd": [0.1, 0.3, 0.9]}],
            "materials": [{"name": "m", "type": "lambertian", "texture": "c"}],
            "instances": [{"mesh": "q"}]}
    from_file = dict(base, meshes=[{"name": "q", "file": "quad.obj", "material": "m"}])
    from_arrays = dict(base, meshes=[{
        "name": "q", "material": "m",
        "positions": np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float32),
        "indices": np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64),
        "normals": np.tile(np.array([0, 0, 1], dtype=np.float64), (4, 1)),
        "uvs": np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float32)}])
    source = str(tmp_path / "scene.json")
    a = wt.render(wt.scene_from_dict(from_file, source=source), **small())
    b = wt.render(wt.scene_from_dict(from_arrays, source=source), **small())
    np.testing.assert_array_equal(a, b)
    assert a[..., :3].max() > 0


def test_bad_input_raises_the_commands_messages(tmp_path):
    scene = wt.load_scene(str(CORNELL))
    with pytest.raises(ValueError, match=r"^spp: must be in 1\.\.1000000 \(got 0\)$"):
        wt.render(scene, spp=0)
    with pytest.raises(ValueError, match=r"^kernel: unknown kernel 'warp'"):
        wt.render(scene, kernel="warp", backend="cpu")
    with pytest.raises(ValueError, match=r"^render: unknown setting 'sppp'"):
        wt.render(scene, sppp=4)
    with pytest.raises(ValueError, match=r"^spp: must be an integer"):
        wt.render(scene, spp=4.5)
    missing = tmp_path / "missing.json"
    with pytest.raises(ValueError, match="^" + str(missing) + ": "):
        wt.load_scene(str(missing))
    d = {"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
         "materials": [{"name": "m", "type": "lambertian", "albedo": [2, 0, 0]}],
         "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]}
    with pytest.raises(ValueError, match=r"^mine\.json: /materials/0/albedo/0: "):
        wt.scene_from_dict(d, source="mine.json")
    with pytest.raises(ValueError, match="not a JSON value"):
        wt.scene_from_dict({"camera": object()})
    with pytest.raises(ValueError, match=r"write_image|\.bmp"):
        wt.write_image(np.zeros((2, 2, 3), np.float32), str(tmp_path / "x.bmp"))
    if not [d for d in wt.devices() if d["backend"] == "cuda"]:
        with pytest.raises(RuntimeError, match="no CUDA device is present"):
            wt.render(scene, backend="cuda", **{k: v for k, v in small().items() if k != "backend"})


def test_ctrl_c_stops_a_render_within_a_second_and_the_scene_stays_usable():
    scene = wt.load_scene(str(CORNELL))
    sent = []

    def interrupt():
        time.sleep(0.5)
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=interrupt).start()
    with pytest.raises(KeyboardInterrupt):
        # 1/256 of the render a pass: 4 samples of 160 x 120, about 50 ms on two cores.
        wt.render(scene, width=160, height=120, spp=1024, backend="cpu", kernel="megakernel")
    assert sent and time.monotonic() - sent[0] < 1.0
    img = wt.render(scene, **small())
    assert img.shape == (32, 48, 4)


def test_progress_runs_to_one_and_its_exception_stops_the_render():
    scene = wt.load_scene(str(CORNELL))
    seen = []
    wt.render(scene, progress=seen.append, **small(spp=64))
    assert seen and seen[-1] == 1.0 and seen == sorted(seen)

    def fail(done):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        wt.render(scene, progress=fail, **small(spp=64))


def test_write_image_writes_what_the_render_holds(tmp_path):
    img = wt.render(wt.load_scene(str(CORNELL)), **small())
    wt.write_image(img, tmp_path / "out.pfm")
    np.testing.assert_array_equal(read_pfm(tmp_path / "out.pfm"), img[..., :3])
    wt.write_image(img, tmp_path / "out.png")
    assert (tmp_path / "out.png").stat().st_size > 0


def test_the_lists_name_what_the_command_takes():
    assert "wavefront" in wt.kernels("cpu") and "megakernel-constant" not in wt.kernels("cpu")
    assert {"spp", "width", "height", "seed", "noise_threshold"} <= set(wt.settings())
    assert wt.devices()[0] == {"backend": "cpu", "index": 0}
