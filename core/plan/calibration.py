"""Self-calibration of the repair strength, for point-wise filters on textured images (photos).

With ``f`` known, O is treated as the scene at twice the resolution: ``O2 = box2(O)``,
``F2 = f(O2)``, target ``box2(F)``; the strength that best reproduces the target there is
used on the real pair (0 keeps F). Measured: photos under gamma, tone mapping,
equalization, gradient maps and colour to grey went from up to -9.2 dB (paper) to >= 0;
threshold and posterize on photos gained 1-3 dB. On hard-edged content it is biased (O's
edges are already blends, and box2(F) keeps F's damage) and is not used there.
"""

import dataclasses

import numpy as np

from ..colour import largest_channel
from ..spec import fit_blend_model, from_working_space, recover_working, to_working_space
from ..spec.blend_model import scaled_confidence
from ..spec.sobel import gradient_magnitude
from .resample import box_downsample

__all__ = ["calibrate_strength", "EDGE_GRADIENT"]

#: Edge pixels for the statistics: a Sobel / 8 magnitude of at least this in O (encoded values).
EDGE_GRADIENT = 0.02
# Candidate strengths tried by self-calibration, and the gain (relative MSE) a non-zero
# strength must show at half resolution to be chosen over leaving F alone.
_STRENGTHS = (0.0, 0.25, 0.5, 1.0)
_MIN_GAIN = 0.01
# After the grid, one more strength halfway between the best and its better neighbour: the
# half-resolution error is smooth in the strength. Measured on the real-tools suite's tuning
# half: photos under point-wise filters 0.295 -> 0.304, JPEG gain kept 0.25 -> 0.27, no new
# loss, for one more half-size recovery (+0.07 s on a 512 x 512 crop); the whole grid of
# eighths gave the same figures for four more.


def calibrate_strength(original, transfer, filtered, space, sigma_d, sigma_e, iterations):
    """Pick the strength that best reproduces ``box2(F)`` from ``(box2(O), f(box2(O)))``.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour of the analysis crop.
    transfer : PointwiseTransfer
        The filter, fitted from the pair.
    space : {"linear", "srgb"}
        The blend space.
    sigma_d, sigma_e, iterations
        The parameters to calibrate at.

    Returns
    -------
    strength : float
        One of the candidate strengths (0, 0.25, 0.5, 1 and one halfway between the best of
        those and its better neighbour); 0 unless a non-zero one gains 1 % MSE.
    errors : dict of float to float
        The half-resolution MSE of each candidate.
    """
    height, width = (original.shape[0] // 2) * 2, (original.shape[1] // 2) * 2
    if height < 16 or width < 16:
        return 1.0, {}
    # A JPEG's noise is averaged away here, so the half-resolution pair is cleaner than O.
    # Measured and not taken: that noise put back (the compression evidence's deviation, the
    # same in every channel, fixed seed) before the table maps it. Tuning half, 920 cases:
    # 22 up, 25 down (the scans at q 75 by up to 0.07 of their edge error), share of the PNG
    # gain kept 0.51 -> 0.50, and the two losses (icons under ImageMagick's sigmoidal
    # contrast, q 75 and 90, calibrated to 0.5 for a predicted third to half of their error)
    # still there. Nor the JPEG's 4:2:0 chroma put back (the half-resolution O's chroma
    # averaged over 2 x 2 and spread back as a decoder does, before the table maps it): those
    # two losses went (to 0.005 and 0.016 of their error), but of the tuning half's 460 JPEG
    # cases 33 rose and 26 fell, the serif text by up to 0.24 (0.330 -> 0.306), and the share
    # of the PNG gain kept fell 0.475 -> 0.470.
    o2 = box_downsample(original[:height, :width], 2, space)
    target = box_downsample(filtered[:height, :width], 2, space)
    f2 = np.clip(transfer(o2), 0, 1).astype(np.float32)
    opaque = np.ones(o2.shape[:2] + (1,), np.float32)
    o2_rgba, f2_rgba = np.concatenate([o2, opaque], -1), np.concatenate([f2, opaque], -1)
    work_o = to_working_space(o2_rgba, blend_space=space)
    work_f = to_working_space(f2_rgba, blend_space=space)
    gradient = gradient_magnitude(o2)
    band = (largest_channel(np.abs(f2 - target)) > 1 / 255) | (gradient.max() > 0) & (gradient >= EDGE_GRADIENT)
    if not band.any():
        return 1.0, {}

    # The model at strength 1, once: a strength only scales its beta (scaled_confidence),
    # bit for bit as a fit at that strength would (0.09 -> 0.06 s of the photo pair's plan).
    fitted = fit_blend_model(work_o, work_f, sigma_d, sigma_e)

    def error_at(strength):
        if strength == 0:
            result = f2
        else:
            model = dataclasses.replace(fitted, beta=scaled_confidence(fitted.beta, strength))
            recovered, _ = recover_working(work_o, work_f, sigma_d, sigma_e, iterations, strength, model=model)
            result = from_working_space(recovered, f2_rgba, blend_space=space)[..., :3]
        return float(np.mean(np.square(result - target)[band]))

    errors = {strength: error_at(strength) for strength in _STRENGTHS}
    ordered = list(_STRENGTHS)
    best = ordered.index(min(errors, key=errors.get))
    closer = min((ordered[i] for i in (best - 1, best + 1) if 0 <= i < len(ordered)), key=errors.get)
    halfway = (ordered[best] + closer) / 2
    errors[halfway] = error_at(halfway)
    base = errors[0.0]
    best = min(errors, key=errors.get)
    if best != 0.0 and errors[best] > base * (1 - _MIN_GAIN):
        best = 0.0
    return best, errors
