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

from .errors import NotEnoughMemory
from .io.limits import format_bytes

__all__ = ["recovery_bytes", "not_enough_memory"]

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
