"""Hatching and screentone: texture that a neighbourhood filter must not see as edges to blend.

Hatching (parallel thin strokes a few pixels apart) and screentone (a grid of dots) alternate
between two colours every few pixels. To the paper's model every stroke is an antialiased
edge, but an edge-aware filter (a bilateral filter, OpenCV's edge-preserving smoothing)
averages across the strokes, and the reference (the scene filtered at a higher resolution)
keeps more of them than F does: the model's blend of O's extreme colours there moves R away
from both. Measured on the tuning half's screentone manga taken through the hard-edged
branch at full strength: OpenCV's bilateral filter lost 0.61 dB against F (linear light).

The evidence is how densely O's luma alternates: a pixel is a **stroke extremum** when it is
brighter or darker than both of its neighbours along a row or a column by
:data:`_EXTREMUM_CONTRAST`; hatching and screentone put one every two or three pixels, a
drawing's lines one per line. Where a share :data:`HATCHED_SHARE` of O's edge pixels lie in
squares dense with extrema, O is hatched, and it is used twice:

* Where F smooths a hatched O (``aarecovery.plan.smoothing``), the plan repairs its flat regions at full strength
  and its hatched ones at :data:`HATCHED_STRENGTH`: the local plan of
  ``aarecovery.spec.local_plan`` (with its GL twin), whose textured regions are where O has
  no flat pixels, as the hatched and dotted regions have none. A sharpening filter keeps
  the strokes and is repaired at full strength everywhere.
* A comic's screentone leaves few quiet pixels without dots, so that the texture test
  (``texture``) reads it as a photo's grain: a neighbourhood filter kept F there, and a
  point-wise one got the calibrated strength of a photo. A hatched O with flat paper
  (:func:`is_screentone_drawing`) is a drawing instead, under both kinds of filter: photos
  have almost no flat pixels and are hatched on few edges.

Tuning half, drawings 96 pixels wide (the 11 x 11 square, extrema 16/255 apart): the shares
are 0.16-0.33 on serif text and maps, 0.50-0.58 on the star burst's converging rays and
0.70-0.80 on the screentone manga; photos and mixed scenes 0.00-0.19. At 64 pixels the maps
and the star burst's rays are as dense as hatching (0.69-0.76).
"""

import numpy as np

from ..colour import LUMA_WEIGHTS
from ..spec.local_plan import flat_pixels

__all__ = ["hatched_share", "is_screentone_drawing", "HATCHED_SHARE", "DENSE_EXTREMA", "SCREENTONE_FLAT_SHARE",
           "HATCHED_STRENGTH"]

# A stroke extremum differs from both neighbours along a row or a column by more than this
# (encoded luma): an antialiased stroke's core against the paper, not 8-bit noise or JPEG ringing.
_EXTREMUM_CONTRAST = 16.0 / 255
# The square around an edge pixel in which extrema are counted: 11 x 11 pixels, a few periods
# of hatching at the suite's scales.
_DENSITY_RADIUS = 5
#: A square is dense with strokes when this share of its pixels are stroke extrema (hatching
#: two or three pixels apart puts 0.3-0.5 there, a lone line's square about 0.1-0.2).
DENSE_EXTREMA = 0.3
#: O is hatched when this share of its edge pixels lie in dense squares (tuning half: 0.58 at
#: most on drawings without screentone, 0.70 at least on the screentone manga).
HATCHED_SHARE = 0.65
#: The strength in the hatched regions of a smoothed O (flat regions get full strength).
#: Tuning half, the screentone manga under the bilateral and edge-preserving filters (6 cases,
#: mean edge-band error reduction): 0.254 at 1 (OpenCV's bilateral lost 0.61 dB), 0.140 at 0,
#: 0.419 at 0.25, 0.509 at 0.4, 0.537 at 0.5, 0.539 at 0.6, 0.488 at 0.75; none worse than F
#: from 0 to 0.75. The filter averaged the strokes part of the way that the model blends them.
HATCHED_STRENGTH = 0.5
#: A hatched O whose grain reads as a photo's (screentone dots leave few quiet pixels without
#: them) is a drawing when at least this share of its pixels are flat (``spec.local_plan``:
#: a 3 x 3 neighbourhood of one 8-bit colour, not black). Tuning half: the screentone manga
#: 0.15 (0.04-0.05 from a JPEG), photos and mixed scenes 0.00-0.02 (a screenshot's chrome 0.08,
#: but hatched on at most 0.16 of its edges, photos on at most 0.19).
SCREENTONE_FLAT_SHARE = 0.03


def _stroke_extrema(encoded):
    luma = encoded @ LUMA_WEIGHTS.astype(np.float32)
    padded = np.pad(luma, 1, mode="edge")
    left, right = padded[1:-1, :-2], padded[1:-1, 2:]
    up, down = padded[:-2, 1:-1], padded[2:, 1:-1]
    c = np.float32(_EXTREMUM_CONTRAST)

    def peak(a, b):
        return ((luma - a > c) & (luma - b > c)) | ((a - luma > c) & (b - luma > c))

    return peak(left, right) | peak(up, down)


def _box_mean(mask, radius):
    """Mean of `mask` over the square of `radius` around each pixel (the outside not counted)."""
    def box_sum(values):
        padded = np.pad(values.astype(np.float64), ((radius + 1, radius), (radius + 1, radius)))
        table = padded.cumsum(axis=0).cumsum(axis=1)
        side = 2 * radius + 1
        height, width = values.shape
        return (table[side:side + height, side:side + width] - table[:height, side:side + width]
                - table[side:side + height, :width] + table[:height, :width])
    return box_sum(mask) / box_sum(np.ones(mask.shape, bool))


def is_screentone_drawing(encoded, edges):
    """Whether a textured-looking O is a hatched drawing (screentone, hatching), not a photo:
    :data:`HATCHED_SHARE` of its edge pixels are hatched and :data:`SCREENTONE_FLAT_SHARE`
    of its pixels are flat.

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's sRGB-encoded colour (the analysis crop).
    edges : ndarray of bool, shape (H, W)

    Returns
    -------
    bool
    """
    return bool(hatched_share(encoded, edges) >= HATCHED_SHARE
                and flat_pixels(encoded).mean() >= SCREENTONE_FLAT_SHARE)


def hatched_share(encoded, edges):
    """Share of O's edge pixels that lie in squares dense with stroke extrema.

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's sRGB-encoded colour (the analysis crop).
    edges : ndarray of bool, shape (H, W)
        O's edge pixels.

    Returns
    -------
    float
        In [0, 1]; 0 without edge pixels.
    """
    if not edges.any():
        return 0.0
    density = _box_mean(_stroke_extrema(encoded), _DENSITY_RADIUS)
    return float((density[edges] > DENSE_EXTREMA).mean())
