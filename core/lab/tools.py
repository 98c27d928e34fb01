"""The real image tools, run as their command lines run them: GEGL, G'MIC and ImageMagick;
OpenCV and Pillow run in-process (:mod:`aarecovery.lab.pytools`).

* **GEGL** (the ``gegl`` command, Debian package ``gegl``): GIMP 3's filters are GEGL
  operations (``gegl:threshold``, ``gegl:levels``, ``gegl:unsharp-mask``...);
  ``gegl -- gegl:load path=IN OPERATION PROPERTY=VALUE... gegl:png-save path=OUT bitdepth=16``.
* **G'MIC** (``gmic``, package ``gmic``): ``gmic -v - IN... COMMAND ARGS -o OUT.tif,float``;
  G'MIC holds 8-bit images as floats in [0, 255] and writes them unclipped and unrounded.
* **ImageMagick** (``magick`` for version 7, ``convert`` for version 6, package
  ``imagemagick``): ``convert IN... OPTIONS +adjoin -depth 16 PNG48:OUT_%05d.png``.

Inputs are written as 8-bit PNG (grey where every channel is equal), as a user's file would
be; outputs come back at 16 bits (GEGL, ImageMagick) or as floats (G'MIC), so that a
reference built from a tool's output is not quantised a second time. Every process start
costs 0.1-0.5 s, so each call takes a batch: G'MIC and ImageMagick process every input of
one command line on its own; GEGL takes one atlas of the batch, each image surrounded by a
replicated border at least as wide as the operation reaches (``support``), so that no
output pixel reads a neighbour's pixels. An operation with per-image state (a histogram)
must not run in an atlas: with ``whole_image=True`` GEGL runs once per image.
"""

import functools
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass

import numpy as np

from .pytools import OPENCV, PILLOW

__all__ = ["Tool", "TOOLS", "available_tools", "run_command", "read_float_rgb", "write_png8"]


def run_command(command, timeout):
    """Run `command` (a list), raising RuntimeError with the tool's last line of stderr on failure."""
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout, check=False)
    if result.returncode != 0:
        tail = result.stderr.decode(errors="replace").strip().splitlines()[-1:] or ["no message"]
        raise RuntimeError(f"{command[0]} exited with status {result.returncode}: {tail[0]}")


def write_png8(path, image):
    """Write float32 ``(H, W, 3)`` in [0, 1] as an 8-bit PNG, grey when all channels are equal."""
    from PIL import Image
    pixels = np.rint(np.clip(image, 0, 1) * 255).astype(np.uint8)
    if (pixels == pixels[..., :1]).all():
        pixels = pixels[..., 0]
    Image.fromarray(pixels).save(path, compress_level=1)  # the fastest: these files live a second


def read_float_rgb(path, full_scale=None):
    """Read a tool's output as float32 ``(H, W, 3)``, clipped to [0, 1].

    Integer files are scaled by their type's maximum, float files by `full_scale` (255 for
    G'MIC's); grey is repeated into RGB; alpha must be opaque (a tool that made pixels
    transparent did something no filter here should).
    """
    return _opaque_rgb(_read_float(path, full_scale), path)


def _read_float(path, full_scale=None):
    from ..io import read_image
    data = read_image(path)
    if data.dtype.kind == "f":
        if full_scale is None:
            raise RuntimeError(f"{path}: a float image needs its full-scale value")
        values = data.astype(np.float32) / np.float32(full_scale)
    else:
        values = data.astype(np.float32) / np.float32(np.iinfo(data.dtype).max)
    return values[..., None] if values.ndim == 2 else values


def _opaque_rgb(values, where):
    if values.shape[2] in (2, 4):
        alpha = values[..., -1]
        if alpha.min() < 1 - 1 / 512:
            raise RuntimeError(f"{where}: the tool's output has transparent pixels (alpha down to {alpha.min():.3f})")
        values = values[..., :-1]
    if values.shape[2] == 1:
        values = np.repeat(values, 3, axis=2)
    return np.ascontiguousarray(np.clip(values, 0, 1), dtype=np.float32)


def _gegl_once(executable, arguments, image, folder, name):
    source, target = os.path.join(folder, f"{name}.png"), os.path.join(folder, f"{name}-out.png")
    write_png8(source, image)
    height, width = image.shape[:2]
    # Some operations grow the extent (gegl:bilateral-filter by its radius, transparent
    # there): the crop keeps the input's rectangle.
    run_command([executable, "--", "gegl:load", f"path={source}", *arguments, "gegl:crop", "x=0", "y=0",
                 f"width={width}", f"height={height}", "gegl:png-save", f"path={target}", "bitdepth=16",
                 "compression=1"], timeout=600)
    return _read_float(target)


def _gegl_batch(executable, arguments, images, folder, support, whole_image):
    if whole_image:
        return [_opaque_rgb(_gegl_once(executable, arguments, image, folder, f"in{i:05d}"), f"gegl {arguments}")
                for i, image in enumerate(images)]
    # One atlas for the batch; GEGL's border handling (transparent, for the bilateral
    # filter) only reaches into the outer replicated border, which is dropped. Grey images
    # go in as RGB: every GEGL operation of the suite gave the same result within 1.6e-5 on
    # a grey file and on its RGB copy (measured), and one process instead of two halves
    # GEGL's share of the run time.
    gap = int(np.ceil(support)) + 1
    heights = [im.shape[0] + 2 * gap for im in images]
    width = max(im.shape[1] for im in images) + 2 * gap
    atlas = np.zeros((sum(heights), width, 3), np.float32)
    top = 0
    for image, height in zip(images, heights):
        atlas[top:top + height] = np.pad(image, ((gap, gap), (gap, width - image.shape[1] - gap), (0, 0)), mode="edge")
        top += height
    result = _gegl_once(executable, arguments, atlas, folder, "atlas")
    out, top = [], 0
    for image, height in zip(images, heights):
        out.append(_opaque_rgb(result[top + gap:top + gap + image.shape[0], gap:gap + image.shape[1]],
                               f"gegl {arguments}"))
        top += height
    return out


def _gmic_batch(executable, arguments, images, folder, support, whole_image):
    sources = [os.path.join(folder, f"in{i:05d}.png") for i in range(len(images))]
    for source, image in zip(sources, images):
        write_png8(source, image)
    target = os.path.join(folder, "out.tif")
    run_command([executable, "-v", "-", *sources, *arguments, "-o", f"{target},float"], timeout=600)
    if len(images) == 1:
        return [read_float_rgb(target, full_scale=255)]
    return [read_float_rgb(os.path.join(folder, f"out_{i:06d}.tif"), full_scale=255) for i in range(len(images))]


# Pixels per ImageMagick command line. Its whole list of images is held at once, and
# Debian's policy (/etc/ImageMagick-6/policy.xml) caps the pixel cache at 256 MiB of memory,
# 512 MiB mapped and 1 GiB on disk, limits that -limit cannot raise: 24 references of a 768 px
# drawing (3072 x 3072 each, 16-bit RGBA) failed with "cache resources exhausted". 32
# megapixels (256 MiB) leave room for the operation's own copy.
_IMAGEMAGICK_PIXELS = 32_000_000


def _imagemagick_chunks(images, limit):
    """Consecutive index ranges of `images` whose pixels add up to at most `limit` (one image
    larger than it on its own)."""
    chunks, start, pixels = [], 0, 0
    for index, image in enumerate(images):
        size = image.shape[0] * image.shape[1]
        if index > start and pixels + size > limit:
            chunks.append(range(start, index))
            start, pixels = index, 0
        pixels += size
    return chunks + [range(start, len(images))] if images else chunks


def _imagemagick_batch(executable, arguments, images, folder, support, whole_image):
    sources = [os.path.join(folder, f"in{i:05d}.png") for i in range(len(images))]
    for source, image in zip(sources, images):
        write_png8(source, image)
    results = []
    for chunk in _imagemagick_chunks(images, _IMAGEMAGICK_PIXELS):
        # PNG48: 16-bit RGB whatever the result's colour type (a threshold's result would
        # otherwise be written as a 1-bit grey file). Each image is processed on its own, so
        # a command line per chunk gives what one for the whole batch would.
        run_command([executable, *(sources[i] for i in chunk), *arguments, "+adjoin", "-depth", "16",
                     "PNG48:" + os.path.join(folder, f"out{chunk.start:05d}_%05d.png")], timeout=600)
        results += [read_float_rgb(os.path.join(folder, f"out{chunk.start:05d}_{i:05d}.png")) for i in range(len(chunk))]
    return results


@functools.lru_cache(maxsize=None)
def _runs(command, marker):
    try:
        result = subprocess.run([command, "-version"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                timeout=60, check=False)
    except OSError:
        return False
    return result.returncode == 0 and marker in result.stdout.decode(errors="replace")


@dataclass(frozen=True)
class Tool:
    """A command-line image tool.

    Attributes
    ----------
    name : str
        ``"gegl"``, ``"gmic"`` or ``"imagemagick"``.
    label : str
    commands : tuple of str
        Executables that provide it, the preferred first.
    package : str
        The Debian package that provides it.
    """

    name: str
    label: str
    commands: tuple
    package: str
    _batch: object
    _version_marker: str = ""

    def executable(self):
        """str or None: the first of :attr:`commands` on PATH that is the real tool."""
        for command in self.commands:
            path = shutil.which(command)
            if path and (not self._version_marker or _runs(path, self._version_marker)):
                return path
        return None

    def available(self):
        """bool: the tool is installed."""
        return self.executable() is not None

    def install_hint(self):
        """What to install when it is missing."""
        return f"none of {', '.join(self.commands)} found; Debian package '{self.package}'"

    def run(self, arguments, images, *, support=0.0, whole_image=False):
        """Apply the tool with `arguments` to each image of a batch.

        Parameters
        ----------
        arguments : sequence of str
            What follows the input on the tool's command line (GEGL: operations and their
            ``property=value`` pairs; G'MIC: commands; ImageMagick: options).
        images : list of ndarray of float32, shape (H, W, 3)
            sRGB-encoded, written as 8-bit PNG.
        support : float
            How far, in pixels, an output pixel reads (GEGL's atlas border).
        whole_image : bool
            The operation has per-image state (GEGL then runs once per image).

        Returns
        -------
        list of ndarray of float32, shape (H, W, 3)
            The tool's results in [0, 1], at 16-bit or float precision.
        """
        executable = self.executable()
        if executable is None:
            raise RuntimeError(f"{self.label} is not installed ({self.install_hint()})")
        if not images:
            return []
        with tempfile.TemporaryDirectory(prefix=f"aarecovery-{self.name}-") as folder:
            return self._batch(executable, list(arguments), images, folder, support, whole_image)


TOOLS = {t.name: t for t in (
    Tool("gegl", "GEGL (GIMP's operations)", ("gegl",), "gegl", _gegl_batch),
    Tool("gmic", "G'MIC", ("gmic",), "gmic", _gmic_batch),
    # `convert` is also the name of other programs (Windows' disk converter, placeholders
    # on some machines): only a command whose -version names ImageMagick counts.
    Tool("imagemagick", "ImageMagick", ("magick", "convert"), "imagemagick", _imagemagick_batch, "ImageMagick"),
    OPENCV,
    PILLOW,
)}


def available_tools():
    """Split :data:`TOOLS` into those installed and those missing."""
    tools = list(TOOLS.values())
    return [t for t in tools if t.available()], [t for t in tools if not t.available()]
