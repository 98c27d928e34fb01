"""Does F already have the right edges? It does when the filter is affine in the blend space.

Box filtering (antialiasing) commutes with an affine map of colour: when ``F = A O + b`` in
the space where O was antialiased, then ``F = box(A scene + b)``, exactly the supersampled
reference. Colour to grey by luminance (linear light), a channel mixer, levels and exposure
without clipping, a hue change of grey content: F is then right already, and any repair can
only harm it (measured on the real-tools suite: starburst/linear under G'MIC's -luminance,
F 63.6 dB from the reference, the repair lost 31 dB). The test fits ``A`` and ``b`` by least
squares on O's pixels and counts the edge pixels the fit explains.
"""

import numpy as np

from ..colour import largest_channel, linear_to_srgb, srgb_to_linear

__all__ = ["affine_share", "AFFINE_SHARE", "AFFINE_TOLERANCE"]

#: An edge pixel is explained when the affine fit reproduces F within this (encoded values).
AFFINE_TOLERANCE = 2.0 / 255
#: F counts as an affine map of O in the blend space when this share of edge pixels is explained.
AFFINE_SHARE = 0.99


def affine_share(original, filtered, edges, blend_space):
    """Share of edge pixels where F is an affine function of O in the blend space.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour of the analysis crop.
    edges : ndarray of bool, shape (H, W)
        Where to count.
    blend_space : {"linear", "srgb"}

    Returns
    -------
    float
        0 when there are no edge pixels.
    """
    if not edges.any():
        return 0.0
    to_space = srgb_to_linear if blend_space == "linear" else (lambda values: values)
    source = to_space(original).reshape(-1, 3).astype(np.float64)
    target = to_space(filtered).reshape(-1, 3).astype(np.float64)
    design = np.concatenate([source, np.ones((len(source), 1))], axis=1)
    coefficients, *_ = np.linalg.lstsq(design, target, rcond=None)
    predicted = np.clip(design[edges.ravel()] @ coefficients, 0, 1).astype(np.float32)
    if blend_space == "linear":
        predicted = linear_to_srgb(predicted)
    miss = largest_channel(np.abs(predicted - filtered.reshape(-1, 3)[edges.ravel()]))
    return float((miss <= AFFINE_TOLERANCE).mean())
