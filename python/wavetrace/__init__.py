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

from __future__ import annotations

import os as _os
from typing import Any, Callable, Optional, Union

import numpy as _np

from . import _wavetrace
from ._wavetrace import Scene, load_scene, scene_from_dict

__all__ = ["Image", "CudaImage", "Scene", "load_scene", "scene_from_dict", "render", "kernels", "devices",
           "settings", "aov_names", "write_image"]


class Image(_np.ndarray):
    """A rendered image: a float32 (H, W, 4) array of linear radiance (alpha 1), with
    the render's statistics in `stats` (the fields of `wavetrace render --stats`),
    the AOVs asked for in `aovs` (name -> float32 (H, W, C) array), and, of a
    denoised render, the render itself in `noisy` (else None)."""

    stats: dict
    aovs: dict
    noisy: Optional[Image]

    def __array_finalize__(self, obj):
        self.stats = getattr(obj, "stats", {})
        self.aovs = getattr(obj, "aovs", {})
        self.noisy = getattr(obj, "noisy", None)


class CudaImage:
    """A rendered image in CUDA device memory (render(..., device="cuda")): a float32
    (H, W, 4) array that torch.from_dlpack and cupy.from_dlpack read where it lies,
    without a copy, with `stats`, `aovs` (arrays on the device too) and `noisy` as
    Image has them (each AOV an array that torch and cupy read the same way).
    numpy() copies it to the host."""

    def __init__(self, array: Any, shape: tuple, stats: dict, aovs: dict, noisy: Optional[CudaImage]):
        self._array = array
        self._shape = tuple(shape)
        self.stats = stats
        self.aovs = aovs
        self.noisy = noisy

    @property
    def shape(self) -> tuple:
        return self._shape

    @property
    def dtype(self) -> _np.dtype:
        return _np.dtype(_np.float32)

    def __dlpack__(self, *args: Any, **kwargs: Any) -> Any:
        return self._array.__dlpack__(*args, **kwargs)

    def __dlpack_device__(self) -> tuple:
        return self._array.__dlpack_device__()

    def numpy(self) -> Image:
        """The image copied to host memory, as an Image."""
        host = _wavetrace.to_host(self._array).view(Image)
        host.stats, host.aovs, host.noisy = self.stats, self.aovs, self.noisy
        return host


def render(scene: Scene, progress: Optional[Callable[[float], None]] = None, device: str = "cpu",
           **settings: Any) -> Union[Image, CudaImage]:
    """Renders `scene` (a Scene) with `settings`: every setting of the command's
    settings table by its key (width, height, spp, depth, roulette_depth, seed, nee,
    warmup, wave_size, threads, megakernel_batch, min_spp, noise_threshold; see
    settings()), and backend ("auto", "cpu", "cuda"), kernel (kernels()) and devices
    ("all", or a list of indices). What is not given is the scene's.

    aovs: the AOVs to return beside the image, in `image.aovs` (a list of
    aov_names(), or "albedo,normal" as --aov takes them). denoise=True: the image
    is Open Image Denoise's (denoise_quality "high" or "balanced"), the render
    itself in `image.noisy`.

    device: where the arrays are returned: "cpu", an Image (a numpy array); "cuda",
    a CudaImage in the memory of the CUDA device the render ran on (the first of
    its devices; device 0 for a CPU render), read by torch and cupy without a copy.

    The scene is uploaded to a CUDA device at its first render there and kept for
    the next (scene.uploads counts them; scene.release_devices() frees them).

    progress: called with the share done (0 to 1) as the render goes, at most
    every 10 ms, and with 1 at the end. Ctrl-C stops the render where it next tells
    its progress (each bounce of a wavefront; each of the CUDA megakernel's passes,
    at least ten a render), looked at as often, and raises KeyboardInterrupt; the
    scene stays usable.
    """
    array, stats, aovs, noisy = _wavetrace.render(scene, progress, device, **settings)
    if device == "cuda":
        shape = (stats["settings"]["height"], stats["settings"]["width"], 4)
        return CudaImage(array, shape, stats, dict(aovs),
                         None if noisy is None else CudaImage(noisy, shape, stats, {}, None))
    image = array.view(Image)
    image.stats = stats
    image.aovs = {name: _np.asarray(a) for name, a in aovs.items()}
    if noisy is not None:
        image.noisy = noisy.view(Image)
        image.noisy.stats = stats
    return image


def kernels(backend: str = "cpu") -> list[str]:
    """The kernels a backend ("cpu" or "cuda") runs, as `kernel=` takes them."""
    return list(_wavetrace.kernels(backend))


def devices() -> list[dict]:
    """The devices a render can use: the CPU, and each CUDA device by its index."""
    out = [{"backend": "cpu", "index": 0}]
    out += [{"backend": "cuda", "index": i} for i in range(_wavetrace.cuda_device_count())]
    return out


def aov_names() -> list[str]:
    """The AOVs render(aovs=...) returns, as --aov names them."""
    return list(_wavetrace.aov_names())


def settings() -> list[str]:
    """The keys of the settings table, as render() takes them."""
    return list(_wavetrace.settings())


def write_image(image: Any, path: Union[str, _os.PathLike], encoding: str = "srgb") -> None:
    """Writes an (H, W, 3 or 4) image of linear radiance: PNG (8-bit, `encoding`
    "srgb" or "gamma2"), PFM or OpenEXR (linear), chosen by the extension, through
    the command's own writers (never a partial file under `path`)."""
    _wavetrace.write_image(_np.ascontiguousarray(image, dtype=_np.float32), str(path), encoding)
