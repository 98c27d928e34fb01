"""The tools a user would reach for instead, run on F alone: GIMP's Antialias and G'MIC's.

* GIMP's Filters > Enhance > Antialias is the GEGL operation ``gegl:antialias`` (Scale3X
  style: it only acts where neighbours are exactly equal), run through the ``gegl`` command.
* G'MIC's "Smooth [Antialias]" is ``fx_smooth_antialias 50,10,0`` (its defaults), run
  through the ``gmic`` command.

Neither looks at the original. Both are Debian packages (``gegl``, ``gmic``). Each
starts slowly (about 0.7 s), so a batch of images goes through one process: G'MIC takes
every image as its own input, GEGL one atlas whose tiles are separated by replicated
borders wide enough that the 3 x 3 operation never reads a neighbour's pixels.
"""

import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass

import numpy as np

__all__ = ["Peer", "PEERS", "available_peers"]

_ATLAS_GAP = 4


def _save_png(path, image):
    from PIL import Image
    Image.fromarray(np.rint(np.clip(image, 0, 1) * 255).astype(np.uint8)).save(path)


def _load_png(path):
    from PIL import Image
    with Image.open(path) as image:
        return np.asarray(image.convert("RGB"), np.float32) / np.float32(255)


def _run(command, timeout):
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout, check=False)
    if result.returncode != 0:
        tail = result.stderr.decode(errors="replace").strip().splitlines()[-1:] or ["no message"]
        raise RuntimeError(f"{command[0]} exited with status {result.returncode}: {tail[0]}")


def _gegl_batch(images, folder):
    gap = _ATLAS_GAP
    heights = [im.shape[0] + 2 * gap for im in images]
    width = max(im.shape[1] for im in images) + 2 * gap
    atlas = np.zeros((sum(heights), width, 3), np.float32)
    top = 0
    for image, height in zip(images, heights):
        padded = np.pad(image, ((gap, gap), (gap, width - image.shape[1] - gap), (0, 0)), mode="edge")
        atlas[top:top + height] = padded
        top += height
    source, target = os.path.join(folder, "atlas.png"), os.path.join(folder, "atlas-out.png")
    _save_png(source, atlas)
    _run(["gegl", "--", "gegl:load", f"path={source}", "gegl:antialias", "gegl:png-save", f"path={target}",
          "bitdepth=8"], timeout=600)
    result = _load_png(target)
    out, top = [], 0
    for image, height in zip(images, heights):
        out.append(result[top + gap:top + gap + image.shape[0], gap:gap + image.shape[1]])
        top += height
    return out


def _gmic_batch(images, folder):
    sources = []
    for i, image in enumerate(images):
        sources.append(os.path.join(folder, f"in{i:05d}.png"))
        _save_png(sources[-1], image)
    target = os.path.join(folder, "out.png")
    _run(["gmic", "-v", "-", *sources, "fx_smooth_antialias", "50,10,0", "-o", target], timeout=600)
    if len(images) == 1:
        return [_load_png(target)]
    return [_load_png(os.path.join(folder, f"out_{i:06d}.png")) for i in range(len(images))]


@dataclass(frozen=True)
class Peer:
    """A peer tool.

    Attributes
    ----------
    name : str
        Column name in tables.
    label : str
        What it is, for reports.
    command : str
        The executable it needs.
    package : str
        The Debian package that provides it.
    """

    name: str
    label: str
    command: str
    package: str
    _batch: object

    def available(self):
        """bool: the executable is on PATH."""
        return shutil.which(self.command) is not None

    def run(self, images):
        """Apply the tool to each image.

        Parameters
        ----------
        images : list of ndarray of float32, shape (H, W, 3)
            sRGB-encoded, written as 8-bit PNG.

        Returns
        -------
        list of ndarray of float32, shape (H, W, 3)
        """
        with tempfile.TemporaryDirectory(prefix=f"aarecovery-{self.name}-") as folder:
            return self._batch(images, folder)


PEERS = (
    Peer("gimp", "GIMP Antialias (gegl:antialias)", "gegl", "gegl", _gegl_batch),
    Peer("gmic", "G'MIC Smooth [Antialias] (fx_smooth_antialias 50,10,0)", "gmic", "gmic", _gmic_batch),
)


def available_peers():
    """Split :data:`PEERS` into those installed and those missing."""
    return [p for p in PEERS if p.available()], [p for p in PEERS if not p.available()]
