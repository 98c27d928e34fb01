"""The safe plan's pure-colour prior: the filter's table and O's flat colours.

For point-wise filters on hard-edged content the passes restore thin features' pure
colours (the rule and its measurements are in ``aarecovery.spec.pure_colours``). This
module builds what they need from the pair: a fitted table that is monotone, extended past
O's key range, and the palette of O's flat colours.
"""

import dataclasses

import numpy as np

from ..colour import largest_channel
from ..params import SIGMA_D, SIGMA_E
from ..spec import to_working_space
from ..spec.pure_colours import (EXTENSION_KEYS, INK_COUNT, INK_TOLERANCE, PALETTE_SIZE, PALETTE_TOLERANCE, SCALE_KEYS,
                                 SHIFT_KEYS, PureColourPrior, filtered_colour, fit_pure_colour_model)
from .pointwise import POINTWISE_SHARE, TABLE_KEYS, filled_bins, key_of

__all__ = ["palette_of", "inks_of", "is_monotone", "turns_at_most_once", "ONE_TURN_VARIATION", "extrapolate_table",
           "pure_colour_prior", "affine_in_key_miss", "clipped_share", "STRAIGHT_TABLE_MISS",
           "STRAIGHT_TABLE_CLIPPED", "COMPRESSED_LUMA_PURITY"]

# A flat pixel's 3x3 neighbourhood lies within this of its colour (encoded values), and a
# palette colour needs this many flat pixels.
_FLAT_TOLERANCE = 1.0 / 255
_PALETTE_MIN_COUNT = 4

#: On a JPEG-compressed O, an extreme whose luma lies within this of a flat colour's
#: (working space) is that colour (``PureColourPrior.luma_purity``): a JPEG keeps luma at full
#: resolution and quantises chroma coarsely, at half resolution with 4:2:0 sampling, so the
#: paper in a gap between two strokes keeps its luma and takes on the strokes' chroma; extended
#: as a thin feature it turned pink under a levels curve (the star burst at q 98: the tan
#: paper between its dark-blue spokes, luma 181 against the paper's 182, blue 163 against 132).
#: Tuning half, the JPEG twins under the 15 point-wise tools, with the flat-blocks reading
#: (``aarecovery.plan.analysis``): serif 0.309 -> 0.336 of the edge error, the star burst
#: 0.165 -> 0.209, no new loss; 0.01-0.03 compared in docs/safe-default.md.
COMPRESSED_LUMA_PURITY = 0.03

# A table counts as monotone when no output channel reverses by more than this (encoded).
_MONOTONE_TOLERANCE = 2.0 / 255
#: Where no fitted table is monotone, one whose every column's total variation is at most
#: this times its range (a single hump: 2) still gives the extension its colours
#: (:func:`turns_at_most_once`). Measured on the tables chosen when the monotone rule is
#: dropped: under OpenCV's JET on the tuning half's drawings 1.00-2.00 per column; on the
#: built-in suite's chart and text under colour to grey and colour replacement 2.42-18.3,
#: at least 3.33 in the column that varies most, where extending with them lost up to
#: 7.8 dB against F.
ONE_TURN_VARIATION = 2.5


def is_monotone(table):
    """Whether every output channel of a table is non-decreasing or non-increasing.

    Threshold, levels, posterize, equalization and gradient maps are monotone in their key.
    Colour to grey and hue swaps are not functions of luma or of each channel; on images of
    few colours a table can still match them (colour to grey on the resolution chart matched
    99 % of edges with the luma key), and there the table ranks hues by chance and is not
    monotone. Extending thin features with such a table lost up to 5 dB (chart, measured), so
    the extension needs a monotone table.

    Parameters
    ----------
    table : ndarray of float32, shape (256, 3)

    Returns
    -------
    bool
    """
    steps = np.diff(table.astype(np.float64), axis=0)
    rising = (steps >= -_MONOTONE_TOLERANCE).all(axis=0)
    falling = (steps <= _MONOTONE_TOLERANCE).all(axis=0)
    return bool(np.all(rising | falling))


def turns_at_most_once(table):
    """Whether every output channel of a table rises and falls (or falls and rises) at most once.

    A colour map of the grey value is a genuine table that is not monotone: OpenCV's JET and
    TURBO take green and blue up and down again, a hump in each column, whose total variation
    is twice its range. Tables that match colour to grey or a colour replacement by chance on
    an image of few colours rank those colours by luma and zigzag (see
    :data:`ONE_TURN_VARIATION`). `table` and the result as for :func:`is_monotone`.
    """
    values = table.astype(np.float64)
    variation = np.abs(np.diff(values, axis=0)).sum(axis=0)
    extent = values.max(axis=0) - values.min(axis=0)
    return bool(np.all(variation <= ONE_TURN_VARIATION * extent + _MONOTONE_TOLERANCE))


def palette_of(original):
    """The flat colours of an image, most frequent first.

    Parameters
    ----------
    original : ndarray of float32, shape (H, W, 3)
        Encoded colour.

    Returns
    -------
    ndarray of float32, shape (N, 3), N <= PALETTE_SIZE
        Colours (rounded to 8 bits) of pixels whose 3x3 neighbourhood lies within 1/255 of
        them, seen at least 4 times; then O's dark ink where no flat colour is within
        ``PALETTE_TOLERANCE`` of it (:data:`DARK_INK_REACH`).
    """
    levels = np.rint(np.clip(original[_flat(original)], 0, 1) * 255).astype(np.int64)
    palette = _most_frequent(levels, PALETTE_SIZE)
    ink = _dark_ink(original)
    if ink is None or (len(palette) and np.abs(palette - ink).max(axis=1).min() <= PALETTE_TOLERANCE):
        return palette
    return np.concatenate([palette[:PALETTE_SIZE - 1], ink[None]]).astype(np.float32)


#: A dark ink that leaves no flat pixel (a JPEG's noise scatters it by a few levels) is the
#: median of O's pixels within this of black in every channel (encoded), where at least
#: :data:`_DARK_INK_COUNT` are. The manga page's ink is (10, 10, 13): saved as a JPEG it left
#: no flat pixel, and its near-whole pixels were extended to black (CORNER_INKS), which a
#: curve steep at black (the built-in x ** 0.5) maps far from the ink's colour. Tuning half:
#: 32 up, 10 down (the manga in sRGB under OpenCV's JET at q 85 -0.033), no PNG case moved;
#: held out, run after the choice: 94 up, 11 down (the sRGB hatching under GEGL's bilateral
#: -0.041), drawings 0.710 -> 0.714 (the hatching under G'MIC's gamma at q 95 0.245 -> 0.761).
DARK_INK_REACH = 24.0 / 255
_DARK_INK_COUNT = 16


def _dark_ink(original):
    """The colour, float32 ``(3,)``, of :data:`DARK_INK_REACH`; None where too few pixels are that dark."""
    pixels = np.clip(original.reshape(-1, 3), 0, 1)
    dark = pixels[(pixels <= DARK_INK_REACH).all(axis=1)]
    if len(dark) < _DARK_INK_COUNT:
        return None
    return (np.rint(np.median(dark, axis=0) * 255) / 255).astype(np.float32)


def _most_frequent(levels, limit):
    """The 8-bit colours ``(N, 3)`` of `levels` seen at least :data:`_PALETTE_MIN_COUNT` times,
    the `limit` most frequent first, as float32 in [0, 1]."""
    if not len(levels):
        return np.zeros((0, 3), np.float32)
    codes = (levels[:, 0] * 256 + levels[:, 1]) * 256 + levels[:, 2]
    unique, counts = np.unique(codes, return_counts=True)
    order = np.argsort(-counts, kind="stable")[:limit]
    kept = unique[order][counts[order] >= _PALETTE_MIN_COUNT]
    return (np.stack([kept // 65536, kept // 256 % 256, kept % 256], -1) / np.float32(255)).astype(np.float32)


def inks_of(original):
    """The colours on the colour cube's faces that an image shows at several pixels, most
    frequent first (``PureColourPrior.inks``).

    Black, white and saturated inks are seen whole in strokes too thin to leave a flat pixel;
    their partial colours' extensions to the cube land on them. `original` as for
    :func:`palette_of`; the result too, with N <= ``INK_COUNT`` colours seen at least 4 times
    (flat or not) that have a channel within ``INK_TOLERANCE`` of 0 or 1, then black and white
    where O does not show them (:data:`CORNER_INKS`).
    """
    levels = np.rint(np.clip(original.reshape(-1, 3), 0, 1) * 255).astype(np.int32)
    reach = int(round(INK_TOLERANCE * 255))
    on_face = ((levels <= reach) | (levels >= 255 - reach)).any(axis=1)
    seen = _most_frequent(levels[on_face], INK_COUNT)
    unseen = [ink for ink in np.asarray(CORNER_INKS, np.float32) if not (seen == ink).all(axis=1).any()]
    if not unseen:
        return seen
    return np.concatenate([seen[:INK_COUNT - len(unseen)], np.stack(unseen)]).astype(np.float32)


#: Inks of every page, seen or not: black and white. A thin stroke of black ink whose whole
#: pixel O never shows (serif's smallest text; the manga's JPEG twins, whose noise leaves no
#: exact black) has near-whole pixels within MIN_REACH of the cube's corner, which kept F's
#: colour there.
CORNER_INKS = ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))


def _flat(original):
    """bool ``(H, W)``: every colour of the pixel's 3 x 3 neighbourhood (borders replicated)
    within :data:`_FLAT_TOLERANCE` of its own in every channel.

    By the neighbourhood's running extremes, not the 9 differences: rounding is monotone and
    symmetric, so the largest ``|n - c|`` is ``max(brightest - c, c - darkest)`` bit for bit
    (tests/test_exact_speedups.py); 36 -> 15 ms on a 512 x 512 window (measured).
    """
    height, width = original.shape[:2]
    padded = np.pad(original, ((1, 1), (1, 1), (0, 0)), mode="edge")
    brightest, darkest = original.copy(), original.copy()
    for dy in range(3):
        for dx in range(3):
            np.maximum(brightest, padded[dy:dy + height, dx:dx + width], out=brightest)
            np.minimum(darkest, padded[dy:dy + height, dx:dx + width], out=darkest)
    np.subtract(brightest, original, out=brightest)
    np.subtract(original, darkest, out=darkest)
    return largest_channel(np.maximum(brightest, darkest, out=brightest)) <= _FLAT_TOLERANCE


# Power-law extrapolation of a table end: the second point lies this far inside the range.
_EXTRAPOLATION_STEP = 0.05


def extrapolate_table(table, filled):
    """Extend a table beyond its filled bins by a power law through the end.

    Below the first filled bin ``x0``: ``f(x) = f(x0) (x / x0)^p``, with p from ``x0`` and the
    filled bin nearest ``x0 + 0.05``, where the table rises there from above zero (a levels
    or gamma curve meets black at black); above the last: the same in ``1 - x`` and
    ``1 - f``. Elsewhere (flat or falling ends) the table stays flat, as ``np.interp`` left it.

    Parameters
    ----------
    table : ndarray of float32, shape (256, 3)
    filled : ndarray of bool, shape (256, 3)
        Bins that held pixels, per column.

    Returns
    -------
    table : ndarray of float32, shape (256, 3)
    low, high : ndarray of float32, shape (3,)
        Bin centres of the first and last filled bins.
    """
    out = table.astype(np.float64).copy()
    centres = (np.arange(256) + 0.5) / 256
    low, high = np.zeros(3, np.float32), np.ones(3, np.float32)
    for c in range(3):
        where = np.nonzero(filled[:, c])[0]
        if len(where) < 2:
            continue
        first, last = where[0], where[-1]
        low[c], high[c] = centres[first], centres[last]
        for end in (first, last):
            sign = 1 if end == first else -1
            x0 = centres[end] if sign > 0 else 1 - centres[end]
            f0 = out[end, c] if sign > 0 else 1 - out[end, c]
            target = centres[end] + sign * _EXTRAPOLATION_STEP
            other = where[np.argmin(np.abs(centres[where] - target))]
            x1 = centres[other] if sign > 0 else 1 - centres[other]
            f1 = out[other, c] if sign > 0 else 1 - out[other, c]
            if not (x1 > x0 * 1.05 and f0 > 1e-3 and f1 > f0 * 1.001):
                continue
            power = min(np.log(f1 / f0) / np.log(x1 / x0), 8.0)
            span = np.arange(0, end) if sign > 0 else np.arange(end + 1, 256)
            x = centres[span] if sign > 0 else 1 - centres[span]
            f = f0 * (x / x0) ** power
            out[span, c] = f if sign > 0 else 1 - f
    return out.astype(np.float32), low, high


#: F counts as an affine function of the table's key when an affine fit of F on the key misses
#: O's edge pixels by less than this on average (encoded values). Measured on the real-tools
#: tuning half, tables of one value per pixel: thresholds miss by 7.8/255 (maps) to 57/255;
#: G'MIC's -luminance 0-0.7/255 and GEGL's hue-chroma on the star burst 2.5-3.5/255.
STRAIGHT_TABLE_MISS = 4.0 / 255
#: ... unless F clips on more than this share of O's edge pixels: an affine map of the key that
#: saturates inside O's range (an autocontrast, a levels stretch) bends there as a threshold
#: does, and its ink past O's darkest extreme is the saturated colour. Measured on the
#: real-tools tuning half (edge pixels whose F is 0 or 1 in a channel where the affine fit of
#: the unsaturated ones passes the range by over 4/255): Pillow's autocontrast on the memo,
#: the notice and the star burst 0.022-0.029, on the icons and the screenshot 0.000-0.002;
#: G'MIC's -luminance and GEGL's hue-chroma 0.000 on every drawing.
STRAIGHT_TABLE_CLIPPED = 0.01
# F saturates in a channel within half an 8-bit step of 0 or 1; the affine fit passes the
# range when it lies beyond it by more than the straight miss.
_SATURATED = 0.5 / 255


def affine_in_key_miss(original, filtered, edges, key):
    """Mean miss of the best affine function of the table's key as a model of F on edge pixels.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour.
    edges : ndarray of bool, shape (H, W)
    key : str
        A table key of :data:`~aarecovery.plan.pointwise.TABLE_KEYS` ("channel": each output
        channel on its own input channel).

    Returns
    -------
    float
        Mean over edge pixels of the largest channel miss; inf for scale keys or no edges.
    """
    if key not in TABLE_KEYS or not edges.any():
        return float("inf")
    misses = []
    for design, target in _affine_designs(original, filtered, edges, key):
        coefficients, *_ = np.linalg.lstsq(design, target, rcond=None)
        misses.append(np.abs(design @ coefficients - target))
    return float(largest_channel(np.stack(misses, axis=-1)).mean())


def _affine_designs(original, filtered, edges, key):
    """Per channel, the design matrix of an affine function of the key on the edge pixels
    (key, 1), float64, and F's channel there."""
    values = key_of(original, key)[edges].astype(np.float64)
    target = filtered[edges].astype(np.float64)
    for c in range(3):
        x = values[:, c] if key == "channel" else values
        yield np.stack([x, np.ones_like(x)], axis=1), target[:, c]


def clipped_share(original, filtered, edges, key):
    """Share of O's edge pixels where F is an affine function of the table's key, clipped.

    Per channel, the affine fit of F on the key over the edge pixels where F is not saturated;
    a pixel counts where F is 0 (or 1) in a channel and that fit lies below 0 (above 1) by more
    than :data:`STRAIGHT_TABLE_MISS` there.

    The parameters are :func:`affine_in_key_miss`'s. Returns a float in [0, 1]; 0 for scale
    keys or no edges.
    """
    if key not in TABLE_KEYS or not edges.any():
        return 0.0
    clipped = np.zeros(int(edges.sum()), bool)
    for design, target in _affine_designs(original, filtered, edges, key):
        low, high = target <= _SATURATED, target >= 1 - _SATURATED
        middle = ~low & ~high
        if middle.sum() < 2:
            continue
        coefficients, *_ = np.linalg.lstsq(design[middle], target[middle], rcond=None)
        fitted = design @ coefficients
        clipped |= (low & (fitted < -STRAIGHT_TABLE_MISS)) | (high & (fitted > 1 + STRAIGHT_TABLE_MISS))
    return float(clipped.mean())


def pure_colour_prior(original, transfer, blend_space, filtered=None, edges=None, noise_contrast=0.0,
                      extend_ends=True, ridge_noise=0.0, luma_purity=0.0):
    """The prior for the passes, from the first fitted table fit for the extension.

    Keys often tie (a threshold of black/white text matches per channel and by luma); the
    best candidate that matches F, is keyed for the extension and is monotone is used (failing
    one, the best whose columns turn at most once: a colour map such as JET), and
    it extends to the cube only where the candidates that tie with it agree there.

    Parameters
    ----------
    original : ndarray of float32, shape (H, W, 3)
        O's encoded colour (the analysis crop).
    transfer : PointwiseTransfer
        From ``fit_pointwise``, with its ``alternatives``.
    blend_space : {"linear", "srgb"}
    filtered : ndarray of float32, shape (H, W, 3), optional
        F's encoded colour, with `edges` (bool, shape (H, W)): where F is an affine function
        of the table's key there, thin features keep to O's flat colours and are not
        extended to the colour cube.
    noise_contrast : float, optional
        O's compression noise as a contrast (``aarecovery.plan.compression``): extremes
        closer than that are not thin features.
    extend_ends : bool, optional
        Extrapolate the table past O's key range (:func:`extrapolate_table`); False for a
        JPEG-compressed O, whose range ends at its ringing.
    ridge_noise : float, optional
        O's compression noise as a contrast, which a thin feature's ridge must also stand out
        from (``PureColourPrior.ridge_noise``); 0 for an uncompressed O.
    luma_purity : float, optional
        ``PureColourPrior.luma_purity``: :data:`COMPRESSED_LUMA_PURITY` for a JPEG-compressed
        O, 0 otherwise.

    Returns
    -------
    PureColourPrior or None
        None when no candidate qualifies.
    """
    palette, inks = palette_of(original), inks_of(original)
    eligible = [candidate for candidate in transfer.alternatives
                if candidate.consistency >= POINTWISE_SHARE and candidate.key in EXTENSION_KEYS]
    # A monotone table first; failing one, a colour map's hump (turns_at_most_once), only of a
    # table that gives F's colour (a colour map of the grey), not of a luma that scales or
    # shifts O's: those that turn are colour replacements matched by chance (the built-in
    # text under colour replacement: a luma shift 0.595 -> 0.566 at 128 px, a luma scale
    # 0.537 -> 0.370 at 80 px).
    fit = ([candidate for candidate in eligible if is_monotone(_mapped_table(candidate))]
           or [candidate for candidate in eligible
               if candidate.key not in SHIFT_KEYS + SCALE_KEYS and turns_at_most_once(candidate.table)])
    # A luma shift only where no other key explains F (an equalized YCbCr luma): on a grey
    # image it ties with the channel table, and as a tied candidate that disagrees on the
    # cube it took the extension's reach to the cube away (tuning half, the manga under
    # G'MIC's equalize at q 75: 0.751 -> 0.671).
    # Nor above compression noise or a paper grain: a grain-level change of the grey moves a
    # steep curve's offset by whole steps, and the extension painted the grain into the paper
    # (tuning half, the memo and notice pages under Pillow's YCbCr equalization: 2-30 -> 17-214
    # paper pixels darker than F per case, for 0.17-0.41 -> 0.30-0.60 of their edge error).
    others = [candidate for candidate in fit if candidate.key not in SHIFT_KEYS]
    fit = others or ([] if noise_contrast > 0 else fit)
    if not fit:
        return None
    priors = [PureColourPrior(candidate.key, palette=palette, inks=inks, noise_contrast=float(noise_contrast),
                              ridge_noise=float(ridge_noise), luma_purity=float(luma_purity),
                              **_extrapolated(original, candidate, extend_ends))
              for candidate in fit
              if candidate.consistency >= fit[0].consistency and candidate.mean_miss <= fit[0].mean_miss + _TIE_MISS]
    chosen = priors[0]
    if not _agree_where_extended(priors, original, blend_space):
        chosen = dataclasses.replace(chosen, to_cube=False)
    elif (filtered is not None and affine_in_key_miss(original, filtered, edges, chosen.key) < STRAIGHT_TABLE_MISS
          and clipped_share(original, filtered, edges, chosen.key) <= STRAIGHT_TABLE_CLIPPED):
        # The extension guesses an ink O never shows and reads the table's extrapolation
        # there: worth it where the table bends (a threshold, levels, an affine stretch that
        # clips), only its own error where F is a straight function of the key (colour to
        # grey, a hue change of a few colours). Tuning half: the sRGB star burst under G'MIC's
        # -luminance -1.94 with the extension, +0.42 without; under GEGL's hue-chroma -0.21 /
        # +0.52. Pillow's autocontrast (2% clipped at each end) was read as straight: its
        # sub-pixel strokes kept O's darkest extreme as their ink (the memo 0.214, the notice
        # 0.113 of their edge error; 0.681 and 0.672 extended).
        chosen = dataclasses.replace(chosen, to_cube=False)
    return chosen


def _mapped_table(candidate):
    """What a candidate's table maps its key to: the table, or for a shift key (``F = clip(O +
    s(Y))``) each grey level plus its offset, the luma it maps to, which is monotone where
    the filter is (an equalization), while the offset alone is not."""
    if candidate.key not in SHIFT_KEYS:
        return candidate.table
    return (candidate.table + (np.arange(256, dtype=np.float32) / np.float32(255))[:, None]).astype(np.float32)


def _extrapolated(original, candidate, extend_ends):
    # A JPEG's key range ends at its ringing and its end bins hold few, noisy pixels: the power
    # law through them is no guide to the ink beyond, so the table stays flat there
    # (np.interp's ends). Tuning half, JPEG drawings and scans under the point-wise filters:
    # the star burst's thin spokes, whose colour the JPEG's subsampled chroma lost, were
    # extended to near white through the extrapolated top of OpenCV's gamma 2.2 and lost
    # 3.00 dB against F at q 75 (flat: 0.66 dB better than F); serif and memo moved by at
    # most 0.02 in error reduction. A coarse paper grain (plan/paper_grain.py) keeps the
    # extrapolation: flat there, the grained page lost 0.04-0.07 under GEGL's levels and
    # exposure.
    # A shift key's table is not extrapolated: an offset's power law is no curve's, and the
    # curves it fits (equalizations) reach black and white within O's range.
    own = filled_bins(original, candidate.key)
    # The range stays O's own: its ends say which extremes are O's darkest and brightest colours.
    extrapolated, low, high = extrapolate_table(candidate.table, own)
    table = candidate.table
    if candidate.key == "channel":
        table, filled = shared_channel_table(table, own)
        if not np.array_equal(filled, own):
            extrapolated, _, _ = extrapolate_table(table, filled)
    extend = extend_ends and candidate.key not in SHIFT_KEYS
    return {"table": extrapolated if extend else table, "key_low": low, "key_high": high}


#: Per-channel tables agree where both channels hold pixels within this (encoded), over at
#: least :data:`_SHARED_OVERLAP` bins, when they are one curve (:func:`shared_channel_table`).
SHARED_CHANNEL_AGREEMENT = 4.0 / 255
_SHARED_OVERLAP = 8


def shared_channel_table(table, filled):
    """Fill a per-channel table's clipped end from a channel that is the same curve.

    Most point-wise tools apply one curve to R, G and B, but O's channels cover different
    ranges: a dark grey ink never seen whole leaves the green and blue columns empty below
    its thin strokes' level, where the curve is clipped at 1 and a flat end says nothing of
    where it turns (G'MIC's ``-pow 3``: a step at 6 levels), while a green ink's red channel
    shows the curve down to 0. Beyond a column's last bin with pixels, where its table is
    clipped there (within :data:`_SATURATED` of 0 or 1), it takes the values of another column
    that holds pixels there and agrees with it, within :data:`SHARED_CHANNEL_AGREEMENT`, on
    every bin both hold (at least :data:`_SHARED_OVERLAP`).

    Parameters
    ----------
    table : ndarray of float32, shape (256, 3)
        The fitted table, interpolated across its empty bins (``aarecovery.plan.pointwise``).
    filled : ndarray of bool, shape (256, 3)
        Bins that held pixels, per column.

    Returns
    -------
    table : ndarray of float32, shape (256, 3)
    filled : ndarray of bool, shape (256, 3)
        The bins that hold a pixel of the column or of the column it took values from.
    """
    shared, held = table.copy(), filled.copy()
    bins = np.arange(len(table))
    for c in range(3):
        own = np.nonzero(filled[:, c])[0]
        if not len(own):
            continue
        for end, beyond in ((own[0], bins < own[0]), (own[-1], bins > own[-1])):
            value = table[end, c]
            if not (value <= _SATURATED or value >= 1 - _SATURATED):
                continue
            for d in range(3):
                both = filled[:, c] & filled[:, d]
                new = filled[:, d] & beyond & ~held[:, c]
                if d == c or both.sum() < _SHARED_OVERLAP or not new.any():
                    continue
                if np.abs(table[both, c] - table[both, d]).max() <= SHARED_CHANNEL_AGREEMENT:
                    shared[new, c], held[new, c] = table[new, d], True
        if not np.array_equal(held[:, c], filled[:, c]):
            kept = np.nonzero(held[:, c])[0]
            shared[:, c] = np.interp(bins, kept, shared[kept, c])
    return shared.astype(np.float32), held


# Tables that explain F within this mean miss of the best one tie with it.
_TIE_MISS = 0.5 / 255
# Tied tables agree where the extension lands when f of those colours differs by less than
# this on this share of them.
_AGREEMENT = 0.05
_AGREEING_SHARE = 0.95


def _agree_where_extended(priors, original, blend_space):
    """Whether tied tables predict the same f on the pure colours the extension reaches.

    On images of two or three colours every key explains F (the starburst: luma, mean and
    both luminances matched every edge pixel of G'MIC's -luminance exactly) and the keys
    disagree on colours O does not show: extending to the cube with the first of them lost
    8 dB there. Black and white text ties too (per channel, luma, luminance), but its
    extensions stay on the grey axis, where the keys agree.
    """
    if len(priors) < 2:
        return True
    opaque = np.ones(original.shape[:2] + (1,), np.float32)
    work = to_working_space(np.concatenate([original, opaque], -1), blend_space=blend_space)
    model = fit_pure_colour_model(work, work, SIGMA_D.default, SIGMA_E.default, 1.0, priors[0], blend_space)
    colours = np.concatenate([model.colour_a[model.pure_a], model.colour_b[model.pure_b]]).T
    if colours.shape[1] == 0:
        return True
    outputs = [filtered_colour(colours, prior, blend_space)[:3] for prior in priors]
    agreeing = np.all([np.abs(output - outputs[0]).max(axis=0) < _AGREEMENT for output in outputs[1:]], axis=0)
    return bool(agreeing.mean() >= _AGREEING_SHARE)
