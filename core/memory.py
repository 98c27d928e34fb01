"""How much memory a recovery needs: the figure the out-of-memory message gives, and its advice.

Measured peaks of ``aarecovery recover --paper`` on generated 8-bit RGB pairs (``/usr/bin/time``
maximum resident size), against this estimate:

=========  =======  =========  ========  ========
size       backend  tile       measured  estimate
=========  =======  =========  ========  ========
2048^2     gl       2048       0.71 GB   0.96 GB
2048^2     gl       1024       0.41 GB   0.46 GB
4096^2     gl       2048       1.12 GB   1.07 GB
4096^2     gl       1024       0.51 GB   0.57 GB
2048^2     numpy    512        0.12 GB   0.13 GB
4096^2     numpy    512        0.23 GB   0.24 GB
=========  =======  =========  ========  ========

The whole images stay in memory at their own depth (O, F and R; the maps add 16 bytes per
pixel); one tile at a time holds the backend's working set, about 160 bytes per tile pixel
on both backends (GL: ~110 bytes of textures, the readback and the driver's copies; NumPy:
~40 float32 planes); the process itself takes about 250 MB with a GL driver, 50 MB without.
"""

import numpy as np

from .contract import layout_of
from .errors import InputError, NotEnoughMemory
from .io import check_decoded_size, declared_image
from .io.limits import format_bytes, max_bytes_from, raise_the_limit

__all__ = ["recovery_bytes", "not_enough_memory", "check_recovery_peak", "check_pair_files"]

_TILE_BYTES_PER_PIXEL = 160
_PROCESS_BYTES = {"gl": 250 * 10**6, "numpy": 50 * 10**6}
_MAP_BYTES_PER_PIXEL = 16


def _image_bytes(layout):
    return layout.height * layout.width * layout.channels * layout.dtype.itemsize


def recovery_bytes(o_layout, f_layout, backend, tile, maps=False):
    """About how many bytes :func:`aarecovery.recover` needs at its peak.

    Returns
    -------
    whole, tiles, total : int
        The whole images (O, F, R and maps), one tile's working set, and the total with
        the process itself.
    """
    pixels = f_layout.height * f_layout.width
    whole = _image_bytes(o_layout) + 2 * _image_bytes(f_layout) + (_MAP_BYTES_PER_PIXEL * pixels if maps else 0)
    side = min(tile, max(f_layout.height, f_layout.width))
    working = _TILE_BYTES_PER_PIXEL * min(side * side, pixels)
    return whole, working, whole + working + _PROCESS_BYTES.get(backend, _PROCESS_BYTES["gl"])


def not_enough_memory(o_layout, f_layout, backend, tile, maps=False, detail=""):
    """A :class:`NotEnoughMemory` saying what a recovery needs and what to try."""
    whole, working, total = recovery_bytes(o_layout, f_layout, backend, tile, maps)
    advice = []
    if tile > 512:
        smaller = tile // 2
        advice.append(f"smaller tiles (--tile-size {smaller}, tile_size={smaller}: about "
                      f"{format_bytes(recovery_bytes(o_layout, f_layout, backend, smaller, maps)[2])})")
    if backend == "gl":
        numpy_total = recovery_bytes(o_layout, f_layout, "numpy", 512, maps)[2]
        advice.append(f"the NumPy backend (--backend numpy: about {format_bytes(numpy_total)}, slower)")
    advice.append("closing other programs or a machine with more memory")
    return NotEnoughMemory(
        f"not enough memory to recover this {f_layout.width}x{f_layout.height} pair on the {backend} backend"
        f"{f' ({detail})' if detail else ''}: it needs about {format_bytes(total)} ({format_bytes(whole)} for the "
        f"whole images, {format_bytes(working)} for a {min(tile, max(f_layout.height, f_layout.width))}-pixel "
        f"tile); try {', or '.join(advice)}")


def check_recovery_peak(original, filtered, tile, maps=False, max_bytes=None, name=None):
    """Refuse a pair whose recovery would hold more than the image memory limit at its peak.

    The limit (``--max-image-memory``, ``max_bytes``) bounds each decoded image, but a
    recovery holds O, F and R whole and expands one tile to RGBA float planes (a 1.6 GB
    40000 x 40000 grey pair peaked at 5 GB): this counts all of it, from the files' headers,
    before anything is decoded.

    Parameters
    ----------
    original, filtered : (shape, dtype)
        What the two files declare (``aarecovery.io.read.declared_image``).
    tile : int
        The tile side the recovery will use.
    maps : bool
    max_bytes : int or float, optional
        The limit; by default ``aarecovery.io.limits.max_bytes_from``.
    name : str, optional
        The pair, for the message.
    """
    limit = max_bytes_from(max_bytes)
    try:
        o_layout, f_layout = (layout_of(np.broadcast_to(np.zeros((), dtype), shape), role)
                              for (shape, dtype), role in ((original, "original"), (filtered, "filtered")))
    except InputError:  # a layout the reader refuses, naming the file: let it
        return
    whole, working, _ = recovery_bytes(o_layout, f_layout, None, tile, maps)
    if whole + working <= limit:
        return
    raise InputError(
        f"{name + ': ' if name else ''}recovering this {f_layout.width}x{f_layout.height} pair holds about "
        f"{format_bytes(whole + working)} at its peak ({format_bytes(whole)} for O, F and R whole"
        f"{' and the maps' if maps else ''}, {format_bytes(working)} for one tile in RGBA float), over the "
        f"{format_bytes(limit)} limit on image memory; {raise_the_limit(whole + working)}, or give tiled TIFFs, "
        "which stream in bounded memory")


def check_pair_files(original, filtered, tile, maps=False, max_bytes=None, name=None):
    """Before decoding a pair of files: each image's declared size, then the recovery's peak,
    against the limit (:func:`check_recovery_peak`). `filtered` None: F will be made from O,
    of its size."""
    declared = [declared_image(path) for path in (original, filtered) if path is not None]
    for path, (shape, dtype) in zip((original, filtered), declared):
        check_decoded_size(path, shape, dtype, max_bytes)
    check_recovery_peak(declared[0], declared[-1], tile, maps=maps, max_bytes=max_bytes, name=name)
