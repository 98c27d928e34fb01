"""Do ORIGINAL and FILTERED look swapped? The one with the antialiased edges is the original.

A user who gives the pair in the wrong order gets a run that exits 0 and a result close to
O. Filters that destroy antialiasing leave hard edges: no edge pixel of a thresholded image is
a blend of its neighbours. So the pair looks reversed when the image given as *original*
has only hard edges and the one given as *filtered* has antialiased ones. Both are measured
on the analysis crop, in luma of sRGB-encoded values:

* an **edge pixel** has a 3 x 3 neighbourhood whose luma spans at least 0.25;
* it is a **blend** when its luma lies strictly inside that span (15 % to 85 % of the way);
* it is an **antialiased blend** when, besides, the 3 x 3 span is at least 80 % of the 5 x 5
  span: the whole transition fits in one pixel, as antialiasing makes it, where a blur's
  ramp spans several (an aliased drawing under a slight blur is not taken for an original).

Measured on the lab's scenes under the eleven filters, 8-bit, both antialiasing spaces, at
128 and 384 pixels wide: 286 pairs each way, 154 from the quick suite's scenes (text, shapes,
lines, astronaut), where the limits below were set, and 132 held out (chart, star, coffee,
chelsea). Correctly ordered originals have blend shares of 0.20 (chart) to 0.76 (a photo) and
one-pixel-blend shares of 0.19 to 0.40; thresholded images 0.000. No correctly ordered pair
was called reversed (0 of 154, 0 of 132 held out), and every reversed threshold pair was
(14 of 14, 12 of 12). Reversed pairs under the other filters keep blends in the image given as
original and are not called: posterize's 4 levels leave blends between levels, point-wise
curves keep every blend. On 55 aliased drawings (point-sampled, no antialiasing) under each
filter, in order, one was called reversed before the low-pass exception (the star, blurred:
its blur is only a pixel wide); ``fit_lowpass`` found F a low-pass of O there and on every
aliased drawing under blur (kernel residual 0.02-0.09), and on no reversed threshold pair
(0.23-1.7), so that case is exempt: 0 of 55 now. The check takes about 30 ms on the 512 x 512
crop (``recover`` runs it once per pair), the low-pass fit 0.1 s more when the shares fire.
"""

import functools
from dataclasses import dataclass

import numpy as np

from ..colour import linear_to_srgb, luma
from ..contract import layout_of, to_rgba_float
from .analysis import analysis_crop
from .lowpass import fit_lowpass

__all__ = ["OrderVerdict", "check_order"]

_EDGE_SPAN = 0.25
_BLEND_LOW, _BLEND_HIGH = 0.15, 0.85
_ONE_PIXEL_TRANSITION = 0.8
# Hard: at most this share of the original's edge pixels are blends (thresholded: 0.000;
# originals: 0.24 and up). Antialiased: at least this share of the filtered image's edge
# pixels are one-pixel blends (originals 0.20 and up). Fewer edge pixels than the minimum
# decide nothing.
_HARD_BLEND_SHARE = 0.02
_ANTIALIASED_SHARE = 0.10
_MIN_EDGE_PIXELS = 64


@dataclass(frozen=True)
class OrderVerdict:
    """Whether a pair looks given in the wrong order, and why.

    Attributes
    ----------
    looks_reversed : bool
    reason : str
        One line for the user: the warning when `looks_reversed`, else what was measured.
    original_blend_share, filtered_antialiased_share : float
        The shares the decision compares (NaN where an image has too few edges).
    """

    looks_reversed: bool
    reason: str
    original_blend_share: float
    filtered_antialiased_share: float


def _encoded_colour(image, linear):
    crop = analysis_crop(image)
    rgba = to_rgba_float(crop, layout_of(crop, "image"), "image")
    return linear_to_srgb(rgba[..., :3]) if linear else rgba[..., :3]


def _window_range(values, radius):
    """Minimum and maximum over each pixel's (2 radius + 1)^2 window (edge-padded), separably."""
    padded = np.pad(values, radius, mode="edge")
    height, width = values.shape
    extremes = []
    for reduce in (np.minimum, np.maximum):
        rows = functools.reduce(reduce, [padded[dy:dy + height] for dy in range(2 * radius + 1)])
        extremes.append(functools.reduce(reduce, [rows[:, dx:dx + width] for dx in range(2 * radius + 1)]))
    return extremes


def _edge_shares(luma):
    """``(edge pixels, share that are blends, share that are one-pixel blends)``."""
    low, high = _window_range(luma, 1)
    span = high - low
    edges = span >= _EDGE_SPAN
    count = int(edges.sum())
    if count < _MIN_EDGE_PIXELS:
        return count, float("nan"), float("nan")
    position = (luma - low) / np.maximum(span, 1e-6)
    blends = edges & (position > _BLEND_LOW) & (position < _BLEND_HIGH)
    low5, high5 = _window_range(luma, 2)
    one_pixel = blends & (span >= _ONE_PIXEL_TRANSITION * (high5 - low5))
    return count, float(blends.sum()) / count, float(one_pixel.sum()) / count


def check_order(original, filtered, *, linear=False):
    """Tell whether `original` and `filtered` look swapped (the cheap check ``recover`` warns from).

    Parameters
    ----------
    original, filtered : ndarray
        The pair as given, any layout and dtype of the image contract; only a central crop
        of at most 512 x 512 pixels is read.
    linear : bool
        The images hold linear-light values.

    Returns
    -------
    OrderVerdict
    """
    o_colour, f_colour = _encoded_colour(original, linear), _encoded_colour(filtered, linear)
    o_edges, o_blends, _ = _edge_shares(luma(o_colour))
    f_edges, _, f_antialiased = _edge_shares(luma(f_colour))
    reason = (f"order as given: blends are {o_blends:.0%} of the original's edge pixels, one-pixel blends "
              f"{f_antialiased:.0%} of the filtered image's")
    reversed_ = o_blends <= _HARD_BLEND_SHARE and f_antialiased >= _ANTIALIASED_SHARE  # False with NaN
    if reversed_ and o_colour.shape == f_colour.shape and fit_lowpass(o_colour, f_colour)[0]:
        # An aliased drawing under a slight blur: F is a low-pass of O, so the order is right.
        reversed_, reason = False, "order as given: the filtered image is a low-pass (blur) of the original"
    if reversed_:
        reason = (f"the images look swapped: the one given as original has only hard edges ({o_blends:.0%} of "
                  f"its {o_edges} edge pixels are blends) and the one given as filtered has antialiased edges "
                  f"({f_antialiased:.0%} are one-pixel blends); give the image from before the filter first "
                  "(aarecovery recover ORIGINAL FILTERED)")
    return OrderVerdict(bool(reversed_), reason, o_blends, f_antialiased)
