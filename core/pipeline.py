"""``aarecovery.recover``: the whole pipeline for one pair, top to bottom.

check the pair -> resolve the mode into a Plan once (``aarecovery.plan``) -> split into
tiles with a halo (``aarecovery.tiling``) -> load and run each tile in an Engine (its
backend's passes) -> assemble the result in the filtered image's layout and dtype.
"""

import numpy as np

from .backends.base import RecoveryMaps
from .contract import check_same_size, check_values, layout_of
from .engine import Engine
from .params import DEFAULT_MODE, ITERATIONS, SIGMA_D, SIGMA_E, Parameters, check_blend_space, check_mode
from .plan import make_plan
from .sample import array_sample
from .tiling import check_tile_size, halo_for, tiles

__all__ = ["recover", "recover_tiles"]


def recover(original, filtered, *, sigma_d=SIGMA_D.default, sigma_e=SIGMA_E.default, iterations=ITERATIONS.default,
            backend="auto", linear=False, blend_space=None, return_maps=False, tile_size=None, engine=None,
            mode=DEFAULT_MODE, plan=None):
    """Repair the antialiased edges of `filtered` using the edges of `original`.

    Parameters
    ----------
    original : ndarray, shape (H, W) or (H, W, C), C in 1..4
        The image before the filter: uint8, uint16, or float in [0, 1]; grey, grey+alpha,
        RGB or RGBA.
    filtered : ndarray, shape (H, W) or (H, W, C), C in 1..4
        The same image after the filter, the same width and height as `original`.
    sigma_d : float, optional
        Colour-line distance scale. Larger values accept noisier colour lines.
    sigma_e : float, optional
        Edge-strength scale. Smaller values repair weaker edges.
    iterations : int, optional
        Jacobi iterations (0 returns `filtered`). Defaults and valid ranges of the three
        are in ``aarecovery.PARAMETERS``.
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
    plan : Plan, optional
        The pair's plan when it is already made (``aarecovery.plan.make_plan`` on the
        window ``aarecovery.sample`` picks, as this function would make it): the batch
        makes it in a worker thread. It then decides instead of the parameters, `mode`
        and `blend_space`.

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
    parameters = Parameters(sigma_d, sigma_e, iterations)
    check_mode(mode)
    if blend_space is not None:
        check_blend_space(blend_space)
    if tile_size is not None:
        tile_size = check_tile_size(tile_size, parameters.iterations)
    check_values(original, o_layout, "original")
    check_values(filtered, f_layout, "filtered")
    # Every decision on the whole image, before tiling, so that tiled == untiled; the
    # analysis reads the window that aarecovery.sample chooses, as a streamed pair does.
    if plan is None:
        plan = make_plan(*array_sample(original, filtered), parameters, mode=mode, linear=linear,
                         blend_space=blend_space)
    if plan.keeps_filtered and not return_maps:
        return filtered.copy()

    own_engine = engine is None
    if own_engine:
        engine = Engine(backend)
    try:
        capabilities = engine.capabilities
        tile = min(capabilities.max_tile, tile_size or capabilities.default_tile)
        height, width = f_layout.height, f_layout.width
        result = np.empty(f_layout.shape, f_layout.dtype)
        maps = None
        if return_maps:
            maps = RecoveryMaps(*(np.empty((height, width), np.float32) for _ in RecoveryMaps.NAMES))
        pieces = recover_tiles(engine, lambda outer: (original[outer], filtered[outer]), plan,
                               tiles(height, width, tile, halo_for(plan.iterations)), linear=linear, maps=return_maps)
        for inner, tile_result, tile_maps in pieces:
            result[inner] = tile_result
            if return_maps:
                for name in RecoveryMaps.NAMES:
                    getattr(maps, name)[inner] = getattr(tile_maps, name)
    finally:
        if own_engine:
            engine.release()
    return (result, maps) if return_maps else result


def recover_tiles(engine, read, plan, pieces, *, linear=False, maps=False):
    """Run a resolved plan tile by tile: the loop of :func:`recover`, for any source of pixels.

    Parameters
    ----------
    engine : Engine
    read : callable
        ``read(outer) -> (original, filtered)``: the pair's pixels in the rows and columns
        ``outer`` (a tuple of two slices), in the caller's layout and dtype.
    plan : Plan
        Made once for the whole pair.
    pieces : iterable of (inner, outer)
        Tiles with halos, from ``aarecovery.tiling.tiles``.
    linear, maps : bool
        The pair holds linear light; also give each tile's maps.

    Yields
    ------
    inner : tuple of slice
    result : ndarray
        R on `inner`, in the filtered image's layout and dtype.
    maps : RecoveryMaps or None
        The maps on `inner`, with ``maps=True``.
    """
    for inner, outer in pieces:
        original, filtered = read(outer)
        engine.set_images(original, filtered, linear=linear, blend_space=plan.blend_space)
        engine.run(plan, maps=maps)
        crop = tuple(slice(i.start - o.start, i.stop - o.start) for i, o in zip(inner, outer))
        tile_maps = None
        if maps:
            whole = engine.maps()
            tile_maps = RecoveryMaps(*(getattr(whole, name)[crop] for name in RecoveryMaps.NAMES))
        yield inner, engine.result()[crop], tile_maps
