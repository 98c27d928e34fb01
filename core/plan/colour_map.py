"""Is F a point-wise function of O's whole colour, ``F = f(O)`` with ``f: RGB -> RGB``?

The tables of ``plan.pointwise`` are indexed by one value per pixel or per channel. Some
point-wise filters need all three channels at once: a palette quantiser (G'MIC's
``-quantize``: every colour goes to the nearest of a few palette colours), a hue or
saturation change (``gegl:hue-chroma``, ImageMagick's ``-modulate``), a channel mixer.
Here ``f`` is fitted as a coarse 3-D lookup table of bin means and scored on O's edge
pixels leaving each pixel out of its own bin, so that a bin holding one pixel (every bin
fits its own pixel) proves nothing. Neighbourhood filters, whose output at one colour
depends on the pixel's surroundings, score far lower (measured below).

The table serves self-calibration on textured images and JPEG drawings
(``plan.calibration``), which applies ``f`` to colours O does not hold (blends at half
resolution); empty bins take the mean of their filled neighbours, grown outwards. Where F is
indexed colour it also gives the pure colours of thin features their filtered colour
(:func:`indexed_colour_prior`). On
hard-edged content its share alone tells a colour map from a neighbourhood filter
(:data:`HARD_EDGED_COLOUR_MAP_SHARE`).
"""

import numpy as np

from ..colour import largest_channel
from ..spec.pure_colours import COLOUR_KEY, PureColourPrior, colour_map_at
from .pure_colours import inks_of, palette_of

__all__ = ["ColourMapTransfer", "fit_colour_map", "indexed_colour_prior", "indexed_colour_fallback", "COLOUR_MAP_SHARE",
           "HARD_EDGED_COLOUR_MAP_SHARE", "INDEXED_COLOURS", "INDEXED_SHARE"]

# Bins per channel: 8/255 wide, not swept. Finer bins hold fewer pixels each to leave one out
# of (a 512 x 512 crop has 8 pixels per bin of 32^3 on average); coarser ones straddle more
# of a quantiser's boundaries.
_BINS = 32
_MATCH = 3.0 / 255
#: Share of O's edge pixels (left out of their own bin) that the 3-D table must match within
#: 3/255, chosen on the real-tools suite's tuning half: point-wise colour maps there (GEGL's
#: hue-chroma on PNG drawings) score 0.917-0.975, neighbourhood filters (unsharp mask,
#: bilateral) at most 0.712, JPEG sources under hue-chroma 0.66-0.70.
COLOUR_MAP_SHARE = 0.85
#: The same share on hard-edged content, where a filter the point-wise tables do not explain
#: is otherwise taken for a neighbourhood filter: a palette quantiser scores 0.91-0.99 there
#: (tuning half, Pillow's median-cut quantize to 6 colours on PNG drawings and scans: the maps
#: 0.922-0.950, icons 0.976-0.987, the star burst 0.909-0.917; the sRGB notice page 0.859, which
#: a one-key table explains first), GEGL's hue-chroma 0.917-0.990, but a bilateral filter on
#: flat-coloured drawings reaches 0.875 (OpenCV's, the icons), and the other neighbourhood
#: filters (unsharp masks, G'MIC's bilateral, OpenCV's smoothing) at most 0.806.
HARD_EDGED_COLOUR_MAP_SHARE = 0.9


#: F is indexed colour (a palette quantiser's output: GIF, PNG-8, GIMP's Image > Mode > Indexed)
#: where it shows at most this many 8-bit colours in the window...
INDEXED_COLOURS = 256
#: ... and at most this share of O's: tuning half, Pillow's median cut to 6 colours leaves 5-6
#: of the drawings' 64-1006 (JPEG twins 1771-6496), where GEGL's hue-chroma, also a colour map
#: on hard-edged content, keeps 0.88-1.00 of them.
INDEXED_SHARE = 0.25


class ColourMapTransfer:
    """A fitted colour map ``F = f(O)`` as a 32 x 32 x 32 lookup table of encoded colour.

    Attributes
    ----------
    key : str
        ``"colour"``: the whole colour indexes the table (``PointwiseTransfer.key`` names
        its single key the same way).
    table : ndarray of float32, shape (32, 32, 32, 3)
        Output colour per bin of (R, G, B).
    consistency : float
        Share of O's edge pixels that share their bin with another pixel and whose colour
        the others' mean matches within 3/255.
    """

    key = COLOUR_KEY

    def __init__(self, table, consistency):
        self.table, self.consistency = table, consistency

    def __call__(self, colour):
        """Apply to encoded colour ``(..., 3)``, interpolating trilinearly between bin centres."""
        return colour_map_at(self.table, colour)


def _bin_index(colour):
    return np.clip((colour * _BINS).astype(np.intp), 0, _BINS - 1)


def fit_colour_map(original, filtered, edges):
    """Fit ``F = f(O)`` as a 3-D table of bin means and score it on edge pixels, leaving each out.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour.
    edges : ndarray of bool, shape (H, W)
        Where to score the fit.

    Returns
    -------
    ColourMapTransfer
    """
    index = _bin_index(original)
    flat = ((index[..., 0] * _BINS + index[..., 1]) * _BINS + index[..., 2]).ravel()
    size = _BINS ** 3
    counts = np.bincount(flat, minlength=size).astype(np.float64)
    sums = np.stack([np.bincount(flat, filtered[..., c].ravel().astype(np.float64), minlength=size)
                     for c in range(3)], axis=-1)
    scored = edges.ravel()
    own_bin, own_f = flat[scored], filtered.reshape(-1, 3)[scored].astype(np.float64)
    shared = counts[own_bin] > 1
    if shared.any():
        others = (sums[own_bin[shared]] - own_f[shared]) / (counts[own_bin[shared]] - 1)[:, None]
        consistency = float((largest_channel(np.abs(others - own_f[shared])) <= _MATCH).mean())
    else:
        consistency = 0.0
    filled = (counts > 0).reshape((_BINS,) * 3)
    table = np.zeros((_BINS,) * 3 + (3,))
    table[filled] = (sums / np.maximum(counts, 1)[:, None]).reshape((_BINS,) * 3 + (3,))[filled]
    return ColourMapTransfer(_fill_empty(table, filled).astype(np.float32), consistency)


def _fill_empty(table, filled):
    """Give each empty bin the mean of its filled face neighbours, ring by ring outwards."""
    if not filled.any():
        return table
    while not filled.all():
        total = np.zeros_like(table)
        weight = np.zeros(filled.shape)
        for axis in range(3):
            for step in (-1, 1):
                source = [slice(None)] * 3
                target = [slice(None)] * 3
                source[axis] = slice(0, -1) if step == 1 else slice(1, None)
                target[axis] = slice(1, None) if step == 1 else slice(0, -1)
                source, target = tuple(source), tuple(target)
                total[target] += table[source] * filled[source][..., None]
                weight[target] += filled[source]
        grown = ~filled & (weight > 0)
        table[grown] = total[grown] / weight[grown][:, None]
        filled = filled | grown
    return table


def _colour_count(encoded):
    levels = np.rint(np.clip(encoded, 0, 1) * 255).astype(np.uint32).reshape(-1, 3)
    return len(np.unique((levels[:, 0] << 16) | (levels[:, 1] << 8) | levels[:, 2]))


def _is_indexed(original, filtered):
    """Whether F shows a palette's few colours (:data:`INDEXED_COLOURS`, :data:`INDEXED_SHARE`)."""
    # Every 16th pixel first: a photo's F shows more colours than a palette's there already,
    # and is told in 2 ms, not the 50 ms of counting every pixel's (a 512 x 512 window).
    if _colour_count(filtered.reshape(-1, 3)[::16]) > INDEXED_COLOURS:
        return False
    shown = _colour_count(filtered)
    if shown > INDEXED_COLOURS:
        return False
    # O's colours the same way: the sample, where it already shows enough, settles it.
    needed = shown / INDEXED_SHARE
    return _colour_count(original.reshape(-1, 3)[::16]) >= needed or _colour_count(original) >= needed


def indexed_colour_prior(original, filtered, colour_map, noise_contrast=0.0, luma_purity=0.0):
    """The pure colours of thin features for a palette quantiser on hard-edged content, or None.

    A quantiser maps each whole colour to its nearest palette entry: point-wise, so a thin
    feature's pure colour, extended to the colour cube as for a table of one key
    (``aarecovery.spec.pure_colours``), takes the colour the fitted 3-D table gives it. Only
    where F is indexed colour (:data:`INDEXED_COLOURS`, :data:`INDEXED_SHARE`): a smooth
    colour map (a hue change) fills the table's bins far from O's colours with guesses, and
    the serif page under GEGL's hue-chroma fell 0.76-0.83 -> -0.22-0.08 of its edge error
    with them. F at the observed extreme is not asked to match the table: the bins average
    colours across the palette's boundaries (with the test, the sRGB map under Pillow's
    quantize kept 0.587 of its edge error, without 0.775).

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour of the analysis window.
    colour_map : ColourMapTransfer
    noise_contrast, luma_purity : float, optional
        A JPEG's compression noise as a contrast and its luma purity, as for a table of one
        key on a compressed O (``PureColourPrior.noise_contrast``, ``ridge_noise``,
        ``luma_purity``); 0: a lossless O.

    Returns
    -------
    PureColourPrior or None
    """
    if not _is_indexed(original, filtered):
        return None
    return PureColourPrior(COLOUR_KEY, colour_map.table, palette_of(original), explain_filtered=False,
                           inks=inks_of(original), noise_contrast=float(noise_contrast), ridge_noise=float(noise_contrast),
                           luma_purity=float(luma_purity))


def indexed_colour_fallback(original, filtered, edges, noise_contrast=0.0, luma_purity=0.0):
    """:func:`indexed_colour_prior` where no table of one key gave the pure colours: for F that
    such a table explains but no extension key reads (the channels' mean), if the 3-D table
    explains it as on hard-edged content (:data:`HARD_EDGED_COLOUR_MAP_SHARE`).

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour of the analysis window.
    edges : ndarray of bool, shape (H, W)
    noise_contrast, luma_purity : float, optional
        As for :func:`indexed_colour_prior`.

    Returns
    -------
    PureColourPrior or None
    """
    # The colour count first: it is the cheaper test, and fails on most pairs that get here.
    if not _is_indexed(original, filtered):
        return None
    colour_map = fit_colour_map(original, filtered, edges)
    if colour_map.consistency < HARD_EDGED_COLOUR_MAP_SHARE:
        return None
    return indexed_colour_prior(original, filtered, colour_map, noise_contrast, luma_purity)
