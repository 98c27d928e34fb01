"""``aarecovery.recover``: the whole pipeline for one pair, top to bottom.

check the pair -> resolve the mode into a Plan once (``aarecovery.plan``) -> split into
tiles with a halo (``aarecovery.tiling``) -> load and run each tile in an Engine (its
backend's passes) -> assemble the result in the filtered image's layout and dtype.
"""

import dataclasses
import warnings

import numpy as np

from .backends.base import RecoveryMaps
from .contract import check_same_size, check_values, from_rgba_float, layout_of, native_byte_order
from .engine import Engine
from .errors import NotEnoughMemory, OrderWarning
from .memory import not_enough_memory
from .params import (DEFAULT_MODE, ITERATIONS, SIGMA_D, SIGMA_E, STRENGTH, Parameters, check_blend_space,
                     check_gl_path, check_mode)
from .plan import make_plan
from .plan.order import check_order
from .sample import array_window
from .tiling import DEFAULT_TILES, check_tile_size, halo_for, tiles

__all__ = ["recover", "recover_tiles", "tile_side"]


def recover(original, filtered, *, sigma_d=SIGMA_D.default, sigma_e=SIGMA_E.default, iterations=ITERATIONS.default,
            backend="auto", linear=False, blend_space=None, return_maps=False, tile_size=None, engine=None,
            mode=DEFAULT_MODE, gl_path="auto", strength=STRENGTH.default, plan=None, quantization=None):
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
        An engine to reuse (its backend and GL path win over `backend` and `gl_path`); its
        ``last_plan`` then says what was decided, for :func:`aarecovery.summarize_recovery`.
    mode : {"safe", "paper"}, optional
        ``"safe"`` (the default) analyses the whole pair once before tiling: it picks the
        blend space, leaves blurred images alone, and calibrates the repair strength so that
        the result is not worse than `filtered` (see ``docs/quality.md``). ``"paper"`` is the
        method of Yang et al. (2011) exactly.
    gl_path : {"auto", "fragment", "compute"}, optional
        How the GL backend runs its passes (``aarecovery.params.GL_PATHS``); ``"auto"``
        chooses by the GL version and a measured rule.
    strength : float, optional
        How much to repair, from 0 (`filtered` as it is) to 1 (the full repair), instead of
        the strength the mode chooses (``"safe"``: per image; ``"paper"``: 1). It also
        forces a repair where the safe default would keep `filtered` (a blur, a photo under
        a neighbourhood filter).
    plan : Plan, optional
        The pair's plan when it is already made (``aarecovery.plan.make_plan`` on the
        window ``aarecovery.sample`` picks, as this function would make it): the batch
        makes it in a worker process. It then decides instead of the parameters, `mode`,
        `strength` and `blend_space`.
    quantization : sequence of sequence of int, optional
        The quantization tables of `original`'s JPEG file (:func:`aarecovery.read_quantization`):
        the safe default then knows how large O's compression noise is. Without them it looks
        for a JPEG block grid in O's pixels.

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
    NotEnoughMemory
        A MemoryError whose message says how much the pair needs and what to try.

    Warns
    -----
    OrderWarning
        When the pair looks given in the wrong order (:func:`aarecovery.check_order`).

    Examples
    --------
    >>> import numpy as np, aarecovery
    >>> o = np.linspace(0, 1, 64, dtype=np.float32).reshape(8, 8)
    >>> f = (o > 0.5).astype(np.float32)
    >>> aarecovery.recover(o, f, backend="numpy").shape
    (8, 8)
    """
    original, filtered = native_byte_order(original), native_byte_order(filtered)
    o_layout = layout_of(original, "original")
    f_layout = layout_of(filtered, "filtered")
    check_same_size(o_layout, f_layout)
    parameters = Parameters(sigma_d, sigma_e, iterations, strength)
    check_mode(mode)
    check_gl_path(gl_path)
    if blend_space is not None:
        check_blend_space(blend_space)
    if tile_size is not None:
        tile_size = check_tile_size(tile_size, parameters.iterations, image_size=f_layout.shape[:2])
    check_values(original, o_layout, "original")
    check_values(filtered, f_layout, "filtered")
    order = check_order(original, filtered, linear=linear)
    if order.looks_reversed:
        warnings.warn(order.reason, OrderWarning, stacklevel=2)
    # Every decision on the whole image, before tiling, so that tiled == untiled; the
    # analysis reads the window that aarecovery.sample chooses, as a streamed pair does.
    try:
        if plan is None:
            # The paper's method reads nothing of the pair: no window to choose (50 ms at 4096^2).
            window = array_window(original) if mode == "safe" else None
            pair = (original, filtered) if window is None else (original[window], filtered[window])
            plan = dataclasses.replace(make_plan(*pair, parameters, mode=mode, linear=linear, blend_space=blend_space,
                                                 quantization=quantization), window=window)
        if plan.keeps_filtered and not return_maps:
            if engine is not None:
                engine.last_plan = plan
            return filtered.copy()
    except MemoryError as error:
        name = engine.backend if engine is not None else "gl" if backend == "auto" else backend
        raise _out_of_memory(error, o_layout, f_layout, name, tile_size or DEFAULT_TILES[name], return_maps) from None

    own_engine = engine is None
    if own_engine:
        engine = Engine(backend, gl_path=gl_path)
    tile = tile_side(engine.capabilities, tile_size)
    try:
        return _recover_in_tiles(original, filtered, f_layout, plan, engine, tile, linear, return_maps)
    except MemoryError as error:
        raise _out_of_memory(error, o_layout, f_layout, engine.backend, tile, return_maps) from None
    finally:
        if own_engine:
            engine.release()


def tile_side(capabilities, tile_size=None):
    """The tile side :func:`recover` uses on a backend with these capabilities."""
    return min(capabilities.max_tile, tile_size or capabilities.default_tile)


def _out_of_memory(error, o_layout, f_layout, backend, tile, return_maps):
    """One line with the figures, instead of a traceback from wherever the allocation failed."""
    if isinstance(error, NotEnoughMemory):
        return error
    return not_enough_memory(o_layout, f_layout, backend, tile, return_maps, str(error))


def _recover_in_tiles(original, filtered, f_layout, plan, engine, tile, linear, return_maps):
    height, width = f_layout.height, f_layout.width
    result = np.empty(f_layout.shape, f_layout.dtype)
    maps = None
    if return_maps:
        maps = RecoveryMaps(*(np.empty((height, width), np.float32) for _ in RecoveryMaps.NAMES))
    # The local plan reads farther than the tile size was checked for: the tile grows by its
    # reach on each side, so that its interior stays what the size was chosen for.
    halo = halo_for(plan.iterations, plan.reach)
    pieces = recover_tiles(engine, lambda outer: (original[outer], filtered[outer]), plan,
                           tiles(height, width, min(engine.capabilities.max_tile, tile + 2 * plan.reach), halo),
                           f_layout, linear=linear, maps=return_maps, into=result)
    for inner, _, tile_maps in pieces:
        if return_maps:
            for name in RecoveryMaps.NAMES:
                getattr(maps, name)[inner] = getattr(tile_maps, name)
    return (result, maps) if return_maps else result


def recover_tiles(engine, read, plan, pieces, layout, *, linear=False, maps=False, into=None):
    """Run a resolved plan tile by tile: the loop of :func:`recover`, for any source of pixels.

    Each tile's readback starts before the previous tile is handed over, so that on a GPU
    the copy overlaps the caller's work on the previous tile.

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
    layout : Layout
        The filtered image's (``aarecovery.contract.layout_of``): the results' channels and dtype.
    linear, maps : bool
        The pair holds linear light; also give each tile's maps.
    into : ndarray, optional
        The whole result, to write each tile's part into (no copy); by default each tile's
        result is a new array.

    Yields
    ------
    inner : tuple of slice
    result : ndarray
        R on `inner`, in the filtered image's layout and dtype (a view of `into` if given).
    maps : RecoveryMaps or None
        The maps on `inner`, with ``maps=True``.
    """
    # The engine's lock for the whole pair: a thread sharing the engine waits, instead of
    # loading its tiles between this one's load and readback.
    with engine.lock:
        pending = None
        for inner, outer in pieces:
            original, filtered = read(outer)
            engine.set_images(original, filtered, linear=linear, blend_space=plan.blend_space)
            engine.run(plan, maps=maps, wait=False)
            crop = tuple(slice(i.start - o.start, i.stop - o.start) for i, o in zip(inner, outer))
            tile_maps = None
            if maps:
                whole = engine.maps()
                tile_maps = RecoveryMaps(*(getattr(whole, name)[crop] for name in RecoveryMaps.NAMES))
            started = engine.start_result(crop)
            if pending is not None:
                yield _finished(pending, layout, into)
            pending = (inner, started, tile_maps)
        if pending is not None:
            yield _finished(pending, layout, into)


def _finished(pending, layout, into):
    inner, started, tile_maps = pending
    height, width = (part.stop - part.start for part in inner)
    out = into[inner] if into is not None else np.empty((height, width) + layout.shape[2:], layout.dtype)
    from_rgba_float(started.wait(), layout, out=out)
    return inner, out, tile_maps
