"""Smoothing filters (bilateral, edge-preserving): they average part of an edge's damage away.

A filter that sharpens (an unsharp mask, detail enhancement) raises the contrast of O's edges;
one that smooths lowers it, and what it does to an antialiased edge is partly what the
reference (the scene filtered at a higher resolution) does too: the model's full blend of
O's extreme colours overshoots it, and a lower strength comes closer. Measured on the tuning
half's drawings without hatching (serif text, maps, icons, the star burst) under G'MIC's and
OpenCV's bilateral filters and OpenCV's edge-preserving smoothing (24 cases, mean edge-band
error reduction): 0.518 at full strength, 0.577 at 0.6, 0.596 at 0.7, 0.597 at 0.75, 0.594
at 0.8, 0.568 at 0.9; every case gains at least 0.77 dB over F from 0.7 to 0.8.

A smoothing filter also leaves some edge pixels as O had them while it moves their
neighbours by a few levels, and there F is nearer the reference (the scene filtered at a
higher resolution) than the model's blend of F's moved extremes: the repair made F's error
there 1.1-1.9 times larger. So the confidence falls to 0 where F's pixel is O's
(:data:`UNTOUCHED_SPAN`, a per-pixel reading of F in the model's pass: the spec's
``fit_blend_model`` and its GLSL twin). Measured, the gain is all on such pixels: asking
instead that F left the whole 3 x 3 neighbourhood as it was gained nothing (0.586 -> 0.585).
A colour replacement, which the contrast test also reads as smoothing, leaves the blend
between a swapped colour and the paper as O had it too, but that is its damage: it moves the
extremes by much more (``spec.blend_model.UNTOUCHED_EXTREMES``), and is repaired as before.
"""

import numpy as np

from ..colour import LUMA_WEIGHTS

__all__ = ["contrast_ratio", "SMOOTHED_CONTRAST", "SMOOTHED_STRENGTH", "UNTOUCHED_SPAN"]

#: F smooths (rather than sharpens) when its Laplacian at O's edges is below this multiple of
#: O's. Only smoothing averages the strokes away: under an unsharp mask the screentone manga
#: (tuning half) gained 0.60-0.74 of its edge error at full strength everywhere and 0.10-0.13
#: with F kept in its hatched regions. Tuning half, drawings: bilateral and edge-preserving
#: filters 0.78-1.00, unsharp masks 1.42-2.37.
SMOOTHED_CONTRAST = 1.2
#: The strength for a smoothing filter on hard-edged content (see the module's measurements).
SMOOTHED_STRENGTH = 0.75
#: Under a smoothing filter, an edge pixel that F moved from O by less than this (the largest
#: channel's change, in the working space) gets less confidence, by a smoothstep from 0 at no
#: change to 1 at this change: the filter left it as O had it, and so does the reference
#: (where F also moved the pixel's extremes by at most ``spec.blend_model.UNTOUCHED_EXTREMES``).
#: Tuning half, PNG drawings under G'MIC's and OpenCV's bilateral filters and OpenCV's
#: edge-preserving smoothing (30 cases, mean edge-band error reduction, without that bound,
#: which takes the 0.604 below to 0.600): 0.586 without,
#: 0.594 at 2/255, 0.601 at 4/255, 0.604 at 6/255, 0.603 at 8/255; the largest gains on the
#: star burst (0.28 -> 0.33, 0.60 -> 0.68) and the maps under OpenCV's bilateral (0.35 ->
#: 0.39), the largest loss manga in sRGB under it (0.538 -> 0.521). Why, binned by F's change
#: of encoded luma (the 24 cases without hatching, each bin's best strength of 0-1): the
#: pixels changed by less than 2.3/255 hold 3 % of F's edge-band error, and a repair at 0.75
#: made it 1.1-1.9 times larger there (best 0.25); those changed by more than 5.4/255 hold
#: 86 % and want 0.75. Under unsharp masks (20 cases) the same factor moved the mean by
#: -0.0007: F moves nearly every edge pixel there, so it is not applied. Whole tuning half
#: (with the bound): 61 cases moved, 8 down by at most 0.017, none worse than F; neighbourhood
#: filters on PNG drawings 0.651 -> 0.659.
UNTOUCHED_SPAN = 6.0 / 255


def _laplacian(encoded):
    luma = encoded @ LUMA_WEIGHTS.astype(np.float32)
    padded = np.pad(luma, 1, mode="edge")
    return np.abs(4 * luma - padded[:-2, 1:-1] - padded[2:, 1:-1] - padded[1:-1, :-2] - padded[1:-1, 2:])


def contrast_ratio(original, filtered, edges):
    """F's mean absolute Laplacian (of luma) at O's edge pixels over O's: below 1 F smooths.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour (the analysis crop).
    edges : ndarray of bool, shape (H, W)

    Returns
    -------
    float
        1 without edge pixels or where O's Laplacian is 0 there.
    """
    contrast = _laplacian(original)[edges].sum() if edges.any() else 0.0
    if contrast <= 0:
        return 1.0
    return float(_laplacian(filtered)[edges].sum() / contrast)
