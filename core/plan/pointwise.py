"""Is F a point-wise function of O, ``F = f(O)``? Fitted from the pair as a lookup table.

Most damaging filters act on each pixel alone (threshold, levels and curves, posterize,
gradient maps, tone mapping, histogram equalization); ``f`` can be fitted by bin means and
scored on O's edge pixels. When it explains F, the safe plan knows the filter and can
restore thin features' pure colours (``plan.pure_colours``) or calibrate the strength
(``plan.calibration``).
"""

import numpy as np

from ..colour import LUMA, largest_channel, luma, srgb_to_linear
from ..spec.pure_colours import (LUMINANCE_KEYS, SCALE_KEYS, SHIFT_KEYS, key_values, rec601_grey, scale_transfer,
                                 shift_grey)

__all__ = ["PointwiseTransfer", "fit_pointwise", "filled_bins", "key_of", "POINTWISE_SHARE", "TABLE_KEYS"]

# Point-wise fit: bins of the table, tolerance of a match and the share of edge pixels that
# must match. Point-wise filters of the suite score >= 0.99; neighbourhood filters <= 0.8.
_LUT_BINS = 256
_LUT_TOLERANCE = 3.0 / 255
POINTWISE_SHARE = 0.97


#: The keys a table can be indexed by, besides the scale keys: each channel, luma, mean, max
#: (HSV value), the encoded luminance of linear light (Rec. 709 and babl's D50 weights) and
#: Rec. 601 luma, the grey of OpenCV (``cv2.applyColorMap`` on a colour image, its gradient
#: maps), Pillow's ``convert("L")`` and ImageMagick's ``Rec601Luma``.
TABLE_KEYS = ("channel", "luma", "mean", "max") + tuple(LUMINANCE_KEYS) + ("luma601",)
# Rec. 601 luma (colour.REC601_LUMA): a TURBO-like gradient map of a colour photo's Rec. 601
# grey matched 0.62 of the edge pixels by Rec. 709 luma, so the safe plan called it a
# neighbourhood filter and kept F.
# Luma shifts (spec.pure_colours.SHIFT_KEYS), F = clip(O + s(Y)) with the same offset on
# every channel: a curve of the Y of JPEG's YCbCr with the chroma kept (equalizing the luma,
# the usual recipe for a colour image: OpenCV's equalizeHist on YCrCb's Y, Pillow's equalize
# on convert("YCbCr")'s), since R, G and B are Y plus functions of the chroma. OpenCV rounds
# that Y, Pillow's YCbCr truncates it (Pillow's convert("L") rounds): a bin straddling the two
# gets two offsets far apart under a steep equalization curve. Tuning half, Pillow's YCbCr
# equalization was a neighbourhood filter to every other key (maps 0.91-0.92 of the edges
# matched by luma): photos kept F and the mixed scenes were repaired in their drawn regions
# only; keyed by the luma shift, 1.000 (maps), 0.991-1.000 (photos).


def key_of(colour, key):
    """The values of `key` for encoded colour ``(..., 3)``: shape (..., 3) for "channel", else (...)."""
    if key == "channel":
        return colour
    if key == "luma":
        return luma(colour)
    if key == "mean":
        return colour.mean(axis=-1)
    if key == "max":
        return largest_channel(colour)
    if key == "luma601":
        # The 8-bit grey those tools index their map by, at its bin's centre (as the pure
        # colours read the table, spec.pure_colours.rec601_grey): binned raw, a bin straddled
        # two grey levels and a steep map missed (0.965 of the edges matched).
        grey = rec601_grey(np.moveaxis(colour, -1, 0))
        return ((grey + np.float32(0.5)) / np.float32(_LUT_BINS)).astype(np.float32)
    planes = np.ascontiguousarray(colour.reshape(-1, 3).T, dtype=np.float32)
    return key_values(planes, key)[0].reshape(colour.shape[:-1])


def _bins(key):
    return np.clip((key * _LUT_BINS).astype(np.intp), 0, _LUT_BINS - 1)


class PointwiseTransfer:
    """A fitted point-wise transfer ``F = f(O)`` as a lookup table.

    Attributes
    ----------
    key : str
        What the table is indexed by (:data:`TABLE_KEYS`, a scale key or a shift key): each
        channel of O on its own, or one value per pixel.
    table : ndarray of float32, shape (256, 3)
        Output colour per bin (for ``"channel"``, column c maps channel c; for a shift key
        ``spec.pure_colours.SHIFT_KEYS``, the offset added to O's channels before clipping).
    consistency : float
        Share of O's edge pixels where ``f(O)`` matches F within 3/255.
    """

    def __init__(self, key, table, consistency):
        self.key, self.table, self.consistency = key, table, consistency

    def __call__(self, colour):
        """Apply to encoded colour ``(..., 3)``."""
        if self.key in SCALE_KEYS:
            planes = np.ascontiguousarray(colour.reshape(-1, 3).T, dtype=np.float32)
            return scale_transfer(planes, self.key, self.table).T.reshape(colour.shape)
        if self.key in SHIFT_KEYS:
            index = _bins(_grey601(colour, self.key))
            return np.clip(colour + self.table[index], 0, 1)
        values = key_of(colour, self.key)
        index = _bins(values)
        if self.key == "channel":
            return np.stack([self.table[index[..., c], c] for c in range(3)], axis=-1)
        return self.table[index]


def fit_pointwise(original, filtered, edges):
    """Fit ``F = f(O)`` by bin means and score it on edge pixels.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour.
    edges : ndarray of bool, shape (H, W)
        Where to score the fit.

    Returns
    -------
    PointwiseTransfer
        The key with the best consistency (the first of equal ones); its ``alternatives``
        attribute lists every key's transfer, best first.
    """
    best = None
    fitted = []
    # Tables are fitted on every pixel but scored on the edge pixels only: scoring a dozen
    # candidate tables on the whole crop took half of the analysis (measured).
    scored = edges if edges.any() else np.ones(edges.shape, bool)
    scored_o, scored_f = original[scored], filtered[scored]

    def consistency(transfer):
        miss = largest_channel(np.abs(transfer(scored_o) - scored_f))
        # Ties (two colours fit any key) go to the key that reproduces F more closely.
        transfer.mean_miss = float(miss.mean())
        return float((miss <= _LUT_TOLERANCE).mean())

    # F's channels as the weights bincount converts them to, once for every key.
    weights = [filtered[..., c].ravel().astype(np.float64) for c in range(3)]
    for key in TABLE_KEYS:
        values = key_of(original, key)
        index = _bins(values)
        table = np.empty((_LUT_BINS, 3), np.float32)
        shared_counts = None if key == "channel" else np.bincount(index.ravel(), minlength=_LUT_BINS)
        for c in range(3):
            bins = index[..., c] if key == "channel" else index
            sums = np.bincount(bins.ravel(), weights[c], minlength=_LUT_BINS)
            counts = np.bincount(bins.ravel(), minlength=_LUT_BINS) if shared_counts is None else shared_counts
            filled = counts > 0
            centres = np.arange(_LUT_BINS)
            table[:, c] = np.interp(centres, centres[filled], sums[filled] / counts[filled]) if filled.any() else 0
        transfer = PointwiseTransfer(key, table, 0.0)
        transfer.consistency = consistency(transfer)
        fitted.append(transfer)
        if best is None or _better(transfer, best):
            best = transfer
    for key in SHIFT_KEYS:
        transfer = PointwiseTransfer(key, _shift_table(original, filtered, key), 0.0)
        transfer.consistency = consistency(transfer)
        fitted.append(transfer)
        if _better(transfer, best):
            best = transfer
    for key in SCALE_KEYS:
        chosen = None
        for table in _scale_tables(original, filtered, key):
            transfer = PointwiseTransfer(key, table, 0.0)
            transfer.consistency = consistency(transfer)
            if chosen is None or _better(transfer, chosen):
                chosen = transfer
        fitted.append(chosen)
        if _better(chosen, best):
            best = chosen
    best.alternatives = sorted(fitted, key=lambda t: (-t.consistency, t.mean_miss))
    return best


def _grey601(colour, key):
    """The 8-bit Rec. 601 grey of encoded colour ``(..., 3)`` that a shift key's tool indexes its
    curve by (``spec.pure_colours.shift_grey``), at its bin's centre: shape (...)."""
    planes = np.moveaxis(colour, -1, 0)
    return ((shift_grey(planes, key) + np.float32(0.5)) / np.float32(_LUT_BINS)).astype(np.float32)


def _shift_table(original, filtered, key):
    """A shift key's table: per grey bin, the mean of F - O over the channels F did not clip
    (a clipped channel's difference is not the offset: the shifts of one grey level spread
    over 40 levels on the maps); where F clipped every channel of a bin, the offset that
    clips them just (white paper that stays white: 0, not its neighbours' offset); the same
    offset in each column."""
    index = _bins(_grey601(original, key)).ravel()
    sums, counts = np.zeros(_LUT_BINS), np.zeros(_LUT_BINS)
    above = np.full(_LUT_BINS, -np.inf)  # the least offset that clips every high channel
    below = np.full(_LUT_BINS, np.inf)   # the greatest that clips every low one
    for c in range(3):
        channel = filtered[..., c].ravel()
        source = original[..., c].ravel().astype(np.float64)
        high, low = channel >= 1 - 0.5 / 255, channel <= 0.5 / 255
        inside = ~(high | low)
        shift = channel[inside].astype(np.float64) - source[inside]
        sums += np.bincount(index[inside], shift, minlength=_LUT_BINS)
        counts += np.bincount(index[inside], minlength=_LUT_BINS)
        np.maximum.at(above, index[high], 1 - source[high])
        np.minimum.at(below, index[low], -source[low])
    offsets = np.full(_LUT_BINS, np.nan)
    measured = counts > 0
    offsets[measured] = sums[measured] / counts[measured]
    only_high = ~measured & np.isfinite(above) & ~np.isfinite(below)
    only_low = ~measured & np.isfinite(below) & ~np.isfinite(above)
    offsets[only_high], offsets[only_low] = above[only_high], below[only_low]
    filled = np.isfinite(offsets)
    centres = np.arange(_LUT_BINS)
    column = (np.interp(centres, centres[filled], offsets[filled]) if filled.any()
              else np.zeros(_LUT_BINS))
    return np.repeat(column[:, None], 3, axis=1).astype(np.float32)


def _better(transfer, other):
    """More edge pixels matched, or as many matched more closely."""
    return (transfer.consistency, -transfer.mean_miss) > (other.consistency, -other.mean_miss)


def _scale_tables(original, filtered, key):
    """Candidate tables of a scale key (``aarecovery.spec.pure_colours.scale_transfer``): bin
    means of the mapped luma, estimated two ways.

    * F's own luma, from pixels F did not clip at 1 where a bin has any (right for curves
      with steps, such as histogram equalization of few colours);
    * each pixel's scale (F / O in its largest channel that F did not clip) times its luma,
      leaving out pixels clipped in every channel (right where the curve maps above 1, as
      tone mapping does near white);

    each placed at bin centres or at the bins' mean keys.

    The caller keeps the one that explains F best.
    """
    to_values = (lambda c: srgb_to_linear(c)) if key == "luminance_scale" else (lambda c: c)
    weights = np.array(LUMA, np.float64)
    source = to_values(original).reshape(-1, 3).astype(np.float64)
    result = to_values(filtered).reshape(-1, 3).astype(np.float64)
    source_luma = source @ weights
    index = np.clip((source_luma * _LUT_BINS).astype(np.intp), 0, _LUT_BINS - 1)
    centres = np.arange(_LUT_BINS)

    def tables(values, use):
        # The bins' counts and sums once for both placements (they took 2 x 12 ms per key).
        used = index[use]
        counts = np.bincount(used, minlength=_LUT_BINS)
        sums = np.bincount(used, values[use], minlength=_LUT_BINS)
        filled = counts > 0
        means = sums[filled] / counts[filled]
        # Each bin's mean at its bin's centre, or at its pixels' mean key (a bin holding
        # black and a few dark blends is not centred).
        for where in (centres[filled], (np.bincount(used, source_luma[use], minlength=_LUT_BINS)[filled]
                                        / counts[filled] * _LUT_BINS - 0.5)):
            column = np.interp(centres, where, means) if filled.any() else np.zeros(_LUT_BINS)
            yield np.repeat(column[:, None], 3, axis=1).astype(np.float32)

    own = result @ weights
    unclipped = largest_channel(result) < 1 - 1 / 512
    has_unclipped = np.bincount(index[unclipped], minlength=_LUT_BINS) > 0
    first = unclipped | ~has_unclipped[index]
    scaled, second = _scaled_luma(source, result, source_luma)
    return tuple(table for values, use in ((own, first), (scaled, second)) for table in tables(values, use))


def _scaled_luma(source, result, source_luma):
    """Each pixel's scale (F / O in its largest channel that F did not clip) times its luma,
    and which pixels have one, for :func:`_scale_tables`.

    Channel by channel, not by NumPy's reductions over the last axis (its slowest): the first
    channel of largest usable source, as ``argmax`` picks it, and the mean as ``mean`` sums
    it, bit for bit.

    Parameters
    ----------
    source, result : ndarray of float64, shape (N, 3)
        O's and F's values.
    source_luma : ndarray of float64, shape (N,)

    Returns
    -------
    scaled : ndarray of float64, shape (N,)
        The scaled luma; F's mean where O is black.
    usable : ndarray of bool, shape (N,)
        Pixels with a channel F did not clip, or black in O.
    """
    usable = (result < 1 - 1 / 512) & (source > 1e-4)
    candidates = np.where(usable, source, -1)
    largest = largest_channel(candidates)
    first_is, second_is = candidates[:, 0] == largest, candidates[:, 1] == largest
    picked_source, picked_result = (np.where(first_is, values[:, 0], np.where(second_is, values[:, 1], values[:, 2]))
                                    for values in (source, result))
    ratio = picked_result / np.maximum(picked_source, 1e-4)
    mean_result = (result[:, 0] + result[:, 1] + result[:, 2]) / 3
    scaled = np.where(source_luma > 1e-6, ratio * source_luma, mean_result)
    return scaled, usable[:, 0] | usable[:, 1] | usable[:, 2] | (source_luma <= 1e-6)


def filled_bins(original, key):
    """Which of a table's bins O's pixels fill, per column: ndarray of bool, shape (256, 3)."""
    keys = key_values(np.ascontiguousarray(original.reshape(-1, 3).T, dtype=np.float32), key)
    filled = np.zeros((_LUT_BINS, 3), bool)
    for c in range(3):
        filled[:, c] = np.bincount(_bins(keys[c]), minlength=_LUT_BINS) > 0
    return filled
