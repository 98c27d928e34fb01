"""Neighbourhood filters that keep flat colours: the pure colours of thin features without a table.

Sharpening, the bilateral filter and other edge-aware smoothing leave a large flat area of
one colour as it is; what they damage is the antialiased edge, and most of all a thin
feature (a 1-2 px line, a serif), whose blended pixels they push towards the ink or the
paper as if they were a colour of their own. The paper's model blends the recovered colours
at the two extreme pixels of the 3x3 neighbourhood, but a thin feature has no pure ink
pixel: its extreme is itself a blend, and the model keeps F's damage there. For a
point-wise filter the pure colours of thin features are extended to the colour cube and
filtered by the fitted table (``aarecovery.spec.pure_colours``); for a filter that keeps
flat colours the same extension holds with the identity as the table, since what the
filter does to the ink seen as a flat area is nothing. F at the thin feature itself is
not asked to agree with that table: it differs by the damage the passes repair.

Measured on the real-tools suite, drawings with PNG originals, neighbourhood filters on
hard-edged content (the paper's passes at full strength before): tuning half mean
edge-band error reduction 0.455 -> 0.673 (GEGL's unsharp mask 0.544 -> 0.781, G'MIC's
bilateral 0.343 -> 0.476, ImageMagick's unsharp 0.478 -> 0.763); held-out half G'MIC's
unsharp 0.433 -> 0.831. Extending only to a flat colour of O beyond the extreme (not to
the cube) gave 0.464: the ink of thin lines is rarely seen flat.

The identity is the filter's table only where the filter keeps colours: it must keep O's
flat areas (:func:`flat_kept_share`) and leave each edge pixel on O's colour line there
(:func:`colour_line_miss`), which a hue change or a colour-to-grey conversion does not,
even where it keeps the greys of the image.
"""

import numpy as np

from ..colour import largest_channel
from ..spec.pure_colours import PureColourPrior
from .paper_grain import paper_pixels
from .pure_colours import inks_of, palette_of

__all__ = ["flat_kept_share", "paper_kept_share", "colour_line_miss", "flat_colour_prior", "FLAT_KEPT_SHARE",
           "PAPER_KEPT_SHARE", "LINE_MISS"]

# A pixel is deep in a flat area when O within this many pixels of it (a square) lies within
# 1/255 of its colour: beyond the reach of a 3x3 antialiased edge and of most of the halo of
# a small sharpening radius.
_FLAT_RADIUS = 2
_FLAT_TOLERANCE = 1.0 / 255
# F keeps a flat pixel's colour when it lies within this of O's in every channel (encoded).
_KEPT_TOLERANCE = 3.0 / 255
# Fewer deep flat pixels than this decide nothing.
_MIN_FLAT_PIXELS = 64
# Where fewer than _MIN_FLAT_PIXELS lie that deep, the pixels whose 3 x 3 square is flat
# decide (a small image, text over a photo: the 96 px poster of the tuning half has 19 deep
# flat pixels and 459 at this radius). Near an edge a sharpening halo reaches them, so an
# unsharp mask keeps few (the poster: 0.04-0.08) where the smoothing filters keep 0.87-1.00
# and a hue change or colour to grey none. Tuning half, the drawings, scans, photos and mixed
# scenes under the five neighbourhood filters, GEGL's hue-chroma and G'MIC's luminance (280
# cases, PNG and JPEG): three cases moved, the poster under the bilateral filters and OpenCV's
# smoothing, its text and graphics 0.186-0.279 -> 0.247-0.436 of their edge error, its photo
# regions within 0.001.
_SMALL_FLAT_RADIUS = 1
#: F keeps flat colours when it keeps this share of O's deep flat pixels. Real-tools suite,
#: drawings: unsharp masks and bilateral filters keep 0.43-1.00 (the rest are halos reaching
#: past two pixels: GEGL's unsharp mask on the serif text keeps least); hue changes and
#: colour to grey 0.00-0.94 (the icons' greys and white are kept).
FLAT_KEPT_SHARE = 0.3
# An edge pixel's colour line runs to its 3x3 neighbour farthest from it in colour, when
# that lies at least this far (encoded); nearer, the direction is noise.
_MIN_EDGE_CONTRAST = 8.0 / 255
#: F keeps a grained page's colours when it keeps the paper's local mean on this share of its
#: bare paper (:func:`paper_kept_share`). Tuning half, memo (grain 3.7 levels, PNG): the
#: unsharp masks 0.12-0.26 (their halos reach the paper beside the letters), the bilateral
#: filters and OpenCV's smoothing 0.95-1.00; point-wise filters, GEGL's hue-chroma among
#: them, 0.00.
PAPER_KEPT_SHARE = 0.1
# The share of edge pixels that lie within the miss limit below.
_LINE_QUANTILE = 75
#: F stays on O's colour lines when 3 of 4 edge pixels lie within this of the line through O
#: at that pixel (encoded, Euclidean). Real-tools suite, drawings: unsharp masks and
#: bilateral filters 0.8-35/255 (GEGL's unsharp on the icons, whose clipped halos leave
#: the line most); hue changes, channel mixers and colour to grey 15-160/255, and 57-160 on
#: the images where they keep flat colours (pies, icons).
LINE_MISS = 45.0 / 255


def _deep_flat(original, r=_FLAT_RADIUS):
    """Pixels of O whose whole (2r+1)^2 square lies within the flat tolerance of their colour."""
    height, width = original.shape[:2]
    padded = np.pad(original, ((r, r), (r, r), (0, 0)), mode="edge")
    flat = np.ones((height, width), bool)
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            flat &= largest_channel(np.abs(padded[r + dy:r + dy + height, r + dx:r + dx + width] - original)) \
                <= _FLAT_TOLERANCE
    return flat


def flat_kept_share(original, filtered):
    """Share of O's deep flat pixels whose colour F keeps.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour.

    Returns
    -------
    float
        In [0, 1]; 0 when O has fewer than 64 flat pixels, deep ones or, where there are
        fewer of those, ones whose 3 x 3 square is flat.
    """
    flat = _deep_flat(original)
    if flat.sum() < _MIN_FLAT_PIXELS:
        flat = _deep_flat(original, _SMALL_FLAT_RADIUS)
    if flat.sum() < _MIN_FLAT_PIXELS:
        return 0.0
    kept = largest_channel(np.abs(filtered[flat] - original[flat])) <= _KEPT_TOLERANCE
    return float(kept.mean())


def paper_kept_share(original, filtered, grain):
    """Share of O's bare paper (its quietest pixels, :func:`paper_grain.paper_pixels`) where
    F keeps the paper's colour on average: the 5 x 5 means of F and O there within the kept
    tolerance in every channel.

    A page with paper grain has no flat pixel to keep; a filter that keeps its colours
    (sharpening, edge-aware smoothing) moves the grain but not the paper's local mean, which
    a hue change or a conversion to grey does.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour.
    grain : PaperGrain

    Returns
    -------
    float
        In [0, 1]; 0 when O has fewer than 64 such pixels (no grain: an O with flat areas).
    """
    paper = paper_pixels(original, grain)
    if paper.sum() < _MIN_FLAT_PIXELS:
        return 0.0
    return float((largest_channel(np.abs(_box_mean(filtered) - _box_mean(original))[paper]) <= _KEPT_TOLERANCE).mean())


def _box_mean(image):
    """The mean of each pixel's (2r+1)^2 square, r = _FLAT_RADIUS (borders replicated).

    Not ``hatching``'s summed-area mean, which leaves the image's outside out: the shares
    :data:`PAPER_KEPT_SHARE` was chosen on are these, and near the window's border they
    differ (held out, measured after the choice: two of the letter's cases under unsharp
    masks fell below it with the other border).
    """
    height, width = image.shape[:2]
    r = _FLAT_RADIUS
    padded = np.pad(image, ((r, r), (r, r), (0, 0)), mode="edge")
    total = np.zeros_like(image)
    for dy in range(2 * r + 1):
        for dx in range(2 * r + 1):
            total += padded[dy:dy + height, dx:dx + width]
    return total / np.float32((2 * r + 1) ** 2)


def colour_line_miss(original, filtered, edges):
    """How far F leaves O's colour lines at edge pixels (the 75th percentile).

    At an edge pixel p, O's colour line runs from O[p] to its 3x3 neighbour farthest from it
    in colour; a filter that sharpens or smooths moves F[p] along that line (overshoot,
    a thin feature darkened), a hue change or a conversion to grey moves it off.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour.
    edges : ndarray of bool, shape (H, W)

    Returns
    -------
    float
        Encoded distance; inf where no edge pixel has a neighbour 8/255 away.
    """
    height, width = original.shape[:2]
    padded = np.pad(original, ((1, 1), (1, 1), (0, 0)), mode="edge")
    farthest = np.zeros_like(original)
    spread = np.zeros((height, width), original.dtype)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            offset = padded[1 + dy:1 + dy + height, 1 + dx:1 + dx + width] - original
            distance = (offset * offset).sum(-1)
            further = distance > spread
            farthest[further] = offset[further]
            spread[further] = distance[further]
    used = edges & (spread >= np.float32(_MIN_EDGE_CONTRAST ** 2))
    if not used.any():
        return float("inf")
    direction = farthest[used] / np.sqrt(spread[used])[:, None]
    change = filtered[used] - original[used]
    off_line = change - (change * direction).sum(-1)[:, None] * direction
    return float(np.percentile(np.sqrt((off_line * off_line).sum(-1)), _LINE_QUANTILE))


def flat_colour_prior(original, filtered, edges, grain=None, sharpened=False):
    """The pure-colour prior of a neighbourhood filter that keeps colours, or None.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour (the analysis crop).
    edges : ndarray of bool, shape (H, W)
        O's edge pixels.
    grain : PaperGrain, optional
        O's paper grain (``plan.paper_grain``): on a page with grain and no flat pixel, F
        keeps colours where it keeps the paper's local mean (:func:`paper_kept_share`).
    sharpened : bool, optional
        F sharpens drawn regions over a photo (``plan.smoothing.contrast_ratio`` at least
        ``SMOOTHED_CONTRAST``): the share of flat colours kept is not asked, the colour-line
        miss alone decides.

    Returns
    -------
    prior : PureColourPrior or None
        The identity table by channel, O's palette, extension to the colour cube, and no
        test of the table against F at the extreme; None unless F keeps
        :data:`FLAT_KEPT_SHARE` of O's deep flat pixels (unless `sharpened`) and stays
        within :data:`LINE_MISS` of O's colour lines.
    reason : str
        What was measured, for the plan's reason.
    """
    share, what, needed = flat_kept_share(original, filtered), "flat colours", FLAT_KEPT_SHARE
    # A scanned page's grain leaves no flat pixel: its paper's mean is what F keeps. Tuning
    # half, memo and notice under the five tuning neighbourhood filters and serif's JPEGs
    # under the unsharp masks (where the compression reads as grain): 24 cases up, none down
    # (memo PNG 0.25-0.80 -> 0.68-0.91, notice under GEGL's mask 0.29 -> 0.81-0.87).
    if share < FLAT_KEPT_SHARE and grain is not None and grain.span > 0:
        share, what, needed = paper_kept_share(original, filtered, grain), "the paper's mean", PAPER_KEPT_SHARE
    miss = colour_line_miss(original, filtered, edges)
    reason = f"{what} kept on {share:.2f}, colour-line miss {miss * 255:.0f}/255"
    # A sharpening filter keeps colours by nature, but its halos reach past two pixels and
    # cover the few flat pixels of text drawn over a photo: the tuning half's poster under the
    # two unsharp masks keeps 0.04-0.09 of them (colour-line miss 11-19/255), the screenshot,
    # whose title and status bars are wider, 0.51-0.66. A hue change or a conversion to grey,
    # which the share guards against, reads as no sharpening (edge contrast 0.97-1.01 times
    # O's there, the masks 1.71-2.04) and misses O's lines by 87-137/255 on the poster. Not
    # asking the share there: tuning half, 4 of 1056 cases moved, all up (the poster under
    # ImageMagick's mask in sRGB values 0.155 -> 0.442, its text and graphics 0.161 ->
    # 0.478; under GEGL's 0.154 -> 0.286; in linear light +0.03 and +0.04), photo regions
    # unchanged; mixed text and graphics 0.579 -> 0.585.
    if (share < needed and not sharpened) or not miss <= LINE_MISS:
        return None, reason
    centres = (np.arange(256, dtype=np.float32) + np.float32(0.5)) / np.float32(256)
    identity = np.repeat(centres[:, None], 3, axis=1)
    return PureColourPrior("channel", identity, palette_of(original), to_cube=True, explain_filtered=False,
                           inks=inks_of(original)), reason
