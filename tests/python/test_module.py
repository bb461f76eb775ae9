"""The Python module (python/, docs/python.md), with pytest: scripts/test.sh runs it
against the module of the build folder (PYTHONPATH=<build>/python, WAVETRACE_BIN the
command beside it) where the module was built.

- the module renders the image the command line renders for the same seed;
- a dict scene renders as its JSON file, and numpy-array meshes as their OBJ;
- bad input raises ValueError with the command's one-line message, a missing device
  RuntimeError;
- Ctrl-C during a render raises KeyboardInterrupt within a second and leaves the
  scene usable; the progress callback sees the render through to 1;
- the AOVs are the command's --aov files, a denoised render's image the command's;
- on CUDA (skipped without a device): the image is the command's, the scene is
  uploaded once for renders of any settings (counted), and device="cuda" hands the
  image to torch through DLPack without a copy (skipped without torch).
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


HAS_CUDA = any(d["backend"] == "cuda" for d in wt.devices())
needs_cuda = pytest.mark.skipif(not HAS_CUDA, reason="no CUDA device")


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        assert kind in (b"PF", b"Pf")
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        c = 3 if kind == b"PF" else 1
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4").reshape(h, w, c)
    return data[::-1]  # PFM's rows run bottom to top


def small(**kw):
    return dict(dict(width=48, height=32, spp=4, seed=3, backend="cpu"), **kw)


def command(tmp_path, *args, name="cli.pfm"):
    """The command's render of the Cornell box at small()'s settings (the backend and
    the rest in args), read back."""
    if not BIN.exists():
        pytest.skip("no wavetrace command at %s" % BIN)
    out = tmp_path / name
    subprocess.run([str(BIN), "render", str(CORNELL), "-o", str(out), "--width", "48", "--height", "32",
                    "--spp", "4", "--seed", "3", "-q", *args], check=True)
    return read_pfm(out)


@pytest.mark.parametrize("backend,kernel", [("cpu", "megakernel"), ("cpu", "wavefront"),
                                            pytest.param("cuda", "megakernel", marks=needs_cuda),
                                            pytest.param("cuda", "wavefront", marks=needs_cuda)])
def test_the_module_renders_what_the_command_renders(tmp_path, backend, kernel):
    cli = command(tmp_path, "--backend", backend, "--kernel", kernel)
    img = wt.render(wt.load_scene(str(CORNELL)), kernel=kernel, **small(backend=backend))
    assert img.shape == (32, 48, 4) and img.dtype == np.float32
    assert np.all(img[..., 3] == 1)
    if kernel == "megakernel":
        np.testing.assert_array_equal(img[..., :3], cli)  # one thread a pixel: bit for bit
    else:
        # The wavefront's threads add to the film in their own order: to its rounding.
        np.testing.assert_allclose(img[..., :3], cli, rtol=1e-5, atol=1e-6)
    assert img.stats["kernel"] == kernel and img.stats["settings"]["spp"] == 4
    assert img.stats["backend"] == backend and img.stats["paths"] == 48 * 32 * 4


def test_the_aovs_are_the_commands(tmp_path):
    command(tmp_path, "--backend", "cpu", "--aov", "albedo,normal,depth", name="a.pfm")
    img = wt.render(wt.load_scene(str(CORNELL)), aovs=["albedo", "normal", "depth"], **small())
    assert list(img.aovs) == ["albedo", "normal", "depth"]
    for name in img.aovs:
        np.testing.assert_array_equal(img.aovs[name], read_pfm(tmp_path / ("a.%s.pfm" % name)))
    assert img.aovs["depth"].shape == (32, 48, 1) and img.aovs["albedo"].shape == (32, 48, 3)
    assert img.aovs["albedo"].max() > 0 and np.isfinite(img.aovs["depth"]).any()
    with pytest.raises(ValueError, match=r"^aovs: .*'shine'"):
        wt.render(wt.load_scene(str(CORNELL)), aovs="albedo,shine", **small())


def test_a_denoised_render_is_the_commands(tmp_path):
    scene = wt.load_scene(str(CORNELL))
    try:
        img = wt.render(scene, denoise=True, **small(width=64, height=64))
    except ValueError as e:
        if str(e).startswith("denoise: "):
            pytest.skip("Open Image Denoise is not here: %s" % e)
        raise
    if not BIN.exists():
        pytest.skip("no wavetrace command at %s" % BIN)
    out = tmp_path / "d.pfm"
    subprocess.run([str(BIN), "render", str(CORNELL), "-o", str(out), "--width", "64", "--height", "64",
                    "--spp", "4", "--seed", "3", "-q", "--backend", "cpu", "--denoise", "--keep-noisy"], check=True)
    np.testing.assert_allclose(img[..., :3], read_pfm(out), rtol=1e-5, atol=1e-6)
    np.testing.assert_array_equal(img.noisy[..., :3], read_pfm(tmp_path / "d.noisy.pfm"))
    assert img.stats["denoise"]["device"] == "cpu"


@needs_cuda
def test_a_scene_is_uploaded_once_for_renders_of_any_settings():
    scene = wt.load_scene(str(CORNELL))
    assert scene.uploads == 0
    first = wt.render(scene, kernel="megakernel", **small(backend="cuda"))
    assert scene.uploads == 1
    # Other kernels, sizes, samples and the AOVs' pass: the same copy.
    for kernel in wt.kernels("cuda"):
        wt.render(scene, kernel=kernel, aovs=["albedo"], **small(backend="cuda", width=40, height=24))
    again = wt.render(scene, kernel="megakernel", **small(backend="cuda"))
    assert scene.uploads == 1
    assert again.stats["upload_seconds"] == 0 and first.stats["upload_seconds"] > 0
    # The kept copy renders what a fresh one renders, bit for bit.
    np.testing.assert_array_equal(again, first)
    np.testing.assert_array_equal(wt.render(wt.load_scene(str(CORNELL)), kernel="megakernel",
                                            **small(backend="cuda")), again)
    scene.release_devices()
    wt.render(scene, kernel="megakernel", **small(backend="cuda"))
    assert scene.uploads == 2


@needs_cuda
def test_a_cuda_image_is_handed_over_by_dlpack():
    scene = wt.load_scene(str(CORNELL))
    on_gpu = wt.render(scene, device="cuda", aovs=["normal"], **small(backend="cuda", kernel="megakernel"))
    assert on_gpu.__dlpack_device__()[0] == 2 and on_gpu.shape == (32, 48, 4)  # kDLCUDA
    host = wt.render(scene, **small(backend="cuda", kernel="megakernel"))
    np.testing.assert_array_equal(on_gpu.numpy(), host)
    torch = pytest.importorskip("torch")
    t = torch.from_dlpack(on_gpu)
    assert t.is_cuda and tuple(t.shape) == (32, 48, 4) and t.dtype == torch.float32
    assert torch.from_dlpack(on_gpu).data_ptr() == t.data_ptr()  # the same memory: no copy
    np.testing.assert_array_equal(t.cpu().numpy(), host)
    np.testing.assert_array_equal(torch.from_dlpack(on_gpu.aovs["normal"]).cpu().numpy(),
                                  wt.render(scene, aovs=["normal"], **small(backend="cuda",
                                                                            kernel="megakernel")).aovs["normal"])


@needs_cuda
@pytest.mark.parametrize("kernel", ["megakernel", "wavefront"])
def test_an_image_finished_on_the_device_is_the_hosts(kernel):
    """A render with no AOV and no denoiser finishes its image on the device: handed
    over there (device="cuda") or brought back once into page-locked memory, which
    the next image of its size reuses. Either is the image of a render whose AOVs made
    it come back as sums and be finished on the host."""
    scene = wt.load_scene(str(CORNELL))
    settings = small(backend="cuda", kernel=kernel, width=400, height=300)
    through_host = wt.render(scene, aovs=["albedo"], **settings)
    on_gpu = wt.render(scene, device="cuda", **settings)
    brought_back = wt.render(scene, **settings)
    if kernel == "megakernel":
        np.testing.assert_array_equal(on_gpu.numpy(), through_host)
        np.testing.assert_array_equal(brought_back, through_host)
    else:
        np.testing.assert_allclose(on_gpu.numpy(), through_host, rtol=1e-5, atol=1e-6)
        np.testing.assert_allclose(brought_back, through_host, rtol=1e-5, atol=1e-6)
    assert brought_back.stats["nonfinite_pixels"] == through_host.stats["nonfinite_pixels"] == 0
    del brought_back
    blocks = wt._wavetrace.pinned_allocations()
    for _ in range(4):
        img = wt.render(scene, **settings)
        del img
    assert wt._wavetrace.pinned_allocations() == blocks  # the block let go served each


def test_a_cuda_image_needs_a_device():
    if HAS_CUDA:
        pytest.skip("a CUDA device is present")
    with pytest.raises(RuntimeError, match="^device: cuda was asked for the image, but no CUDA device is present"):
        wt.render(wt.load_scene(str(CORNELL)), device="cuda", **small())
    with pytest.raises(ValueError, match="^device: must be 'cpu' or 'cuda'"):
        wt.render(wt.load_scene(str(CORNELL)), device="gpu", **small())


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
    with pytest.raises(ValueError, match=r"^checkpoint_every: a render in memory keeps no checkpoint"):
        wt.render(scene, checkpoint_every=60)
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


@pytest.mark.parametrize("backend,kernel,size,spp", [
    # Rows of 640 x 64 samples a chunk: short enough on a loaded two-core machine.
    ("cpu", "megakernel", (640, 480), 64),
    # About 2 s on an H100, stopped after its bounce in flight.
    pytest.param("cuda", "wavefront", (1920, 1080), 1024, marks=needs_cuda),
    # About 2 s in passes of a tenth: the pass in flight and the one queued behind it
    # finish before the render unwinds.
    pytest.param("cuda", "megakernel", (1920, 1080), 512, marks=needs_cuda)])
def test_ctrl_c_stops_a_render_within_a_second_and_the_scene_stays_usable(backend, kernel, size, spp):
    scene = wt.load_scene(str(CORNELL))
    sent = []

    def interrupt():
        time.sleep(0.5)
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=interrupt).start()
    with pytest.raises(KeyboardInterrupt):
        # The CPU megakernel looks between chunks of rows; the CUDA one between its
        # passes (at least ten a render).
        wt.render(scene, width=size[0], height=size[1], spp=spp, backend=backend, kernel=kernel)
    assert sent and time.monotonic() - sent[0] < 1.0
    img = wt.render(scene, **small(backend=backend, kernel=kernel))
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
    assert "checkpoint_every" not in wt.settings()
    assert wt.devices()[0] == {"backend": "cpu", "index": 0}


def test_the_package_carries_its_type_stubs():
    here = Path(wt.__file__).parent
    assert (here / "py.typed").exists()
    stub = (here / "_wavetrace.pyi").read_text()
    for name in ("def render(", "def load_scene(", "class Scene", "def uploads(", "def release_devices("):
        assert name in stub, name
