"""The safe default: per-image decisions that stop recovery from harming what it cannot help.

The paper's method (``mode="paper"``) harms some inputs measurably (``docs/quality.md``):
Gaussian blur, whose soft edges it re-sharpens, and natural photos under smooth filters,
whose texture the two-colour model flattens. A user cannot know which case they are in,
so ``mode="safe"`` first looks at the pair (O, F) as a whole and decides:

1. **Blend space.** The model must be fitted and imposed in the space in which the image
   was antialiased. An edge between two colours, box-filtered in one space, lies exactly on
   a straight colour line in that space and off it in the other, so the space whose edge
   pixels fit their colour line better wins. Grey-only edges cannot tell; they keep linear
   light, the paper's choice and right for cameras.
2. **Low-pass filters.** A small shift-invariant kernel is fitted from O to F by least
   squares. If it explains F and is low-pass (a blur), F's soft edges are the filter's
   intent and F is returned unchanged.
3. **Point-wise filters and self-calibration.** Most damaging filters act on each pixel
   alone, ``F = f(O)``, and ``f`` can be fitted from the pair as a lookup table. When it
   explains F, O is treated as the scene at twice the resolution: ``O2 = box2(O)``,
   ``F2 = f(O2)``, target ``box2(F)``; the repair strength that best reproduces the target
   there is used on the real pair (0 keeps F).
4. **Other filters on textured images.** With no way to simulate the filter, texture
   decides: when O's edge pixels are poor two-colour blends (a photo), the strength is
   lowered to the value measured as safe for the neighbourhood filters of the suite.

All of it runs once, in NumPy, on the whole image (or a central crop of large ones)
before tiling, and results in three numbers, ``blend_space``, ``strength`` and ``sigma_d``,
that every backend takes as uniforms: the per-pixel passes are the paper's, with ``beta``
multiplied by ``strength``.
"""

from dataclasses import dataclass

import numpy as np

from ._groundtruth import box_downsample
from ._pure_colours import (EXTENSION_KEYS, SCALE_KEYS, PureColourPrior, extrapolate_table, is_monotone, key_values,
                            palette_of, scale_transfer)
from ._reference import fit_blend_model, from_working_space, jacobi_step, sobel_gradients, to_working_space

__all__ = ["SafePlan", "plan_recovery", "choose_blend_space", "fit_lowpass", "fit_pointwise"]

# Analysis works on at most this many pixels per side (a central crop): every statistic
# below is a global average that a 512 x 512 window estimates well, and it bounds the cost
# of self-calibration to a few tenths of a second.
_ANALYSIS_SIDE = 512
# The blend-space test fits the model on up to this many pixels of the crop (all of a
# 256 x 256 crop; strips around every twelfth row of a 512 x 512 one): its mean residual
# settles long before,
# and the two full fits took 0.63 s of the 0.92 s analysis of a 1080p pair (measured).
_FIT_SAMPLE = 65536
# Edge pixels for the statistics: a Sobel / 8 magnitude of at least this in O (encoded values).
_EDGE_GRADIENT = 0.02
# Blend space: the other space must fit colour lines this much worse (ratio of mean
# normalised residuals) and by this much in absolute terms before linear light is left.
# Measured on the synthetic scenes: the right space gives 0.000-0.005, the wrong one
# 0.008-0.04; photos give ~0.03-0.05 in both (ratio < 1.1).
_SPACE_RATIO = 1.5
_SPACE_MARGIN = 0.003
# Low-pass fit: kernel radius, the largest relative residual that counts as "F is this
# kernel applied to O", and the shape of a low-pass kernel. Measured with a 5 x 5 kernel:
# Gaussian blur (sigma 1.5) fits to 0.02-0.10 (the Siemens star is the worst, its spokes
# alias) with no negative weights and a centre weight near 0.08; unsharp masking has
# negative lobes of 0.3-1.2; the bilateral filter leaves residuals of 0.1-0.19 with a centre
# of 0.27-1.04 and negative lobes of 0.05-0.38.
_KERNEL_RADIUS = 2
_LOWPASS_RESIDUAL = 0.15
_LOWPASS_NEGATIVE = 0.03
_LOWPASS_CENTRE = 0.5
# Point-wise fit: bins of the table, tolerance of a match and the share of edge pixels that
# must match. Point-wise filters of the suite score >= 0.99; neighbourhood filters <= 0.8.
_LUT_BINS = 256
_LUT_TOLERANCE = 3.0 / 255
_POINTWISE_SHARE = 0.97
# Candidate strengths tried by self-calibration, and the gain (relative MSE) a non-zero
# strength must show at half resolution to be chosen over leaving F alone.
_STRENGTHS = (0.0, 0.25, 0.5, 1.0)
_MIN_GAIN = 0.01
# Texture: mean normalised colour-line residual of O's edge pixels above which the image is
# treated as a photo. Synthetic scenes measured 0.000-0.005, photos 0.03-0.05.
_TEXTURE_RESIDUAL = 0.015
# Strength for neighbourhood (not point-wise, not low-pass) filters on photos: the paper's
# method lost up to 3.4 dB there (unsharp mask, colour replacement) and gained at most 1 dB
# (bilateral); no strength was safe for all, so F is kept.
_PHOTO_NEIGHBOURHOOD_STRENGTH = 0.0


@dataclass(frozen=True)
class SafePlan:
    """What the safe default decided for one image pair.

    Attributes
    ----------
    blend_space : {"linear", "srgb"}
    strength : float
        Multiplies the confidence ``beta``; 0 returns F unchanged, 1 is the paper's method.
    reason : str
        One line saying why, for ``--verbose`` output and the evaluation report.
    pure_colours : PureColourPrior or None
        For point-wise filters on hard-edged content: the filter's table and O's flat
        colours, with which the passes restore thin features (``aarecovery._pure_colours``).
    """

    blend_space: str
    strength: float
    reason: str
    pure_colours: object = None


def _analysis_crop(image):
    height, width = image.shape[:2]
    top = max(0, (height - _ANALYSIS_SIDE) // 2)
    left = max(0, (width - _ANALYSIS_SIDE) // 2)
    return image[top:top + _ANALYSIS_SIDE, left:left + _ANALYSIS_SIDE]


def _sobel(image):
    gx, gy = sobel_gradients(image)
    return np.sqrt(np.sum(gx * gx + gy * gy, axis=-1))


def _sampled_rows(image, limit=_FIT_SAMPLE):
    """At most about `limit` pixels of `image` as stacked 3-row strips, and their middle rows.

    The fit reads a 3x3 neighbourhood, so a strip of three rows gives its middle row exactly
    the model of the whole image. Crops up to `limit` pixels (every eval image) are used whole.
    """
    height, width = image.shape[:2]
    if height * width <= limit or height < 3:
        return image, slice(None)
    stride = -(-3 * height * width // limit)  # each sampled row brings its two neighbours
    if stride <= 3:
        return image, slice(None)
    return np.concatenate([image[row - 1:row + 2] for row in range(1, height - 1, stride)]), slice(1, None, 3)


def _colour_line_fit(rgba, linear_input, blend_space):
    """Mean colour-line residual of confident edge pixels, relative to their contrast."""
    work, middle = _sampled_rows(to_working_space(rgba, linear_input=linear_input, blend_space=blend_space))
    model = fit_blend_model(work, work, 0.1, 0.01)
    colours = np.stack([np.pad(work, ((1, 1), (1, 1), (0, 0)), mode="edge")[1 + dy:1 + dy + work.shape[0],
                                                                                1 + dx:1 + dx + work.shape[1]]
                        for dy, dx in ((0, 0), (-1, 0), (0, -1), (0, 1), (1, 0),
                                       (-1, -1), (-1, 1), (1, -1), (1, 1))])
    c_a = np.take_along_axis(colours, model.index_a[None, ..., None].astype(np.intp), 0)[0]
    c_b = np.take_along_axis(colours, model.index_b[None, ..., None].astype(np.intp), 0)[0]
    span = np.sqrt(np.sum(np.square(c_a - c_b)[..., :3], axis=-1))
    selected = (model.beta > 0.5) & (span > 0.2) & (model.alpha > 0.03) & (model.alpha < 0.97)
    selected[~np.isin(np.arange(work.shape[0]), np.arange(work.shape[0])[middle])] = False
    if selected.sum() < 16:
        return None
    return float(np.mean(model.residual[selected] / span[selected]))


def choose_blend_space(original_rgba, linear_input=False):
    """Pick the space in which O was antialiased, from how well its edges fit colour lines.

    Parameters
    ----------
    original_rgba : ndarray of float32, shape (H, W, 4)
        O in the core contract.
    linear_input : bool

    Returns
    -------
    space : {"linear", "srgb"}
    residuals : dict
        Mean normalised residual per space (None where too few edges were found).
    """
    residuals = {space: _colour_line_fit(original_rgba, linear_input, space) for space in ("linear", "srgb")}
    lin, srgb = residuals["linear"], residuals["srgb"]
    if lin is not None and srgb is not None and lin > _SPACE_RATIO * srgb and lin - srgb > _SPACE_MARGIN:
        return "srgb", residuals
    return "linear", residuals


def fit_lowpass(original, filtered):
    """Fit ``F ~ K * O`` with a small kernel shared by the colour channels.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour.

    Returns
    -------
    lowpass : bool
        The kernel explains F (relative residual below the measured bound) and is a
        low-pass kernel: weights sum to about 1, negative lobes are negligible and the
        centre does not dominate (which would be the identity).
    residual : float
        ``|F - K * O| / |F - mean(F)|`` on the sampled pixels.
    kernel : ndarray of float64, shape (2r + 1, 2r + 1)
    """
    r = _KERNEL_RADIUS
    height, width = original.shape[:2]
    if height <= 2 * r + 2 or width <= 2 * r + 2:
        return False, 1.0, None
    padded = np.pad(original, ((r, r), (r, r), (0, 0)), mode="edge")
    step = max(1, int(np.sqrt(height * width / 20000)))
    rows = np.arange(0, height, step)
    cols = np.arange(0, width, step)
    columns = [padded[r + dy + rows[:, None], r + dx + cols[None, :]].reshape(-1)
               for dy in range(-r, r + 1) for dx in range(-r, r + 1)]
    design = np.stack(columns, axis=1).astype(np.float64)
    target = filtered[rows[:, None], cols[None, :]].reshape(-1).astype(np.float64)
    spread = np.linalg.norm(target - target.mean())
    if spread < 1e-6:
        return False, 1.0, None
    # Normal equations: a 25 x 25 solve, ten times faster than lstsq's SVD here; the tiny
    # ridge only matters for flat images, whose columns are all alike.
    gram = design.T @ design
    gram[np.diag_indices_from(gram)] += 1e-9 * np.trace(gram)
    weights = np.linalg.solve(gram, design.T @ target)
    residual = float(np.linalg.norm(design @ weights - target) / spread)
    kernel = weights.reshape(2 * r + 1, 2 * r + 1)
    total = kernel.sum()
    negative = -kernel[kernel < 0].sum()
    lowpass = (residual < _LOWPASS_RESIDUAL and abs(total - 1) < 0.05 and negative < _LOWPASS_NEGATIVE * total
               and kernel[r, r] < _LOWPASS_CENTRE * total)
    return bool(lowpass), residual, kernel


def _keys(colour):
    luma = colour @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    return {"channel": colour, "luma": luma, "mean": colour.mean(axis=-1), "max": colour.max(axis=-1)}


def _bins(key):
    return np.clip((key * _LUT_BINS).astype(np.intp), 0, _LUT_BINS - 1)


class PointwiseTransfer:
    """A fitted point-wise transfer ``F = f(O)`` as a lookup table.

    Attributes
    ----------
    key : {"channel", "luma", "mean", "max"}
        What the table is indexed by: each channel of O on its own, or one value per pixel.
    table : ndarray of float32, shape (256, 3)
        Output colour per bin (for ``"channel"``, column c maps channel c).
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
        values = _keys(colour)[self.key]
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
        return float((np.abs(transfer(scored_o) - scored_f).max(axis=-1) <= _LUT_TOLERANCE).mean())

    for key, values in _keys(original).items():
        index = _bins(values)
        table = np.empty((_LUT_BINS, 3), np.float32)
        for c in range(3):
            bins = index[..., c] if key == "channel" else index
            sums = np.bincount(bins.ravel(), filtered[..., c].ravel(), minlength=_LUT_BINS)
            counts = np.bincount(bins.ravel(), minlength=_LUT_BINS)
            filled = counts > 0
            centres = np.arange(_LUT_BINS)
            table[:, c] = np.interp(centres, centres[filled], sums[filled] / counts[filled]) if filled.any() else 0
        transfer = PointwiseTransfer(key, table, 0.0)
        transfer.consistency = consistency(transfer)
        fitted.append(transfer)
        if best is None or transfer.consistency > best.consistency:
            best = transfer
    for key in SCALE_KEYS:
        chosen = None
        for table in _scale_tables(original, filtered, key):
            transfer = PointwiseTransfer(key, table, 0.0)
            transfer.consistency = consistency(transfer)
            if chosen is None or transfer.consistency > chosen.consistency:
                chosen = transfer
        fitted.append(chosen)
        if chosen.consistency > best.consistency:
            best = chosen
    best.alternatives = sorted(fitted, key=lambda t: -t.consistency)
    return best


def _scale_tables(original, filtered, key):
    """Candidate tables of a scale key (``_pure_colours.scale_transfer``): bin means of the
    mapped luma, estimated two ways.

    * F's own luma, from pixels F did not clip at 1 where a bin has any (right for curves
      with steps, such as histogram equalization of few colours);
    * each pixel's scale (F / O in its largest channel that F did not clip) times its luma,
      leaving out pixels clipped in every channel (right where the curve maps above 1, as
      tone mapping does near white);

    each placed at bin centres or at the bins' mean keys.

    The caller keeps the one that explains F best.
    """
    from ._colour import srgb_to_linear
    to_values = (lambda c: srgb_to_linear(c)) if key == "luminance_scale" else (lambda c: c)
    weights = np.array([0.2126, 0.7152, 0.0722], np.float64)
    source = to_values(original).reshape(-1, 3).astype(np.float64)
    result = to_values(filtered).reshape(-1, 3).astype(np.float64)
    luma = source @ weights
    index = np.clip((luma * _LUT_BINS).astype(np.intp), 0, _LUT_BINS - 1)
    centres = np.arange(_LUT_BINS)

    def table(values, use, at_mean_key):
        counts = np.bincount(index[use], minlength=_LUT_BINS)
        sums = np.bincount(index[use], values[use], minlength=_LUT_BINS)
        filled = counts > 0
        # Each bin's mean at its bin's centre, or at its pixels' mean key (a bin holding
        # black and a few dark blends is not centred).
        where = (np.bincount(index[use], luma[use], minlength=_LUT_BINS)[filled] / counts[filled] * _LUT_BINS - 0.5
                 if at_mean_key else centres[filled])
        column = np.interp(centres, where, sums[filled] / counts[filled]) if filled.any() else np.zeros(_LUT_BINS)
        return np.repeat(column[:, None], 3, axis=1).astype(np.float32)

    own = result @ weights
    unclipped = result.max(axis=-1) < 1 - 1 / 512
    has_unclipped = np.bincount(index[unclipped], minlength=_LUT_BINS) > 0
    first = unclipped | ~has_unclipped[index]
    usable = (result < 1 - 1 / 512) & (source > 1e-4)
    channel = np.argmax(np.where(usable, source, -1), axis=-1)
    rows = np.arange(len(source))
    ratio = result[rows, channel] / np.maximum(source[rows, channel], 1e-4)
    scaled = np.where(luma > 1e-6, ratio * luma, result.mean(axis=-1))
    second = usable.any(axis=-1) | (luma <= 1e-6)
    return tuple(table(values, use, at_mean_key) for values, use in ((own, first), (scaled, second))
                 for at_mean_key in (False, True))


def _filled_bins(original, key):
    """Which of a table's bins O's pixels fill, per column: ndarray of bool, shape (256, 3)."""
    keys = key_values(np.ascontiguousarray(original.reshape(-1, 3).T, dtype=np.float32), key)
    filled = np.zeros((_LUT_BINS, 3), bool)
    for c in range(3):
        filled[:, c] = np.bincount(_bins(keys[c]), minlength=_LUT_BINS) > 0
    return filled


def _recover_at(work_o, work_f, filtered_rgba, space, strength, sigma_d, sigma_e, iterations):
    model = fit_blend_model(work_o, work_f, sigma_d, sigma_e, strength=strength)
    recovered = work_f
    for _ in range(iterations):
        recovered = jacobi_step(recovered, work_f, model)
    return from_working_space(recovered, filtered_rgba, blend_space=space)


def _calibrate(original, transfer, filtered, space, sigma_d, sigma_e, iterations):
    """Pick the strength that best reproduces ``box2(F)`` from ``(box2(O), f(box2(O)))``."""
    height, width = (original.shape[0] // 2) * 2, (original.shape[1] // 2) * 2
    if height < 16 or width < 16:
        return 1.0, {}
    o2 = box_downsample(original[:height, :width], 2, space)
    target = box_downsample(filtered[:height, :width], 2, space)
    f2 = np.clip(transfer(o2), 0, 1).astype(np.float32)
    opaque = np.ones(o2.shape[:2] + (1,), np.float32)
    o2_rgba, f2_rgba = np.concatenate([o2, opaque], -1), np.concatenate([f2, opaque], -1)
    work_o = to_working_space(o2_rgba, blend_space=space)
    work_f = to_working_space(f2_rgba, blend_space=space)
    band = (np.abs(f2 - target).max(axis=-1) > 1 / 255) | (_sobel(o2).max() > 0) & (_sobel(o2) >= _EDGE_GRADIENT)
    if not band.any():
        return 1.0, {}
    errors = {}
    for strength in _STRENGTHS:
        result = f2 if strength == 0 else _recover_at(work_o, work_f, f2_rgba, space, strength, sigma_d, sigma_e,
                                                       iterations)[..., :3]
        errors[strength] = float(np.mean(np.square(result - target)[band]))
    base = errors[0.0]
    best = min(errors, key=errors.get)
    if best != 0.0 and errors[best] > base * (1 - _MIN_GAIN):
        best = 0.0
    return best, errors


def plan_recovery(original_rgba, filtered_rgba, *, linear_input=False, sigma_d=0.1, sigma_e=0.01, iterations=3):
    """Decide blend space and strength for one pair (the safe default).

    Parameters
    ----------
    original_rgba, filtered_rgba : ndarray of float32, shape (H, W, 4)
        The whole pair in the core contract (straight alpha).
    linear_input : bool
        True when the colour is linear light.
    sigma_d, sigma_e, iterations
        The recovery parameters the plan will be used with.

    Returns
    -------
    SafePlan
    """
    o_rgba = _analysis_crop(original_rgba)
    f_rgba = _analysis_crop(filtered_rgba)
    space, residuals = choose_blend_space(o_rgba, linear_input)
    # The remaining analysis is on sRGB-encoded colour, as filters see it.
    from ._colour import linear_to_srgb
    o = o_rgba[..., :3] if not linear_input else linear_to_srgb(o_rgba[..., :3])
    f = f_rgba[..., :3] if not linear_input else linear_to_srgb(f_rgba[..., :3])
    fit = residuals[space]
    lowpass, kernel_residual, _ = fit_lowpass(o, f)
    if lowpass:
        return SafePlan(space, 0.0, f"F is a low-pass (blur) of O (kernel residual {kernel_residual:.3f}): kept F")
    edges = _sobel(o) >= _EDGE_GRADIENT
    transfer = fit_pointwise(o, f, edges)
    textured = fit is not None and fit > _TEXTURE_RESIDUAL
    if transfer.consistency >= _POINTWISE_SHARE and not textured:
        # Hard-edged content: calibration would be biased here, since O is not a sharp
        # scene at twice the resolution (its edges are already blends) and box2(F) keeps
        # F's damage; measured, it chose strengths of 0.25-0.5 that lost 3-8 dB of the
        # paper's gain on synthetic scenes. Full strength is the measured best.
        # With a monotone per-channel or luma table, thin features get their pure colours
        # (_pure_colours.py): quick suite 0.600 -> 0.712 (linear), 0.628 -> 0.686 (sRGB); the
        # table's ends extended by a power law (extrapolate_table): 0.774 / 0.734.
        # Keys often tie (a threshold of black/white text matches per channel and by luma);
        # the first that is also fit for the extension is used.
        prior = None
        for candidate in transfer.alternatives:
            if candidate.consistency >= _POINTWISE_SHARE and candidate.key in EXTENSION_KEYS \
                    and is_monotone(candidate.table):
                table, low, high = extrapolate_table(candidate.table, _filled_bins(o, candidate.key))
                prior = PureColourPrior(candidate.key, table, palette_of(o), low, high)
                break
        return SafePlan(space, 1.0, f"point-wise filter (key {transfer.key}, {transfer.consistency:.3f} of edges "
                                    "match) on hard-edged content: full strength"
                                    + (", pure colours of thin features" if prior is not None else ""), prior)
    if transfer.consistency >= _POINTWISE_SHARE:
        strength, errors = _calibrate(o, transfer, f, space, sigma_d, sigma_e, iterations)
        return SafePlan(space, strength,
                        f"point-wise filter (key {transfer.key}, {transfer.consistency:.3f} of edges match); "
                        f"half-resolution calibration chose strength {strength:g}")
    if textured:
        return SafePlan(space, _PHOTO_NEIGHBOURHOOD_STRENGTH,
                        f"neighbourhood filter on a textured image (colour-line residual {fit:.3f}): "
                        f"strength {_PHOTO_NEIGHBOURHOOD_STRENGTH:g}")
    return SafePlan(space, 1.0, "neighbourhood filter on hard-edged content: full strength")
