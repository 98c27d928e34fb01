"""The part of a pair that the safe plan's analysis sees, chosen from the whole image.

``aarecovery.plan`` analyses one window of the pair (``analysis_crop``: at most 512 x 512
pixels). Which window matters for large images: the centre of a scanned page can be a
margin, the centre of a map a sea, and a gigapixel file cannot be loaded to look. So the
window is chosen here, by looking at the whole image in pieces, and every caller (the
in-memory pipeline, the engine, the streamed tiled-TIFF path and the batch) plans on the
same window: the result does not depend on how the pair is stored or read.

How: windows of the analysis's own size are laid on a grid that spans the image (at most
8 x 8 positions, evenly spaced, plus the central window); only O is read for them, and the
window with the most edge pixels of O wins; ties go to the window nearest the centre, so
an image without edges is analysed where it always was. Images no larger than the window
are analysed whole, as before.

One window, not a mosaic of pieces from all over the image: the analysis fits kernels and
colour lines over neighbourhoods, and a mosaic's seams are edges that are in neither image.
Measured on a 2048 x 2048 photo-like pair (``aarecovery.lab.bench.bench_image_pair``)
under the built-in blur: the chosen window finds the blur (kernel residual 0.009, F kept);
2 x 2 and 4 x 4 mosaics of 256- and 128-pixel pieces do not (0.026 and 0.040, and the
fitted kernel is no longer low-pass), so the paper's passes would re-sharpen the blur.
Threshold and gamma were decided alike either way.
"""

import numpy as np

from .colour import luma
from .plan.analysis import analysis_crop
from .plan.blas import one_blas_thread

__all__ = ["analysis_sample", "array_sample", "array_window", "analysis_window", "analysis_windows"]

# Grid positions per axis: 64 windows of 512 x 512 read 17 megapixels of O, a few seconds
# of decoding at most for a gigapixel tiled TIFF, and 13 windows (40 ms) for 1920 x 1080.
_MOST_POSITIONS = 8
# An edge pixel for the choice of window: luma differs from the next pixel (right or below)
# by more than 1/16. Well above 8-bit sensor noise (about 2/255), and a two-pixel
# antialiased transition between colours whose luma differs by 1/8 or more passes it.
_EDGE_STEP = 1 / 16


def _window_side(height, width):
    """The (rows, columns) the analysis reads of an image of this size, from the analysis itself."""
    return analysis_crop(np.broadcast_to(np.zeros((), bool), (height, width))).shape


def _positions(length, side):
    if length <= side:
        return [0]
    count = min(_MOST_POSITIONS, -(-length // side))
    return sorted(set(np.linspace(0, length - side, count).round().astype(int).tolist()))


def analysis_windows(height, width):
    """Candidate analysis windows of an image, nearest the centre first.

    Returns
    -------
    list of (slice, slice)
        Rows and columns of each window; the first is the central one.
    """
    side_h, side_w = _window_side(height, width)
    centre = ((height - side_h) // 2, (width - side_w) // 2)
    corners = {(top, left) for top in _positions(height, side_h) for left in _positions(width, side_w)}
    corners.add(centre)
    ordered = sorted(corners, key=lambda c: ((c[0] - centre[0]) ** 2 + (c[1] - centre[1]) ** 2, c))
    return [(slice(top, top + side_h), slice(left, left + side_w)) for top, left in ordered]


def _edge_pixels(region):
    values = region if region.ndim == 2 else region[..., 0] if region.shape[2] <= 2 else region[..., :3]
    scale = np.float32(1 / np.iinfo(values.dtype).max) if values.dtype.kind in "ui" else np.float32(1)
    # The same values as astype(float32) * scale, np.diff and a sum of the flags, in fewer
    # passes over the window: the 65 windows of a 4096 x 4096 photo 0.12 -> 0.09 s on a slow
    # 2-core machine (tests/test_exact_speedups.py).
    light = np.multiply(values, scale, dtype=np.float32)
    if light.ndim == 3:
        light = luma(light)
    across = np.abs(np.subtract(light[:, 1:], light[:, :-1])) > _EDGE_STEP
    down = np.abs(np.subtract(light[1:], light[:-1])) > _EDGE_STEP
    return int(np.count_nonzero(across)) + int(np.count_nonzero(down))


def analysis_sample(read_original, read_filtered, height, width):
    """The window of a pair that the safe plan analyses, read through two region readers.

    Parameters
    ----------
    read_original, read_filtered : callable
        ``read(rows, cols) -> ndarray`` giving a region of O or F (slices), in the image's
        own dtype and layout (as :func:`aarecovery.read_image` gives the whole).
    height, width : int
        The pair's size.

    Returns
    -------
    original, filtered : ndarray
        The chosen window of each, to give ``aarecovery.plan.make_plan`` or ``analyse_pair``.
    """
    rows, cols = analysis_window(read_original, height, width)
    return read_original(rows, cols), read_filtered(rows, cols)


def analysis_window(read_original, height, width):
    """The rows and columns (two slices) of the window :func:`analysis_sample` reads: the
    candidate of :func:`analysis_windows` with the most edge pixels in O."""
    windows = analysis_windows(height, width)
    if len(windows) == 1:
        return windows[0]
    # Each window's luma is a matrix product: with BLAS's threads spinning between the 65 of
    # a large image they cost CPU and no time (plan/blas.py).
    with one_blas_thread():
        scores = [_edge_pixels(read_original(rows, cols)) for rows, cols in windows]
    return windows[int(np.argmax(scores))]


def array_window(original):
    """:func:`analysis_window` of an image held in memory: its rows and columns (two slices)."""
    return analysis_window(lambda rows, cols: original[rows, cols], *original.shape[:2])


def array_sample(original, filtered):
    """:func:`analysis_sample` of a pair held in memory."""
    window = array_window(original)
    return original[window], filtered[window]
