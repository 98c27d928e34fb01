"""Which 16 x 16 blocks of pixels the passes must draw: those whose surroundings are not flat.

Where O or F is flat around a pixel, its edge strength is exactly 0, beta is 0 and R = F;
llvmpipe shades every fragment a triangle covers (both sides of a branch), so skipping must
happen before the fragment shader, by drawing only the active blocks (``blocks.vert``), and
a GPU's compute path dispatches one work group per active block (``compute.glsl``).

The backend classifies blocks on the GPU (``classify.py``); the functions here are the
specification it is tested against, and the CPU half of the GL 3.3 classification, which
turns a block mask made on the GPU into lists.
"""

import numpy as np

from ...spec.neighbourhood import neighbours, planes
from ...spec.pure_colours import possible_ridges

__all__ = ["BLOCK_SIDE", "MARGIN", "LISTS", "DRAW_COMMAND_WORDS", "DISPATCH_COMMAND_WORDS", "active_mask",
           "active_blocks", "block_lists", "expand_runs", "extreme_offsets", "live_mask", "differing_pixels",
           "blocks_near", "pure_colour_mask", "WAKE_FILTERED", "WAKE_RIDGE", "FIT_PLAIN", "FIT_WHOLE"]

BLOCK_SIDE = 16
#: Pixels around a block whose differences still wake it (see :func:`active_mask`).
MARGIN = 2
#: The lists one classification makes, in the order of ``block_lists.glsl``: the active
#: blocks; those and the 8 around each (what the active blocks read: the working space is
#: made there); and the rest, where R = F.
LISTS = ("active", "dilated", "inactive")
#: Words of one indirect draw command (moderngl's stride) and one dispatch command.
DRAW_COMMAND_WORDS, DISPATCH_COMMAND_WORDS = 5, 3


def active_mask(pixels, side=BLOCK_SIDE, margin=MARGIN):
    """Which blocks of `side` x `side` pixels have surroundings that are not flat.

    A block is active when a pixel that differs from a neighbour lies in it or within
    `margin` pixels of it. With a margin of 2, every pixel whose 3x3 window is not flat
    (margin 1) and every neighbour such a pixel gathers in a Jacobi step (1 more) lies in an
    active block, so the block passes write every value any pass reads, and the rest of the
    image needs only the unfitted model.

    Parameters
    ----------
    pixels : ndarray, shape (H, W, C), C-contiguous
        An image as uploaded (any dtype): equal values here are equal in the working space.
    side, margin : int

    Returns
    -------
    ndarray of bool, shape (ceil(H / side), ceil(W / side))
    """
    height, width, channels = pixels.shape
    # Rows of interleaved values, compared C values apart: contiguous work, no per-channel
    # strided views (3x faster at 4096 x 4096). A pixel differs where any of its values does,
    # so blocks and margins are simply C times wider in values.
    values = pixels.reshape(height, width * channels)
    rows, columns = -(-height // side), -(-width // side)
    touched = np.zeros((rows * side, columns * side * channels), bool)
    across = values[:, channels:] != values[:, :-channels]
    down = values[1:] != values[:-1]
    touched[:height, channels:width * channels] |= across
    touched[:height, :width * channels - channels] |= across
    touched[1:height, :width * channels] |= down
    touched[:height - 1, :width * channels] |= down
    cells = touched.reshape(rows, side, columns, side * channels)
    edge = margin * channels
    active = cells.any(axis=(1, 3))
    # A differing pixel within `margin` of a block's side also wakes the block beyond it.
    active[:-1] |= cells[1:, :margin].any(axis=(1, 3))
    active[1:] |= cells[:-1, -margin:].any(axis=(1, 3))
    active[:, :-1] |= cells[:, :, 1:, :edge].any(axis=(1, 3))
    active[:, 1:] |= cells[:, :, :-1, -edge:].any(axis=(1, 3))
    corners = {(-1, -1): cells[:, :margin, :, :edge], (-1, 1): cells[:, :margin, :, -edge:],
               (1, -1): cells[:, -margin:, :, :edge], (1, 1): cells[:, -margin:, :, -edge:]}
    for (dy, dx), corner in corners.items():
        # The corner of block (r, c) towards (r + dy, c + dx) wakes that diagonal neighbour.
        hit = corner.any(axis=(1, 3))
        active[max(0, dy):rows + min(0, dy), max(0, dx):columns + min(0, dx)] |= \
            hit[max(0, -dy):rows - max(0, dy), max(0, -dx):columns - max(0, dx)]
    return active


def differing_pixels(pixels):
    """bool ``(H, W)``: the pixels whose value differs from a 4-neighbour's (any channel).

    Parameters
    ----------
    pixels : ndarray, shape (H, W, C)
        An image as uploaded.
    """
    differs = np.zeros(pixels.shape[:2], bool)
    across = (pixels[:, 1:] != pixels[:, :-1]).any(axis=-1)
    down = (pixels[1:] != pixels[:-1]).any(axis=-1)
    differs[:, 1:] |= across
    differs[:, :-1] |= across
    differs[1:] |= down
    differs[:-1] |= down
    return differs


def blocks_near(mask, side=BLOCK_SIDE, margin=MARGIN):
    """bool ``(rows, columns)``: the blocks that a true pixel of `mask` lies in or within
    `margin` pixels of (:func:`active_mask` is ``blocks_near(differing_pixels(pixels))``)."""
    height, width = mask.shape
    near = np.zeros((-(-height // side), -(-width // side)), bool)
    ys, xs = np.nonzero(mask)
    for dy in (-margin, 0, margin):
        for dx in (-margin, 0, margin):
            near[np.clip(ys + dy, 0, height - 1) // side, np.clip(xs + dx, 0, width - 1) // side] = True
    return near


#: The bits by which a pixel wakes the pure colours' fit around it (``pure_colour_blocks.glsl``):
#: F varies there; it could be a thin feature's ridge.
WAKE_FILTERED, WAKE_RIDGE = 1, 2
#: The codes of :func:`pure_colour_mask`: a block the pure colours' fit covers without the
#: extension tests, and one it covers whole (``flag_wakes.comp``).
FIT_PLAIN, FIT_WHOLE = 1, 2


def pure_colour_mask(original_work, original, filtered, floor=0.0, gate=None, side=BLOCK_SIDE, margin=MARGIN):
    """Which blocks the pure colours' fit covers, and where it needs its extension tests
    (``flag_pure_colour_blocks`` and ``flag_wakes.comp``, GL 4.3).

    The fit with pure colours gives F exactly, with nothing for a Jacobi step to gather,
    wherever F is flat around a pixel and none of its extremes is extended: its edge strength
    is O's gradient times the larger of F's and of the contrast of the two extremes' filtered
    colours, which differ only where F varies or an extreme was extended; and only a ridge is
    extended, by a pixel whose gate of drawn content is open. So of O's active blocks
    (:func:`active_mask`) it needs those within `margin` of a pixel that could be a ridge
    (``aarecovery.spec.pure_colours.possible_ridges``) or that differs from a 4-neighbour in
    F; the margin of 2 holds the extreme (1 pixel) and what a step gathers from it (1 more).
    Only those near a possible ridge, and with `gate` open on one of their own pixels, can
    extend an extreme: the others take the same model without the tests. A pixel of F that
    varies beside O's edges lies in O's active blocks, so only those pixels are looked at.

    Parameters
    ----------
    original_work : ndarray of float32, shape (H, W, 4)
        O in the working space.
    original, filtered : ndarray, shape (H, W, C)
        O and F as uploaded.
    floor : float
        The ridge's noise margin (``possible_ridges``).
    gate : ndarray of float32, shape (H, W), optional
        The local plan's gate of drawn content (``PureColourPrior.drawn_only``); None: open.
    side, margin : int

    Returns
    -------
    ndarray of uint8, shape (ceil(H / side), ceil(W / side))
        0 (not fitted), :data:`FIT_PLAIN` or :data:`FIT_WHOLE`.
    """
    height, width = original_work.shape[:2]
    fitted = active_mask(original, side, margin)
    inside = np.kron(fitted, np.ones((side, side), bool))[:height, :width]
    ridges = possible_ridges(neighbours(planes(original_work)), floor) & inside
    near_any = blocks_near(ridges | (differing_pixels(filtered) & inside), side, margin)
    whole = blocks_near(ridges, side, margin)
    if gate is not None:
        rows, columns = fitted.shape
        open_pixels = np.zeros((rows * side, columns * side), bool)
        open_pixels[:height, :width] = np.asarray(gate) > 0
        whole &= open_pixels.reshape(rows, side, columns, side).any(axis=(1, 3))
    codes = np.where(whole, FIT_WHOLE, np.where(near_any, FIT_PLAIN, 0)).astype(np.uint8)
    return np.where(fitted, codes, 0).astype(np.uint8)


def extreme_offsets(code):
    """The offsets of a pixel's two extremes from the fit's model code (``neighbourhood.glsl``).

    Parameters
    ----------
    code : ndarray of float32, shape (H, W)
        The model's third channel: ``(a.x + 1) + 3 (a.y + 1) + 9 (b.x + 1) + 27 (b.y + 1)``,
        plus 81 and 162 where extreme a or b is a pure colour (``blend_model.glsl``).

    Returns
    -------
    ndarray of int, shape (H, W, 4)
        ``a.x, a.y, b.x, b.y``, each in -1..1.
    """
    digits = np.rint(code).astype(np.int64) % 81
    return np.stack([digits // 3 ** k % 3 - 1 for k in range(4)], axis=-1)


def live_mask(beta, code, changed, fitted, side=BLOCK_SIDE):
    """Which blocks the Jacobi steps must cover: those the fit flags (``live_blocks.glsl``).

    Where beta is 0 a step gathers nothing and gives its constant, F itself unless the fit
    moved it (pure colours, towards O): exactly what the result holds before the steps. So
    the steps need the blocks of the pixels where beta is not 0 or the constant is not F,
    and, where beta is not 0, the blocks of the two texels the step gathers.

    Parameters
    ----------
    beta, code : ndarray of float32, shape (H, W)
        The fit's model (``model.y``, ``model.z``).
    changed : ndarray of bool, shape (H, W)
        Where the fit's constant of the steps differs from F.
    fitted : ndarray of bool, shape (H, W)
        The pixels the fit covered (its active blocks): only those flag.
    side : int

    Returns
    -------
    ndarray of bool, shape (ceil(H / side), ceil(W / side))
    """
    height, width = beta.shape
    mask = np.zeros((-(-height // side), -(-width // side)), bool)
    gathers = fitted & (beta != 0)
    ys, xs = np.nonzero(fitted & (gathers | changed))
    mask[ys // side, xs // side] = True
    ys, xs = np.nonzero(gathers)
    offsets = extreme_offsets(code[ys, xs])
    for dx, dy in ((offsets[:, 0], offsets[:, 1]), (offsets[:, 2], offsets[:, 3])):
        mask[np.clip(ys + dy, 0, height - 1) // side, np.clip(xs + dx, 0, width - 1) // side] = True
    return mask


def _as_list(mask):
    """``(column, row)`` indices of the true blocks, row-major, as the GPU lists hold them."""
    return np.ascontiguousarray(np.argwhere(mask)[:, ::-1], dtype=np.int32)


def active_blocks(pixels, side=BLOCK_SIDE, margin=MARGIN):
    """The active blocks of :func:`active_mask` as a list.

    Returns
    -------
    ndarray of int32, shape (N, 2)
        ``(column, row)`` block indices, row-major.
    """
    return _as_list(active_mask(pixels, side, margin))


def _as_runs(mask):
    """Runs of true blocks along rows, ``(column | (length - 1) << 16, row)``, row-major."""
    edges = np.diff(np.pad(mask, ((0, 0), (1, 1))).astype(np.int8), axis=1)
    starts, stops = np.argwhere(edges == 1), np.argwhere(edges == -1)  # pairs, in the same order
    runs = np.stack([starts[:, 1] | ((stops[:, 1] - starts[:, 1] - 1) << 16), starts[:, 0]], axis=-1)
    return np.ascontiguousarray(runs, dtype=np.int32)


def expand_runs(entries):
    """The blocks of run entries (see :func:`block_lists`), as ``(column, row)`` pairs."""
    blocks = [(column & 0xFFFF) + offset for column, _ in entries for offset in range((column >> 16) + 1)]
    rows = [row for column, row in entries for _ in range((column >> 16) + 1)]
    return np.asarray(list(zip(blocks, rows)), dtype=np.int32).reshape(-1, 2)


def block_lists(mask, runs=False):
    """The three lists of :data:`LISTS` from a block mask.

    Parameters
    ----------
    mask : ndarray of bool, shape (rows, columns)
        Active blocks (:func:`active_mask`, or the GPU's block mask).
    runs : bool
        List runs of blocks along rows, as the fragment path draws them: one entry
        ``(column | (length - 1) << 16, row)`` per run.

    Returns
    -------
    dict of str to ndarray of int32, shape (N, 2)
        ``(column, row)`` block indices (or runs) per list, row-major.
    """
    padded = np.pad(mask, 1)
    rows, columns = mask.shape
    dilated = np.zeros_like(mask)
    for dy in range(3):
        for dx in range(3):
            dilated |= padded[dy:dy + rows, dx:dx + columns]
    listed = _as_runs if runs else _as_list
    return {"active": listed(mask), "dilated": listed(dilated), "inactive": listed(~mask)}
