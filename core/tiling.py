"""Tiles with a halo: how an image larger than a backend's limit is recovered piece by piece.

Recovery is local: a pixel of R depends only on O and F within a small radius, the
:func:`halo_for` the iterations. A tile grown by that halo on every side therefore gives,
on its inner part, exactly the result of the whole image. The NumPy backend uses the same
rule for its row strips.
"""

import numbers
import warnings

from .errors import InputError, TileSizeWarning

__all__ = ["DEFAULT_TILES", "SENSIBLE_TILE", "halo_for", "tiles", "aligned_tiles", "smallest_tile", "sensible_tile",
           "check_tile_size"]

#: The tile side each backend runs at by default, in pixels. NumPy: its passes hold about
#: 40 float32 values per pixel at once, so 512 x 512 keeps a tile near 50 MB and in
#: cache-friendly pieces. GL on a CPU renderer (llvmpipe, whose textures are in main memory):
#: 1024, measured with ``aarecovery recover --paper`` on a 4096 x 4096 RGB pair (3 runs,
#: CPU seconds, peak memory): 1024 took 1.5-1.9 s and 0.34 GB, 2048 1.6-1.9 s and 0.46 GB,
#: one 4096 tile 2.2-2.4 s and 1.8 GB. GL on a GPU: 2048, where tiles cost only transfers
#: and dispatches (not measured on a GPU since tiles became equal in size).
DEFAULT_TILES = {"gl": 2048, "gl-software": 1024, "numpy": 512}
#: The smallest tile side worth running. Each tile recomputes its halo and pays a fixed
#: cost (an upload and a set of passes on GL). On a 768 x 512 pair, paper mode, 3
#: iterations (halo 4), against the default tiles: GL 32 px 3.1x the time, 48 px 1.5x,
#: 64 px 1.7x, 128 px 0.4x (one tile per 128 px strip, and noise); NumPy 32 px 3.6x, 48 px
#: 2.0x, 64 px 1.5x, 128 px 1.0x; 16 px took 20x on GL and the issue measured 9 px at
#: 282 s (GL) and 505 s (NumPy) where the default takes 0.1-0.3 s.
SENSIBLE_TILE = 64


def halo_for(iterations, reach=0):
    """Border width that makes a tiled result equal the untiled one.

    `reach` is how much farther a plan reads O (``Plan.reach``: the local plan's factor).

    The model fit and Sobel read a 3x3 neighbourhood (radius 1), and each Jacobi iteration
    reads R at the extreme positions, again within radius 1 of the pixel. R after k
    iterations therefore depends on O and F within radius k + 1. The safe default's
    pure-colour test (``aarecovery.spec.pure_colours``) reads O around the extreme pixel,
    radius 2 for the model; R after k iterations reads models within radius k - 1, so O
    within radius k + 1: the same halo, except for maps alone (k = 0), whose model needs
    radius 2. Its image-border test only fires at a tile's edge, which lies beyond what the
    pixels a tile decides read.
    """
    return max(iterations + 1, 2) + reach


def smallest_tile(iterations):
    """The smallest tile side that leaves an interior with the halo of `iterations`."""
    return 2 * halo_for(iterations) + 1


def sensible_tile(iterations):
    """The smallest tile side worth running: :data:`SENSIBLE_TILE`, or 6 halos, whichever is more.

    At 6 halos the interior is two thirds of the side, so a tile's halo costs at most
    (6/4)^2 = 2.25 times the work of its interior (with many iterations the halo grows).
    """
    return max(SENSIBLE_TILE, 6 * halo_for(iterations))


def check_tile_size(tile_size, iterations, name="tile_size", image_size=None):
    """Return `tile_size` as an int, or raise :class:`InputError` when it leaves no interior.

    `name` is how the caller's user wrote it. The command line (``name="--tile-size"``)
    also refuses tiles below :func:`sensible_tile`, which only make a run take minutes; the
    library warns (:class:`~aarecovery.errors.TileSizeWarning`) when an image of
    `image_size` ``(height, width)`` would be cut into such tiles.
    """
    smallest = smallest_tile(iterations)
    if isinstance(tile_size, bool) or not isinstance(tile_size, numbers.Integral):
        raise InputError(f"{name} must be a whole number of pixels, got {tile_size!r}")
    if tile_size < smallest:
        raise InputError(f"{name} {tile_size} is too small for {iterations} iterations: each tile needs a "
                         f"{halo_for(iterations)}-pixel border on each side, so use at least {smallest}")
    sensible = sensible_tile(iterations)
    if tile_size < sensible:
        why = (f"{name} {tile_size} is below {sensible}: tiles that small recompute their "
               f"{halo_for(iterations)}-pixel borders and repeat their set-up so often that a run takes many "
               "times longer for the same result")
        if name.startswith("--"):
            raise InputError(f"{why}; use at least {sensible}, or leave it out for the backend's default")
        if image_size is not None and max(image_size) > tile_size:
            warnings.warn(why, TileSizeWarning, stacklevel=3)
    return int(tile_size)


def aligned_tiles(height, width, step, halo):
    """Like :func:`tiles`, with each tile's part on a grid of `step` pixels.

    A tiled TIFF is written in tiles of its own grid: a streamed pair decides each of them
    whole, in order (``aarecovery.stream``). Every window has one shape, the part and
    `halo` on each side, shifted inwards at the image's borders.

    Yields
    ------
    inner, outer : tuple of slice
        As for :func:`tiles`; `inner` starts at multiples of `step`.
    """
    if step < 1:
        raise ValueError(f"a grid of {step} pixels has no tiles")
    for rows, outer_rows in _aligned_spans(height, step, halo):
        for columns, outer_columns in _aligned_spans(width, step, halo):
            yield (rows, columns), (outer_rows, outer_columns)


def _aligned_spans(length, step, halo):
    if length <= step:
        return [(slice(0, length), slice(0, length))]
    window = min(length, step + 2 * halo)
    spans = []
    for start in range(0, length, step):
        first = min(max(0, start - halo), length - window)
        spans.append((slice(start, min(start + step, length)), slice(first, first + window)))
    return spans


def _spans(length, tile, halo):
    """``(inner, outer)`` slices along one axis: even inner parts, outer windows of one width."""
    if length <= tile:
        return [(slice(0, length), slice(0, length))]
    step = tile - 2 * halo
    count = -(-length // step)
    bounds = [part * length // count for part in range(count + 1)]
    # The widest part with its halo on both sides; every window gets this width, shifted
    # inwards at the image's borders, where it then holds more than the halo.
    window = min(length, max(b - a for a, b in zip(bounds, bounds[1:])) + 2 * halo)
    return [(slice(start, stop), slice(min(max(0, start - halo), length - window),
                                       min(max(0, start - halo), length - window) + window))
            for start, stop in zip(bounds, bounds[1:])]


def tiles(height, width, tile, halo):
    """Split an image into tiles with halos.

    The image is split into as few tiles as fit in `tile` with their halos, of nearly equal
    sizes, and every tile loads a window of the same shape (larger than its part and halo
    where it meets the image's border): a backend then allocates its buffers once per image,
    and no tile is a sliver. Any window holding the part and its halo gives the untiled
    result there.

    Yields
    ------
    inner : tuple of slice
        The rows and columns this tile decides.
    outer : tuple of slice
        The rows and columns to load: `inner` grown by at least `halo` where the image
        allows, at most `tile` a side, the same shape for every tile.
    """
    if tile - 2 * halo < 1:
        raise ValueError(f"tile size {tile} leaves no interior with a halo of {halo}")
    for rows, outer_rows in _spans(height, tile, halo):
        for columns, outer_columns in _spans(width, tile, halo):
            yield (rows, columns), (outer_rows, outer_columns)
