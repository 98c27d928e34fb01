"""A scanned page's paper grain: how far it varies, and whether it is coarse.

A scanned page has no exactly flat pixel: its paper carries a grain a few pixels across,
which O's Sobel reads as edges (a coarse grain is steeper than
``calibration.EDGE_GRADIENT``), while too many pixels lie near an edge for
``texture.grain`` to be measured, so the colour lines call the page hard-edged. The pure
colours of thin features then take two grain pixels for a thin stroke and its paper and
paint the filter's extrapolated ink between them, and under equalization, narrow levels and
posterization the table stretches the grain into the repair: full strength with pure colours
lost up to 7.2 dB against F on such pages.

The quietest pixels tell the grain: a drawing's flat fills span nothing (the 5th percentile
of the 3 x 3 luma span is 0 on every real-tools drawing and comic), a page's bare paper spans
its grain (3.7 levels on the light-grained memo, 8.9 on the coarse-grained notice and
letter), and the largest span of bare paper is about 4.5 times that (memo 16.6, the coarse
pages 38-39 levels). So:

* extremes closer than :data:`GRAIN_SPAN_FACTOR` times the quiet span are grain, not a thin
  feature on its paper (text's contrast, 150-200 levels, stays far above);
* a quiet span over :data:`COARSE_GRAIN_SPAN` is a coarse grain, which goes through the
  filter like a JPEG's noise: the strength is calibrated, as for a compressed O, and the
  passes run at :data:`GRAIN_EDGE_SCALE` times the edge-strength scale ``sigma_e``. The
  confidence is ``1 - exp(-(e / sigma_e)^2)`` with ``e`` the product of O's and F's
  gradients: the grain's ``e`` is about 0.01 (O's gradient 0.03-0.05 times what the filter
  makes of it), text's 0.1-0.3, so a larger scale leaves the bare paper as F has it (the
  haze a repair paints there) and the letters repaired; where the filter leaves the letters
  weak edges too (a solarize), the scale stops at their edge strength
  (:func:`grain_edge_scale`);
* a sharpening filter on a coarse grain sharpens the grain too: full strength at the
  grain's ``sigma_e``, blended in linear light (:data:`SHARPENED_GRAIN_BLEND_SPACE`), or in
  sRGB values where the filter keeps the paper's mean and the strokes take their pure
  colours (:data:`SHARPENED_GRAIN_PURE_BLEND_SPACE`; :func:`paper_pixels` is the paper
  that ``plan.flat_colours.paper_kept_share`` reads).
"""

from dataclasses import dataclass

import numpy as np

from ..colour import LUMA
from ..spec import to_working_space
from ..spec.blend_model import edge_strength

__all__ = ["PaperGrain", "paper_grain", "paper_pixels", "grain_edge_scale", "GRAIN_SPAN_FACTOR", "COARSE_GRAIN_SPAN",
           "FILTERED_GRAIN_SPAN", "GRAIN_EDGE_SCALE", "GRAIN_EDGE_SHARE", "SHARPENED_GRAIN_BLEND_SPACE",
           "SHARPENED_GRAIN_PURE_BLEND_SPACE", "MAX_GRAIN_SPAN", "GRAINED_NEIGHBOURHOOD_STRENGTH"]

#: The pure colours' contrast floor, in multiples of the quiet pixels' 3 x 3 luma span.
#: Tuning half, scans under levels, equalization, posterize and thresholds (memo and notice,
#: PNG and JPEG): 5 -> notice worst loss 2.83 dB, 8 -> 1.98, 12 -> 1.56, memo 0.779-0.788.
GRAIN_SPAN_FACTOR = 8.0
#: A quiet span above this (encoded) is a coarse grain: memo 3.7 levels, notice 8.9.
COARSE_GRAIN_SPAN = 6.0 / 255
#: F's span at O's quiet pixels above this is a coarse grain too: the filter made it one.
#: Tuning half, memo (light grain, 3.7 levels) PNG, the median of F's 3 x 3 luma span at
#: O's quiet pixels: 0-21 levels under every point-wise filter that its full-strength repair
#: gains on (G'MIC's equalize 20-21, gain 0.66-0.72), 61-62 under Pillow's YCbCr equalization
#: (lost 0.72-1.85 dB at full strength).
FILTERED_GRAIN_SPAN = 36.0 / 255
#: ``sigma_e`` is multiplied by this on a coarse grain (at most: :func:`grain_edge_scale`).
GRAIN_EDGE_SCALE = 10.0
#: ... but the grain's ``sigma_e`` is no larger than this times the edge strength of O's
#: strongest edges (the 90th percentile of ``e`` over O's edge pixels), under a point-wise
#: filter: a curve that brings the paper toward the ink (a solarize inverts it) leaves the
#: letters an ``e`` of 0.04-0.07, and at 10 times the user's sigma_e (0.1) their repair fell
#: to a tenth of its confidence (notice under Pillow's solarize 0.04 -> 0.38 of its edge
#: error at the user's sigma_e). Tuning half, memo and notice under the 15 tuning point-wise
#: filters where the grain's scale applied (74 cases, PNG and JPEG), mean error reduction /
#: paper pixels darker than F: no cap 0.494 / 159, 2: 0.495 / 159, 1: 0.507 / 190, 0.5:
#: 0.538 / 874 (posterize and equalization then paint the paper).
GRAIN_EDGE_SHARE = 1.0
#: The strength under a smoothing filter on a coarse grain (at the grain's ``sigma_e``, no
#: pure colours; ``aarecovery.plan.analysis``). Tuning half, notice under the five tuning
#: neighbourhood filters, PNG and JPEG: full strength at the user's sigma_e 11 cases worse
#: than F by over 0.1 dB (worst 1.51 dB); at the grain's sigma_e 1: 2 (0.33 dB), 0.75: 0
#: (worst 0.09 dB), 0.5: 0 (worst 0.00 dB); unsharp masks keep full strength (at 0.5 their
#: gain on notice fell from 0.45-0.52 to 0.21-0.23).
GRAINED_NEIGHBOURHOOD_STRENGTH = 0.5
#: Under a sharpening filter (an unsharp mask) a coarse grain's page is blended in this
#: space, at the grain's ``sigma_e`` and full strength. The mask sharpens the grain, and
#: the reference keeps it sharpened: at the user's sigma_e the repair took it back beside
#: the letters (haze). The grain also keeps the letters' thin strokes from their pure
#: colours, and without them the strokes' partial colours blend better in linear light, as
#: the paper's method does (serif and the star burst under the tuning unsharp masks without
#: pure colours: sRGB 0.32-0.41, linear 0.50-0.57). Tuning half, memo and notice under the
#: two tuning unsharp masks (PNG and JPEG, the 11 cases on a coarse grain of 15), mean error
#: reduction of the 15 / paper pixels darker than F: the chosen space at the user's sigma_e
#: 0.345 / 1408 px, at 3 times it 0.332 / 206; linear light at 3, 5 and 10 times 0.496 /
#: 1116, 0.474 / 461, 0.429 / 146 (the paper's method 0.518 / 3946).
SHARPENED_GRAIN_BLEND_SPACE = "linear"
#: ... but where the filter keeps the paper's mean and the strokes get their pure colours
#: (``plan.flat_colours.paper_kept_share``), the reason for linear light is gone, and the
#: grain, sharpened in the encoded values, is blended there: tuning half, the 11 cases of
#: memo and notice (PNG and JPEG) under the two tuning unsharp masks that take the prior,
#: mean edge error reduction / paper pixels darker than F: linear light 0.669 / 10978,
#: sRGB values 0.693 / 5862 (memo at q 85 0.777 -> 0.845; the linear-light notice PNG 0.01
#: lower).
SHARPENED_GRAIN_PURE_BLEND_SPACE = "srgb"
#: A quiet span above this is no paper grain but content with no flat pixel: the built-in
#: suite's dense lines span 67 (linear) and 115 (sRGB) levels there, and with their quiet
#: span as a grain lost their pure colours (quick suite 0.792 -> 0.693 linear).
MAX_GRAIN_SPAN = 24.0 / 255
# The quiet pixels are this percentile of the 3 x 3 luma span: below every drawing's share
# of flat pixels (0.08 on the densest, the Ben-Day comic) and within a page's bare paper.
_QUIET_PERCENTILE = 5.0


@dataclass(frozen=True)
class PaperGrain:
    """O's quietest 3 x 3 luma span (encoded): 0 where O has flat areas, or none that is grain;
    and F's span at those quiet pixels (their median; 0 when F was not given)."""

    span: float
    filtered_span: float = 0.0

    @property
    def contrast(self):
        """float: the contrast two extremes need to be told from the grain (encoded)."""
        return GRAIN_SPAN_FACTOR * self.span

    @property
    def coarse(self):
        """bool: the grain goes through the filter like compression noise (or the filter made
        it coarse)."""
        return self.span > COARSE_GRAIN_SPAN or (self.span > 0 and self.filtered_span > FILTERED_GRAIN_SPAN)

    @property
    def edge_scale(self):
        """float: what ``sigma_e`` is multiplied by (1 unless the grain is coarse)."""
        return GRAIN_EDGE_SCALE if self.coarse else 1.0

    def describe(self):
        """The grain in words, for the plan's reason."""
        return f"paper grain ({self.span * 255:.1f} levels)"


def _luma_span(encoded):
    luma = encoded @ np.asarray(LUMA, np.float32)
    height, width = luma.shape
    padded = np.pad(luma, 1, mode="edge")
    shifted = [padded[dy:dy + height, dx:dx + width] for dy in range(3) for dx in range(3)]
    return np.max(shifted, axis=0) - np.min(shifted, axis=0)


def paper_grain(encoded, filtered=None):
    """Measure O's paper grain from its quietest pixels, and what a point-wise filter made of it.

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's encoded colour (the analysis crop).
    filtered : ndarray of float32, shape (H, W, 3), optional
        F's encoded colour, for :attr:`PaperGrain.filtered_span`.

    Returns
    -------
    PaperGrain
    """
    span = _luma_span(encoded)
    quiet = float(np.percentile(span, _QUIET_PERCENTILE))
    if quiet > MAX_GRAIN_SPAN:
        return PaperGrain(0.0)
    filtered_span = 0.0 if filtered is None else float(np.median(_luma_span(filtered)[span <= quiet]))
    return PaperGrain(quiet, filtered_span)


def paper_pixels(encoded, grain):
    """bool ``(H, W)``: O's quiet pixels, the bare paper, whose 3 x 3 luma span is at most the
    grain's (:attr:`PaperGrain.span`; none where it is 0)."""
    if grain.span <= 0:
        return np.zeros(encoded.shape[:2], bool)
    return _luma_span(encoded) <= np.float32(grain.span)


def grain_edge_scale(grain, encoded, filtered, edges, blend_space, sigma_e):
    """What ``sigma_e`` is multiplied by under a point-wise filter on this grain.

    The grain's scale (:attr:`PaperGrain.edge_scale`), capped so that the grain's sigma_e
    stays within :data:`GRAIN_EDGE_SHARE` of the edge strength of O's strongest edges, and
    never below 1.

    Parameters
    ----------
    grain : PaperGrain
    encoded, filtered : ndarray of float32, shape (H, W, 3)
        O's and F's encoded colour (the analysis window).
    edges : ndarray of bool, shape (H, W)
        O's edge pixels.
    blend_space : {"linear", "srgb"}
    sigma_e : float
        The user's.

    Returns
    -------
    float
    """
    scale = grain.edge_scale
    if scale == 1.0 or not edges.any():
        return scale
    opaque = np.ones(encoded.shape[:2] + (1,), np.float32)
    strength = edge_strength(to_working_space(np.concatenate([encoded, opaque], -1), blend_space=blend_space),
                             to_working_space(np.concatenate([filtered, opaque], -1), blend_space=blend_space))
    strongest = float(np.percentile(strength[edges], 90))
    return float(min(scale, max(1.0, GRAIN_EDGE_SHARE * strongest / sigma_e)))
