"""wavetrace from Python: load a scene once, render it with any settings, and get
the image as a numpy array with the render's statistics (docs/python.md).

    import wavetrace as wt
    scene = wt.load_scene("scenes/cornell-box.json")
    img = wt.render(scene, spp=64, kernel="wavefront", backend="cpu", seed=1)
    img.shape                      # (height, width, 4), float32, linear radiance
    img.stats["m_paths_per_s"]     # what `wavetrace render --stats` writes
    wt.write_image(img, "out.png")

Bad input (a scene, a setting, an output path) raises ValueError with the command
line's one-line message; a failure of the machine raises RuntimeError naming the
call and the stage.
"""

import json as _json

import numpy as _np

from . import _wavetrace
from ._wavetrace import Scene, load_scene, scene_from_dict

__all__ = ["Image", "Scene", "load_scene", "scene_from_dict", "render", "kernels", "devices", "settings",
           "write_image"]


class Image(_np.ndarray):
    """A rendered image: a float32 (H, W, 4) array of linear radiance (alpha 1), with
    the render's statistics in `stats` (the fields of `wavetrace render --stats`)."""

    stats: dict

    def __array_finalize__(self, obj):
        self.stats = getattr(obj, "stats", {})


def render(scene, progress=None, **settings):
    """Renders `scene` (a Scene) with `settings`: every setting of the command's
    settings table by its key (width, height, spp, depth, roulette_depth, seed, nee,
    warmup, wave_size, threads, megakernel_batch, min_spp, noise_threshold; see
    settings()), and backend ("auto", "cpu", "cuda"), kernel (kernels()) and devices
    ("all", or a list of indices). What is not given is the scene's.

    progress: called with the share done (0 to 1) as the render goes. Ctrl-C stops
    the render at its next pass and raises KeyboardInterrupt; the scene stays usable.
    """
    array, stats = _wavetrace.render(scene, progress, **settings)
    image = array.view(Image)
    image.stats = _json.loads(stats)
    return image


def kernels(backend="cpu"):
    """The kernels a backend ("cpu" or "cuda") runs, as `kernel=` takes them."""
    return list(_wavetrace.kernels(backend))


def devices():
    """The devices a render can use: the CPU, and each CUDA device by its index."""
    out = [{"backend": "cpu", "index": 0}]
    out += [{"backend": "cuda", "index": i} for i in range(_wavetrace.cuda_device_count())]
    return out


def settings():
    """The keys of the settings table, as render() takes them."""
    return list(_wavetrace.settings())


def write_image(image, path, encoding="srgb"):
    """Writes an (H, W, 3 or 4) image of linear radiance: PNG (8-bit, `encoding`
    "srgb" or "gamma2"), PFM or OpenEXR (linear), chosen by the extension, through
    the command's own writers (never a partial file under `path`)."""
    _wavetrace.write_image(_np.ascontiguousarray(image, dtype=_np.float32), str(path), encoding)
