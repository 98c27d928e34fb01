"""The local plan: how strongly to repair each region of O, from how much of it is flat.

One image can hold both kinds of content: text, logos and lines drawn over a photo. For a
point-wise filter the safe default repairs hard-edged content at full strength and photos at
the strength self-calibration finds (``aarecovery.plan.calibration``); the local plan
decides that per region. Its evidence is **flatness**: rendered content (text, drawings,
user-interface chrome) is made of areas of one exact colour, so most 3 x 3 neighbourhoods
around its edges are flat to the 8-bit level; a photo's sensor noise and texture leave
almost none. Measured on mixed scenes (``aarecovery.lab.mixed_probe``, tuning half): the
edge pixels of the drawn graphics had a median flat share of 0.04-0.10 in the 17 x 17 square
around them (a tenth of them 0.35-0.39), the photos' edge pixels 0.00-0.02 (99th percentile
0.07-0.24). A JPEG source has no exactly flat pixels: it reads as a photo everywhere, as the
whole-image decision reads it.

Per pixel, in passes that read only :data:`REACH` pixels around it, so that a tile with that
much more halo gives the untiled result (the GL twin, ``backends/gl/shaders/local_plan.glsl``,
runs the same passes on each tile: 1, 2 and the sums of 3 along rows, then along columns):

1. :func:`flat_pixels`: where O's 3 x 3 neighbourhood spans at most half an 8-bit level
   in every channel and is not black.
2. :func:`flat_share`: the share of flat pixels in the square of radius
   :data:`REGION_RADIUS` (the image's outside counts as not there).
3. :func:`hard_edged_weight`: 0 below a share of :data:`TEXTURED_SHARE`, 1 above
   :data:`HARD_EDGED_SHARE`, a smoothstep between: box sums change by at most one pixel's
   worth from one pixel to the next, so the weight has no step and R no seam where the
   decision changes.
4. :meth:`LocalStrength.factor`: the factor of the confidence ``beta``, from the textured
   strength (photo regions) to 1 (hard-edged regions).

Thresholds chosen on the tuning half of the mixed scenes (shares 0.05-0.25, 0.1-0.3 and
0.15-0.35, radii 6, 8 and 16: graphics 0.596-0.609, photo 0.360-0.367 of the edge error
removed, against 0.479 and 0.367 for one strength per image).
"""

from dataclasses import dataclass

import numpy as np

from ..colour import linear_to_srgb

__all__ = ["LocalStrength", "encoded_colour", "strength_map", "flat_pixels", "flat_share", "hard_edged_weight", "REACH", "REGION_RADIUS",
           "TEXTURED_SHARE", "HARD_EDGED_SHARE"]

#: A pixel is flat when its 3 x 3 neighbourhood spans at most this in every channel: equal
#: 8-bit values (the 8-bit grid is 1/255 apart).
FLAT_SPAN = 0.5 / 255
#: Radius of the square whose flat share decides a region: 17 x 17 pixels.
REGION_RADIUS = 8
#: Flat shares at and below which a region is textured, and at and above which it is
#: hard-edged.
TEXTURED_SHARE = 0.1
HARD_EDGED_SHARE = 0.3
#: How far the factor at a pixel reads O: the square and the 3 x 3 flatness test.
REACH = REGION_RADIUS + 1


def flat_pixels(encoded):
    """bool ``(H, W)``: O's 3 x 3 neighbourhood spans at most :data:`FLAT_SPAN` in every
    channel, and is not black.

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's sRGB-encoded colour (borders replicated, as every pass does).
    """
    height, width = encoded.shape[:2]
    padded = np.pad(encoded, ((1, 1), (1, 1), (0, 0)), mode="edge")
    window = [padded[dy:dy + height, dx:dx + width] for dy in range(3) for dx in range(3)]
    brightest = np.max(window, axis=0)
    flat = (brightest - np.min(window, axis=0)).max(axis=-1) <= np.float32(FLAT_SPAN)
    # Black is where a camera clips its shadows (a night sky, space): as often a photo's as
    # a drawing's ink, it is no evidence (held-out astronaut under a gamma curve: its photo
    # region went from 0.37 to -0.07 when it counted).
    return flat & (brightest.max(axis=-1) > np.float32(FLAT_SPAN))


def _box_sum(mask, radius):
    """Sum of `mask` over the square of `radius` around each pixel, the image's outside 0.

    Counts are whole numbers: the sums are exact, so a tile gives the whole image's.
    """
    padded = np.pad(mask.astype(np.float64), ((radius + 1, radius), (radius + 1, radius)))
    table = padded.cumsum(axis=0).cumsum(axis=1)
    side = 2 * radius + 1
    height, width = mask.shape
    return (table[side:side + height, side:side + width] - table[:height, side:side + width]
            - table[side:side + height, :width] + table[:height, :width])


def flat_share(encoded, radius=REGION_RADIUS):
    """float32 ``(H, W)``: the share of flat pixels in the square of `radius` around each pixel."""
    inside = _box_sum(np.ones(encoded.shape[:2], bool), radius)
    return (_box_sum(flat_pixels(encoded), radius) / inside).astype(np.float32)


def hard_edged_weight(share):
    """1 where a region's flat share is a drawing's, 0 where it is a photo's, smooth between."""
    t = np.clip((share - np.float32(TEXTURED_SHARE)) / np.float32(HARD_EDGED_SHARE - TEXTURED_SHARE), 0, 1)
    return (t * t * (3 - 2 * t)).astype(np.float32)


@dataclass(frozen=True)
class LocalStrength:
    """The local plan of a point-wise filter: the confidence's factor per pixel.

    Attributes
    ----------
    textured : float
        The factor in textured regions: the calibrated strength for a photo, in (0, 1); a
        fixed strength for hatching and screentone under a smoothing filter (``aarecovery.plan.hatching``).
    textured_regions : str
        What the textured regions are, for the summary line.
    """

    textured: float
    textured_regions: str = "photo"

    #: How far the factor at a pixel reads O (a tile's extra halo).
    reach = REACH

    def factor(self, encoded):
        """float32 ``(H, W)``: from :attr:`textured` (photo) to 1 (hard-edged), per pixel of O.

        Parameters
        ----------
        encoded : ndarray of float32, shape (H, W, 3)
            O's sRGB-encoded colour.
        """
        weight = hard_edged_weight(flat_share(encoded))
        return (np.float32(self.textured) + np.float32(1 - self.textured) * weight).astype(np.float32)


def encoded_colour(rgba, linear_input):
    """O's sRGB-encoded colour ``(H, W, 3)``, which the local plan reads, from contract RGBA."""
    return linear_to_srgb(rgba[..., :3]) if linear_input else rgba[..., :3]


def strength_map(plan, factor, shape):
    """The map of the strength that multiplied the confidence: `plan`'s strength times the
    local plan's `factor` (None: the one strength), float32 of `shape`."""
    if factor is None:
        return np.full(shape, plan.strength, np.float32)
    return (np.float32(plan.strength) * factor).astype(np.float32)
