"""Is O a photograph (texture and grain everywhere) or hard-edged content (flat regions and edges)?

Two measures, each where it works:

* **Colour lines** (``blend_space.colour_line_residual``): the edge pixels of hard-edged
  colour content lie on straight colour lines between two colours (mean normalised
  residual 0.000-0.005 on the synthetic scenes, 0.002-0.024 on the real-tools drawings),
  photos' do not (0.018-0.053). Grey images have no colour to leave the line: their
  residual is always 0.
* **Grain**: pixels away from every edge (nothing steeper than a Sobel / 8 of 0.03 within
  4 pixels) are flat or smooth gradients in rendered content and carry sensor noise and fine
  texture in photos. A quiet pixel is grainy when its 3 x 3 neighbourhood spans 2 levels or
  more and so does its high-pass (O minus its 3 x 3 mean, which a linear gradient leaves at
  zero but for rounding) by more than one level. Measured on the real-tools crops and the
  built-in scenes: every PNG drawing 0.00-0.01 of quiet pixels grainy, every photo
  0.28-1.00 (a 96-pixel photo crop 0.07); JPEG adds its own noise there (drawings
  0.15-0.98), so a JPEG drawing reads as a photo: it gets the photo treatment, which is
  never worse than F, not the hard-edged one. The range alone, used before, called a drawing
  on a soft gradient a photo (0.23 grey, 0.73 in colour: the GIMP tests' scene); the
  high-pass alone called the serif page's flat paper 0.06 grainy.

Content is hard-edged when both say so (the colour test only where O has colour).

Where O is a JPEG (``aarecovery.plan.compression``), the grain is read in the edge-free
blocks of its grid instead (``quiet_block_grain``): compression noise stays in the blocks
that hold an edge, so that a JPEG drawing is flat there and a photo is not.
"""

import numpy as np

from ..colour import largest_channel
from ..spec.local_plan import neighbourhood_extremes
from ..spec.sobel import gradient_magnitude
from .compression import BLOCK_GRAIN_SHARE, quiet_block_grain

__all__ = ["grain", "is_grey", "is_textured", "STRICT_RESIDUAL", "GRAIN_SHARE", "NEAR_GREY"]

#: Channels within this everywhere: a grey (or faintly tinted) image, whose colour lines
#: cannot tell the antialiasing space nor a photo from a drawing; the manga pages' cream paper
#: differs by 3 levels, and by 5 once saved as JPEG at q 95-98 (the chroma's rounding); the
#: next least coloured family, a scanned letter, by 22.
NEAR_GREY = 8.0 / 255

#: Mean normalised colour-line residual of O's edge pixels above which O is a photo, where
#: grain cannot be measured (every pixel is near an edge): the built-in line scene has
#: 0.0014-0.0017, a JPEG star field (Hubble, q 85) 0.010-0.018.
STRICT_RESIDUAL = 0.008
#: Share of grainy quiet pixels (away from edges) above which O is a photo.
GRAIN_SHARE = 0.05
_QUIET_GRADIENT = 0.03
_QUIET_DISTANCE = 4
_GRAIN_RANGE = 1.5 / 255
_GRAIN_HIGH_PASS = 1.0 / 255
# Fewer quiet pixels than this leave the grain undecided (dense drawings have none).
_MIN_QUIET = 64


def _spread(mask, radius):
    height, width = mask.shape
    padded = np.pad(mask, radius)
    out = np.zeros_like(mask)
    for dy in range(2 * radius + 1):
        for dx in range(2 * radius + 1):
            out |= padded[dy:dy + height, dx:dx + width]
    return out


def _neighbourhood_mean(image):
    """The mean of each pixel's 3 x 3 neighbourhood (borders replicated), its nine values
    added in the order NumPy's mean of the nine stacked views adds them: the same values
    without the (9, H, W, 3) copy (the grain 0.07 -> 0.055 s on a 512 x 512 window, with
    the running extremes)."""
    height, width = image.shape[:2]
    padded = np.pad(image, ((1, 1), (1, 1), (0, 0)), mode="edge")
    total = padded[:height, :width].copy()
    for dy in range(3):
        for dx in range(3):
            if dy or dx:
                np.add(total, padded[dy:dy + height, dx:dx + width], out=total)
    return total / 9


def grain(encoded):
    """Share of pixels away from every edge whose 3 x 3 neighbourhood is neither flat nor a
    smooth gradient.

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's encoded colour (the analysis crop).

    Returns
    -------
    float or None
        None when fewer than 64 pixels are away from edges.
    """
    quiet = ~_spread(gradient_magnitude(encoded) > _QUIET_GRADIENT, _QUIET_DISTANCE)
    if quiet.sum() < _MIN_QUIET:
        return None
    brightest, darkest = neighbourhood_extremes(encoded)
    spread = largest_channel(brightest - darkest)
    brightest, darkest = neighbourhood_extremes(encoded - _neighbourhood_mean(encoded))
    high_pass_spread = largest_channel(brightest - darkest)
    grainy = (spread > _GRAIN_RANGE) & (high_pass_spread > _GRAIN_HIGH_PASS)
    return float(grainy[quiet].mean())


def is_grey(encoded):
    """True when every pixel's channels are equal to within :data:`NEAR_GREY`.

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
    """
    # Channel by channel (colour.largest_channel; the smallest as minus the largest of minus
    # it, the same values): 15 ms -> 1 ms on a 512 x 512 window.
    return bool((largest_channel(encoded) + largest_channel(-encoded)).max() <= NEAR_GREY)


def is_textured(encoded, colour_line_residual, compression=None):
    """Whether O is a photo by either measure.

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
    colour_line_residual : float or None
        ``blend_space.colour_line_residual`` in the chosen space (None: too few edges).
    compression : CompressionEvidence, optional
        O's compression (``aarecovery.plan.compression``); None or uncompressed: the pixels'
        grain decides.

    Returns
    -------
    textured : bool
    why : str
        The measure that decided, for the plan's reason.
    """
    if compression is not None and compression.compressed:
        blocks = quiet_block_grain(encoded, compression)
        if blocks is not None:
            return blocks > BLOCK_GRAIN_SHARE, f"grain in {blocks:.2f} of the JPEG's edge-free blocks"
    measured = grain(encoded)
    if measured is not None:
        return measured > GRAIN_SHARE, f"grain {measured:.2f} away from edges"
    # Nothing is far from an edge (dense line art, a star field): the colour lines alone
    # decide, and more strictly, since no grain can confirm them. A grey image leaves no
    # colour line (its residual is 0): nothing decides, and it is read as a photo, whose
    # treatment is never worse than F. A grey photo 64 pixels wide (the built-in astronaut in
    # grey) read as hard-edged and lost 32.8 of its edge error under a gamma curve, 1.2 under
    # an unsharp mask, at full strength; no image of the suites, tuning or held out, is grey
    # without quiet pixels.
    # The cost, on the built-in scenes in grey at 48-64 pixels: dense lines under a threshold
    # 0.75-0.76 -> 0.54-0.55 of their edge error, under gamma 0.24-0.25 -> 0.20-0.21, the
    # chart 0.70 -> 0.69 and 0.50 -> 0.42; none worse than F.
    if colour_line_residual is None or is_grey(encoded):
        return True, "no colour to test"
    if colour_line_residual > STRICT_RESIDUAL:
        return True, f"colour-line residual {colour_line_residual:.3f}"
    return False, ""
