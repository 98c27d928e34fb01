"""``aarecovery.recover``: one call, any size, tiled where needed."""

import numpy as np

from ._contract import check_same_size, check_values, layout_of
from ._engine import Engine, RecoveryMaps, plan_for_pair
from ._errors import InputError
from ._params import Parameters, check_blend_space, check_mode

__all__ = ["recover", "halo_for", "tiles"]

# Pixels per tile side on the NumPy backend: its passes hold about 40 float32 values per
# pixel at once, so 512 x 512 keeps a tile near 50 MB and in cache-friendly pieces.
NUMPY_TILE = 512
# GL tiles are capped below the texture limit as well: the passes keep about 110 bytes of
# textures per pixel, so a 2048 x 2048 tile holds ~450 MB, and `aarecovery recover` on a
# 4096 x 4096 RGB pair peaks at 1.2 GB in all (4096 tiles: 1.9 GB, measured). Larger tiles
# gain no speed on llvmpipe.
GL_TILE = 2048


def halo_for(iterations):
    """Border width that makes a tiled result equal the untiled one.

    The model fit and Sobel read a 3x3 neighbourhood (radius 1), and each Jacobi iteration
    reads R at the extreme positions, again within radius 1 of the pixel. R after k
    iterations therefore depends on O and F within radius k + 1. The safe default's
    pure-colour test (``_pure_colours``) reads O around the extreme pixel, radius 2 for the
    model; R after k iterations reads models within radius k - 1, so O within radius k + 1:
    the same halo, except for maps alone (k = 0), whose model needs radius 2. Its
    image-border test only fires at a tile's edge, which lies beyond what the pixels a tile
    decides read.
    """
    return max(iterations + 1, 2)


def tiles(height, width, tile, halo):
    """Split an image into tiles with halos.

    Yields
    ------
    inner : tuple of slice
        The rows and columns this tile decides.
    outer : tuple of slice
        The rows and columns to load: `inner` grown by `halo`, clipped to the image.
    """
    step = tile - 2 * halo
    if step < 1:
        raise ValueError(f"tile size {tile} leaves no interior with a halo of {halo}")
    if height <= tile and width <= tile:
        whole = (slice(0, height), slice(0, width))
        yield whole, whole
        return
    for top in range(0, height, step):
        for left in range(0, width, step):
            bottom, right = min(top + step, height), min(left + step, width)
            yield ((slice(top, bottom), slice(left, right)),
                   (slice(max(0, top - halo), min(height, bottom + halo)),
                    slice(max(0, left - halo), min(width, right + halo))))


def recover(original, filtered, *, sigma_d=0.1, sigma_e=0.01, iterations=3, backend="auto",
            linear=False, blend_space=None, return_maps=False, tile_size=None, engine=None, mode="safe"):
    """Repair the antialiased edges of `filtered` using the edges of `original`.

    Parameters
    ----------
    original : ndarray, shape (H, W) or (H, W, C), C in 1..4
        The image before the filter: uint8, uint16, or float in [0, 1]; grey, grey+alpha,
        RGB or RGBA.
    filtered : ndarray, shape (H, W) or (H, W, C), C in 1..4
        The same image after the filter, the same width and height as `original`.
    sigma_d : float, optional
        Colour-line distance scale, > 0. Larger values accept noisier colour lines.
    sigma_e : float, optional
        Edge-strength scale, > 0. Smaller values repair weaker edges.
    iterations : int, optional
        Jacobi iterations, 0 to 64 (0 returns `filtered`).
    backend : {"auto", "gl", "numpy"}, optional
        ``"auto"`` uses OpenGL and falls back to NumPy with a warning.
    linear : bool, optional
        True when the images hold linear-light values; by default they are sRGB-encoded.
    blend_space : {"linear", "srgb"}, optional
        Where the two-colour model is fitted and imposed. By default ``mode="safe"`` picks
        the space in which the image was antialiased, and ``mode="paper"`` uses linear light.
    return_maps : bool, optional
        Also return the :class:`RecoveryMaps`.
    tile_size : int, optional
        Largest tile side; images larger than this are processed in overlapping tiles whose
        result equals the untiled one. By default the backend's own limit.
    engine : Engine, optional
        An engine to reuse (its backend wins over `backend`).
    mode : {"safe", "paper"}, optional
        ``"safe"`` (the default) analyses the whole pair once before tiling: it picks the
        blend space, leaves blurred images alone, and calibrates the repair strength so that
        the result is not worse than `filtered` (see ``docs/quality.md``). ``"paper"`` is the
        method of Yang et al. (2011) exactly.

    Returns
    -------
    recovered : ndarray
        The same shape and dtype as `filtered`.
    maps : RecoveryMaps
        Only with ``return_maps=True``.

    Raises
    ------
    InputError
        On images or parameters the core cannot use; the message says how to fix them.

    Examples
    --------
    >>> import numpy as np, aarecovery
    >>> o = np.linspace(0, 1, 64, dtype=np.float32).reshape(8, 8)
    >>> f = (o > 0.5).astype(np.float32)
    >>> aarecovery.recover(o, f, backend="numpy").shape
    (8, 8)
    """
    o_layout = layout_of(original, "original")
    f_layout = layout_of(filtered, "filtered")
    check_same_size(o_layout, f_layout)
    params = Parameters(sigma_d, sigma_e, iterations)
    check_mode(mode)
    if blend_space is not None:
        check_blend_space(blend_space)
    if tile_size is not None:
        smallest = 2 * halo_for(params.iterations) + 1
        if isinstance(tile_size, bool) or not isinstance(tile_size, (int, np.integer)) or tile_size < smallest:
            raise InputError(f"tile_size must be a whole number of at least {smallest} pixels with "
                             f"{params.iterations} iterations (a halo of {halo_for(params.iterations)} "
                             f"on each side), got {tile_size!r}")
    check_values(original, o_layout, "original")
    check_values(filtered, f_layout, "filtered")
    if mode == "safe":
        # Global decisions on the whole image, before tiling, so that tiled == untiled.
        plan = plan_for_pair(original, filtered, linear)
        blend_space = blend_space or plan.blend_space
        params = Parameters(params.sigma_d, params.sigma_e, params.iterations, plan.strength, plan.pure_colours)
        if plan.strength == 0 and not return_maps:
            return filtered.copy()
    blend_space = blend_space or "linear"

    own_engine = engine is None
    if own_engine:
        engine = Engine(backend)
    try:
        limit = engine._impl.max_tile if engine.backend == "gl" else NUMPY_TILE
        tile = min(limit, tile_size if tile_size is not None else
                   (GL_TILE if engine.backend == "gl" else NUMPY_TILE))
        height, width = f_layout.height, f_layout.width
        result = np.empty(f_layout.shape, f_layout.dtype)
        maps = None
        if return_maps:
            maps = RecoveryMaps(*(np.empty((height, width), np.float32) for _ in RecoveryMaps.NAMES))
        for inner, outer in tiles(height, width, tile, halo_for(params.iterations)):
            engine.set_images(original[outer], filtered[outer], linear=linear, blend_space=blend_space)
            engine._run(params, return_maps)
            crop = tuple(slice(i.start - o.start, i.stop - o.start) for i, o in zip(inner, outer))
            result[inner] = engine.result()[crop]
            if return_maps:
                tile_maps = engine.maps()
                for name in RecoveryMaps.NAMES:
                    getattr(maps, name)[inner] = getattr(tile_maps, name)[crop]
    finally:
        if own_engine:
            engine.release()
    return (result, maps) if return_maps else result
